// Google Benchmark micro-benchmarks of the core's hot paths on the shared surface set:
// key encoding, radix sort, building, lookups, iteration, rank, serialization.
//   build-bench/bench/vola_micro --benchmark_repetitions=5 --benchmark_report_aggregates_only=true
// Data: $VOLA_SHARED/data/bench (default ../shared next to the repository).
#include <benchmark/benchmark.h>

#include <cstdlib>
#include <string>
#include <vector>

#include "vola/io/npy.hpp"
#include "vola/vola.hpp"

namespace {

std::vector<vola::Voxel> load(const std::string& name) {
  const char* shared = std::getenv("VOLA_SHARED");
  const std::string dir = (shared ? std::string(shared) : std::string(VOLA_SHARED_DEFAULT)) + "/data/bench/";
  const vola::io::NpyArray array = vola::io::read_npy(dir + name);
  std::vector<vola::Voxel> voxels(array.shape.at(0));
  for (std::size_t i = 0; i < voxels.size(); ++i)
    voxels[i] = {static_cast<std::uint32_t>(array.value(3 * i)), static_cast<std::uint32_t>(array.value(3 * i + 1)),
                 static_cast<std::uint32_t>(array.value(3 * i + 2))};
  return voxels;
}

const std::vector<vola::Voxel>& points() {
  static const auto p = load("surface_points_1e6.npy");
  return p;
}
const std::vector<vola::Voxel>& queries() {
  static const auto q = load("surface_queries_1e6.npy");
  return q;
}
const vola::Tree& tree() {
  static const vola::Tree t = vola::build_from_voxels(points(), 5);
  return t;
}

void encode_keys(benchmark::State& state) {
  std::vector<vola::Key> keys(points().size());
  for (auto _ : state) {
    for (std::size_t i = 0; i < keys.size(); ++i) keys[i] = vola::encode(points()[i]);
    benchmark::DoNotOptimize(keys.data());
  }
  state.SetItemsProcessed(static_cast<std::int64_t>(state.iterations() * keys.size()));
}

void radix_sort(benchmark::State& state) {
  std::vector<vola::Key> keys(points().size());
  for (auto _ : state) {
    state.PauseTiming();
    for (std::size_t i = 0; i < keys.size(); ++i) keys[i] = vola::encode(points()[i]);
    state.ResumeTiming();
    vola::radix_sort(keys, nullptr, 30);
    benchmark::DoNotOptimize(keys.data());
  }
  state.SetItemsProcessed(static_cast<std::int64_t>(state.iterations() * keys.size()));
}

void build(benchmark::State& state) {
  for (auto _ : state) benchmark::DoNotOptimize(vola::build_from_voxels(points(), 5).voxel_count());
  state.SetItemsProcessed(static_cast<std::int64_t>(state.iterations() * points().size()));
}

void contains(benchmark::State& state) {
  const vola::Tree& t = tree();
  for (auto _ : state) {
    std::size_t hits = 0;
    for (const auto& q : queries()) hits += t.contains(q);
    benchmark::DoNotOptimize(hits);
  }
  state.SetItemsProcessed(static_cast<std::int64_t>(state.iterations() * queries().size()));
}

void rank(benchmark::State& state) {
  const vola::Tree& t = tree();
  for (auto _ : state) {
    std::uint64_t sum = 0;
    for (const auto& q : queries()) sum += t.rank(q).value_or(0);
    benchmark::DoNotOptimize(sum);
  }
  state.SetItemsProcessed(static_cast<std::int64_t>(state.iterations() * queries().size()));
}

void iterate(benchmark::State& state) {
  const vola::Tree& t = tree();
  for (auto _ : state) {
    std::uint64_t sum = 0;
    t.for_each_voxel([&](const vola::Voxel& v) { sum += v.x + v.y + v.z; });
    benchmark::DoNotOptimize(sum);
  }
  state.SetItemsProcessed(static_cast<std::int64_t>(state.iterations() * tree().voxel_count()));
}

void serialize(benchmark::State& state) {
  for (auto _ : state) benchmark::DoNotOptimize(vola::serialize(tree()).size());
  state.SetItemsProcessed(static_cast<std::int64_t>(state.iterations() * tree().voxel_count()));
}

}  // namespace

BENCHMARK(encode_keys)->Unit(benchmark::kMillisecond);
BENCHMARK(radix_sort)->Unit(benchmark::kMillisecond);
BENCHMARK(build)->Unit(benchmark::kMillisecond);
BENCHMARK(contains)->Unit(benchmark::kMillisecond);
BENCHMARK(rank)->Unit(benchmark::kMillisecond);
BENCHMARK(iterate)->Unit(benchmark::kMillisecond);
BENCHMARK(serialize)->Unit(benchmark::kMillisecond);
BENCHMARK_MAIN();
