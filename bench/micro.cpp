// Google Benchmark micro-benchmarks of the core's hot paths on the shared benchmark sets
// (1e6 points in a 1024^3 grid, ../shared/data/bench): key encoding and decoding, the radix
// sort, building, lookups, rank, iteration, serialization and opening a mapped file.
// Argument 0 = the surface set, 1 = the uniform set.
//   build-bench/bench/vola_micro --benchmark_repetitions=5 --benchmark_report_aggregates_only=true
// Data: $VOLA_SHARED/data/bench (default: ../shared beside the repository).
#include <benchmark/benchmark.h>

#include <cstdint>
#include <filesystem>
#include <string>
#include <unistd.h>
#include <vector>

#include "bench_data.hpp"
#include "vola/builder.hpp"
#include "vola/file.hpp"
#include "vola/key.hpp"
#include "vola/tree.hpp"

namespace {

constexpr int kDepth = 5;

struct Set {
  std::vector<vola::Voxel> points;
  std::vector<vola::Voxel> queries;  // half occupied, half empty
  std::vector<vola::Key> keys;       // the points' keys, input order
  vola::Tree tree;
  std::string mapped_file;  // the tree as a plain .vol
};

const Set& set(std::int64_t which) {
  static Set sets[2];
  static bool loaded[2] = {false, false};
  Set& s = sets[which];
  if (!loaded[which]) {
    const std::string name = which == 0 ? "surface" : "uniform";
    const auto dir = vola_bench::default_data_dir();
    s.points = vola_bench::read_points(dir / (name + "_points_1e6.npy")).voxels();
    s.queries = vola_bench::read_points(dir / (name + "_queries_1e6.npy")).voxels();
    s.keys.resize(s.points.size());
    for (std::size_t i = 0; i < s.points.size(); ++i) s.keys[i] = vola::encode(s.points[i]);
    s.tree = vola::build_from_voxels(s.points, kDepth);
    s.mapped_file = (std::filesystem::temp_directory_path() /
                     ("vola_micro_" + std::to_string(::getpid()) + "_" + name + ".vol"))
                        .string();
    vola::write(s.tree, s.mapped_file);
    loaded[which] = true;
  }
  return s;
}

void label(benchmark::State& state) { state.SetLabel(state.range(0) == 0 ? "surface" : "uniform"); }

void encode_keys(benchmark::State& state) {
  const Set& s = set(state.range(0));
  std::vector<vola::Key> keys(s.points.size());
  for (auto _ : state) {
    for (std::size_t i = 0; i < keys.size(); ++i) keys[i] = vola::encode(s.points[i]);
    benchmark::DoNotOptimize(keys.data());
    benchmark::ClobberMemory();
  }
  state.SetItemsProcessed(state.iterations() * static_cast<std::int64_t>(keys.size()));
  label(state);
}

void decode_keys(benchmark::State& state) {
  const Set& s = set(state.range(0));
  std::vector<vola::Voxel> voxels(s.keys.size());
  for (auto _ : state) {
    for (std::size_t i = 0; i < voxels.size(); ++i) voxels[i] = vola::decode(s.keys[i]);
    benchmark::DoNotOptimize(voxels.data());
    benchmark::ClobberMemory();
  }
  state.SetItemsProcessed(state.iterations() * static_cast<std::int64_t>(voxels.size()));
  label(state);
}

// The 64-bit LSD radix sort (30-bit keys: 3 passes of 11 bits); the copy of the unsorted
// keys is not timed.
void radix_sort(benchmark::State& state) {
  const Set& s = set(state.range(0));
  std::vector<vola::Key> keys;
  for (auto _ : state) {
    state.PauseTiming();
    keys = s.keys;
    state.ResumeTiming();
    vola::radix_sort(keys, nullptr, 6 * kDepth);
    benchmark::DoNotOptimize(keys.data());
  }
  state.SetItemsProcessed(state.iterations() * static_cast<std::int64_t>(s.keys.size()));
  label(state);
}

// Points -> tree: encoding, the leaf-block bitmap (depth <= 5), levels, rank directory.
void build_from_voxels(benchmark::State& state) {
  const Set& s = set(state.range(0));
  for (auto _ : state) benchmark::DoNotOptimize(vola::build_from_voxels(s.points, kDepth).voxel_count());
  state.SetItemsProcessed(state.iterations() * static_cast<std::int64_t>(s.points.size()));
  label(state);
}

void contains(benchmark::State& state) {
  const Set& s = set(state.range(0));
  for (auto _ : state) {
    std::size_t hits = 0;
    for (const auto& q : s.queries) hits += s.tree.contains(q);
    benchmark::DoNotOptimize(hits);
  }
  state.SetItemsProcessed(state.iterations() * static_cast<std::int64_t>(s.queries.size()));
  label(state);
}

void rank(benchmark::State& state) {
  const Set& s = set(state.range(0));
  for (auto _ : state) {
    std::uint64_t sum = 0;
    for (const auto& q : s.queries) sum += s.tree.rank(q).value_or(0);
    benchmark::DoNotOptimize(sum);
  }
  state.SetItemsProcessed(state.iterations() * static_cast<std::int64_t>(s.queries.size()));
  label(state);
}

void for_each_voxel(benchmark::State& state) {
  const Set& s = set(state.range(0));
  for (auto _ : state) {
    std::uint64_t sum = 0;
    s.tree.for_each_voxel([&](const vola::Voxel& v) { sum += std::uint64_t{v.x} + v.y + v.z; });
    benchmark::DoNotOptimize(sum);
  }
  state.SetItemsProcessed(state.iterations() * static_cast<std::int64_t>(s.tree.voxel_count()));
  label(state);
}

void serialize(benchmark::State& state) {
  const Set& s = set(state.range(0));
  std::size_t bytes = 0;
  for (auto _ : state) {
    bytes = vola::serialize(s.tree).size();
    benchmark::DoNotOptimize(bytes);
  }
  state.SetItemsProcessed(state.iterations() * static_cast<std::int64_t>(s.tree.voxel_count()));
  state.SetBytesProcessed(state.iterations() * static_cast<std::int64_t>(bytes));
  label(state);
}

// WriteOptions.compress (zstd, level 19 by default).
void serialize_zstd(benchmark::State& state) {
  const Set& s = set(state.range(0));
  if (!vola::compression_available()) {
    state.SkipWithError("built without zstd");
    return;
  }
  vola::WriteOptions options;
  options.compress = true;
  std::size_t bytes = 0;
  for (auto _ : state) {
    bytes = vola::serialize(s.tree, options).size();
    benchmark::DoNotOptimize(bytes);
  }
  state.SetItemsProcessed(state.iterations() * static_cast<std::int64_t>(s.tree.voxel_count()));
  state.counters["bits_per_voxel"] = 8.0 * static_cast<double>(bytes) / static_cast<double>(s.tree.voxel_count());
  label(state);
}

// Map a plain .vol (in the page cache) and index it (rank directory, jump table), then one
// lookup so the mapping is used.
void open_mapped(benchmark::State& state) {
  const Set& s = set(state.range(0));
  for (auto _ : state) {
    const vola::Tree t = vola::open_mapped(s.mapped_file);
    benchmark::DoNotOptimize(t.contains(s.queries.front()));
  }
  state.SetItemsProcessed(state.iterations() * static_cast<std::int64_t>(s.tree.voxel_count()));
  label(state);
}

}  // namespace

BENCHMARK(encode_keys)->Arg(0)->Arg(1)->Unit(benchmark::kMillisecond);
BENCHMARK(decode_keys)->Arg(0)->Arg(1)->Unit(benchmark::kMillisecond);
BENCHMARK(radix_sort)->Arg(0)->Arg(1)->Unit(benchmark::kMillisecond);
BENCHMARK(build_from_voxels)->Arg(0)->Arg(1)->Unit(benchmark::kMillisecond);
BENCHMARK(contains)->Arg(0)->Arg(1)->Unit(benchmark::kMillisecond);
BENCHMARK(rank)->Arg(0)->Arg(1)->Unit(benchmark::kMillisecond);
BENCHMARK(for_each_voxel)->Arg(0)->Arg(1)->Unit(benchmark::kMillisecond);
BENCHMARK(serialize)->Arg(0)->Arg(1)->Unit(benchmark::kMillisecond);
BENCHMARK(serialize_zstd)->Arg(0)->Arg(1)->Unit(benchmark::kMillisecond);
BENCHMARK(open_mapped)->Arg(0)->Arg(1)->Unit(benchmark::kMillisecond);

int main(int argc, char** argv) {
  benchmark::Initialize(&argc, argv);
  if (benchmark::ReportUnrecognizedArguments(argc, argv)) return 1;
  benchmark::RunSpecifiedBenchmarks();
  benchmark::Shutdown();
  for (std::int64_t which : {0, 1}) {  // the mapped files, if made
    static const std::string names[2] = {"surface", "uniform"};
    std::error_code ec;
    std::filesystem::remove(std::filesystem::temp_directory_path() /
                                ("vola_micro_" + std::to_string(::getpid()) + "_" + names[which] + ".vol"),
                            ec);
  }
  return 0;
}
