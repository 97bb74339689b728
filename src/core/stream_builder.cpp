#include "vola/stream_builder.hpp"

#include <algorithm>
#include <bit>
#include <cmath>
#include <functional>
#include <limits>
#include <memory>
#include <utility>

#include "emit.hpp"
#include "reductions.hpp"
#include "stream_runs.hpp"
#include "vola/error.hpp"

namespace vola {
VOLA_INLINE_NAMESPACE_BEGIN

using namespace stream;

struct StreamBuilder::State {
  Quantizer quantizer;
  std::vector<AttributeSpec> specs;
  bool payload = false;
  std::vector<Run> runs;  // oldest first; sizes roughly halve towards the back
  std::uint64_t points_in = 0;
  std::uint64_t points_outside = 0;
  // Scratch reused across chunks.
  std::vector<Key> keys;
  std::vector<std::uint32_t> index;
  std::vector<std::uint32_t> starts;
  KeyVector sort_buffer;
  KeyVector chunk_keys;  // key_scratch()
  std::vector<std::uint32_t> counts;
  std::vector<Source> merge_plan;
  Run recycled;  // attributes or payloads: a merged-away run, its vectors reused by add()
  std::uint64_t expected_points = 0;  // expect_points()
  std::vector<double> majority_scratch;

  // Key vectors of merged-away runs, reused for new runs and merge outputs: fresh
  // memory costs a page fault and the kernel's zeroing per page, which dominated the
  // occupancy merges. The spares hold at most as many keys as the live runs (the
  // smallest go first), so memory stays within twice the runs.
  std::vector<KeyVector> spare;
  KeyVector take(std::size_t n, std::size_t room = 0);
  void give(KeyVector&& v, std::size_t also_live = 0);

  void push(Run run);
  void push_keys(std::span<Key> keys);
  void unite(Run& older, Run& newer);
};

// n keys (uninitialized); a new vector has capacity for max(n, room).
KeyVector StreamBuilder::State::take(std::size_t n, std::size_t room) {
  std::size_t best = spare.size();
  for (std::size_t i = 0; i < spare.size(); ++i)
    if (spare[i].capacity() >= n && (best == spare.size() || spare[i].capacity() < spare[best].capacity())) best = i;
  KeyVector v;
  if (best < spare.size()) {
    v = std::move(spare[best]);
    spare.erase(spare.begin() + static_cast<std::ptrdiff_t>(best));
  } else {
    v.reserve(std::max(n, room));
  }
  v.resize(n);  // uninitialized: KeyAllocator
  return v;
}

// also_live: keys of a run not yet in `runs` (a merge's output).
void StreamBuilder::State::give(KeyVector&& v, std::size_t also_live) {
  if (v.capacity() == 0) return;
  v.clear();
  spare.push_back(std::move(v));
  std::size_t live = also_live, kept = 0;
  for (const Run& run : runs) live += run.keys.capacity() + run.bits.capacity();
  for (const KeyVector& k : spare) kept += k.capacity();
  while (kept > live && !spare.empty()) {
    const auto smallest = std::min_element(
        spare.begin(), spare.end(), [](const KeyVector& a, const KeyVector& b) { return a.capacity() < b.capacity(); });
    kept -= smallest->capacity();
    spare.erase(smallest);
  }
}

// Occupancy only: the union of two block runs, left in `older`; newer's vectors given
// back for reuse. In place when older's vectors have room; else older moves to vectors
// with room for as much again (address space only: pages are touched when written),
// so that the next unions into it are in place too. Fresh memory costs a page fault
// and the kernel's zeroing per page, which dominated these unions.
void StreamBuilder::State::unite(Run& older, Run& newer) {
  const std::size_t united = older.keys.size() + newer.keys.size() - common_blocks(older.keys, newer.keys);
  if (older.keys.capacity() < united || older.bits.capacity() < united) {
    KeyVector roomy_keys = take(united, 2 * united), roomy_bits = take(united, 2 * united);
    roomy_keys.resize(older.keys.size());
    roomy_bits.resize(older.keys.size());
    std::copy(older.keys.begin(), older.keys.end(), roomy_keys.begin());
    std::copy(older.bits.begin(), older.bits.end(), roomy_bits.begin());
    std::swap(roomy_keys, older.keys);
    std::swap(roomy_bits, older.bits);
    const std::size_t live = older.keys.capacity() + older.bits.capacity();
    give(std::move(roomy_keys), live);  // the old, smaller vectors
    give(std::move(roomy_bits), live);
  }
  unite_in_place(older.keys, older.bits, newer.keys, newer.bits, united);
  give(std::move(newer.keys));
  give(std::move(newer.bits));
  newer = Run{};
}

void StreamBuilder::State::push_keys(std::span<Key> chunk) {
  if (chunk.empty()) return;
  if (sort_buffer.size() < chunk.size()) sort_buffer.resize(chunk.size());
  Key *blocks = nullptr, *bits = nullptr;
  const std::size_t m = sort_blocks(chunk.data(), sort_buffer.data(), chunk.size(), counts, blocks, bits);
  Run run;
  // Room for the unions into this run to come (address space only: pages are touched
  // when written), so that they need no fresh vectors, whose first touch (a page fault
  // and the kernel's zeroing per page) costs more than the union itself.
  run.keys = take(m, 4 * m);
  run.bits = take(m, 4 * m);
  std::copy(blocks, blocks + m, run.keys.begin());
  std::copy(bits, bits + m, run.bits.begin());
  push(std::move(run));
}

// Binary-counter merging keeps O(log chunks) runs and merges each record O(log) times.
void StreamBuilder::State::push(Run run) {
  runs.push_back(std::move(run));
  while (runs.size() >= 2 && runs[runs.size() - 2].keys.size() <= 2 * runs.back().keys.size()) {
    if (specs.empty() && !payload) {
      unite(runs[runs.size() - 2], runs.back());
    } else {
      merge_into(runs[runs.size() - 2], runs.back(), specs, payload, merge_plan);
      // The merged-away run's vectors take the next chunk's partials: memory already
      // touched, where new vectors would cost a page fault and zeroing per page.
      if (runs.back().keys.capacity() > recycled.keys.capacity()) recycled = std::move(runs.back());
    }
    runs.pop_back();
  }
}

StreamBuilder::StreamBuilder(const Quantizer& quantizer, std::vector<AttributeSpec> attributes, bool payload)
    : state_(std::make_unique<State>()) {
  state_->quantizer = quantizer;
  state_->specs = std::move(attributes);
  state_->payload = payload;
}
StreamBuilder::~StreamBuilder() = default;
StreamBuilder::StreamBuilder(StreamBuilder&&) noexcept = default;
StreamBuilder& StreamBuilder::operator=(StreamBuilder&&) noexcept = default;

std::uint64_t StreamBuilder::points_in() const noexcept { return state_->points_in; }
void StreamBuilder::expect_points(std::uint64_t points) noexcept { state_->expected_points = points; }
std::uint64_t StreamBuilder::points_outside() const noexcept { return state_->points_outside; }

std::size_t StreamBuilder::memory_bytes() const noexcept {
  std::size_t bytes = state_->keys.capacity() * 8 + state_->index.capacity() * 4;
  for (const auto& run : state_->runs) bytes += run.memory_bytes();
  return bytes;
}

void StreamBuilder::add(std::span<const double> xyz, std::span<const std::span<const double>> values,
                        std::span<const std::uint64_t> payloads) {
  State& s = *state_;
  const std::size_t n = xyz.size() / 3;
  if (xyz.size() != 3 * n) VOLA_THROW(InvalidArgument("stream builder: xyz size is not a multiple of 3"));
  if (values.size() != s.specs.size())
    VOLA_THROW(InvalidArgument("stream builder: " + std::to_string(values.size()) + " attribute arrays for " +
                          std::to_string(s.specs.size()) + " attributes"));
  for (const auto& v : values)
    if (v.size() != n) VOLA_THROW(InvalidArgument("stream builder: an attribute array's length differs from the points'"));
  if (s.payload && payloads.size() != n) VOLA_THROW(InvalidArgument("stream builder: one payload per point, please"));
  if (n > std::numeric_limits<std::uint32_t>::max()) VOLA_THROW(InvalidArgument("stream builder: chunk too large"));
  s.points_in += n;

  const bool per_point = s.payload || !s.specs.empty();
  s.keys.clear();
  s.index.clear();
  s.points_outside += s.quantizer.to_keys(xyz.subspan(0, 3 * n), s.keys, per_point ? &s.index : nullptr);
  if (!per_point) {
    s.push_keys(s.keys);
    return;
  }
  radix_sort(s.keys, &s.index, 6 * s.quantizer.depth());

  // Runs of equal keys hold one voxel's points in input order: [starts[v], starts[v+1]).
  Run run = std::move(s.recycled);  // sizes set below; only the capacity matters
  s.recycled = Run{};
  if (s.runs.empty() && s.expected_points > s.keys.size())
    reserve_voxels(run, s.specs, s.payload, std::min(s.expected_points, kMaxReservedVoxels));
  std::vector<std::uint32_t>& starts = s.starts;
  starts.clear();
  run.keys.resize(s.keys.size());  // uninitialized: KeyAllocator
  std::size_t voxels = 0;
  for (std::size_t k = 0; k < s.keys.size(); ++k) {
    if (k == 0 || s.keys[k] != s.keys[k - 1]) {
      starts.push_back(static_cast<std::uint32_t>(k));
      run.keys[voxels++] = s.keys[k];
    }
  }
  starts.push_back(static_cast<std::uint32_t>(s.keys.size()));
  run.keys.resize(voxels);
  const std::uint32_t* index = s.index.data();
  if (s.payload) {
    run.payloads.resize(voxels);
    for (std::size_t v = 0; v < voxels; ++v) run.payloads[v] = payloads[index[starts[v + 1] - 1]];
  }
  if (has_mean(s.specs)) {
    run.points.resize(voxels);
    for (std::size_t v = 0; v < voxels; ++v) run.points[v] = starts[v + 1] - starts[v];
  }
  // Attribute by attribute, each with a tight loop over the voxels.
  run.partials.resize(s.specs.size());
  for (std::size_t a = 0; a < s.specs.size(); ++a) {
    const double* values_of = values[a].data();
    Partial& p = run.partials[a];
    const Reduction reduction = s.specs[a].reduction;
    if (reduction == Reduction::majority) {
      reduce_majority(run.keys, values_of, index, starts, p, s.majority_scratch);
      continue;
    }
    p.value.resize(voxels);
    detail::with_reduction(reduction, [&](auto r) {
      for (std::size_t v = 0; v < voxels; ++v) {
        const std::uint32_t* points = index + starts[v];
        p.value[v] = detail::fold<decltype(r)::value>([&](std::uint32_t k) { return values_of[points[k]]; },
                                                      starts[v + 1] - starts[v]);
      }
    });
    // A mean counts its points without a value, where the chunk has any.
    p.nans.clear();
    if (reduction == Reduction::mean &&
        std::any_of(values[a].begin(), values[a].end(), [](double x) { return std::isnan(x); })) {
      p.nans.resize(voxels);
      for (std::size_t v = 0; v < voxels; ++v) {
        const std::uint32_t* points = index + starts[v];
        p.nans[v] = detail::count_nan([&](std::uint32_t k) { return values_of[points[k]]; }, starts[v + 1] - starts[v]);
      }
    }
  }
  s.push(std::move(run));
}

std::span<Key> StreamBuilder::key_scratch(std::size_t n) {
  State& s = *state_;
  if (s.chunk_keys.size() < n) s.chunk_keys.resize(n);
  return {s.chunk_keys.data(), n};
}

void StreamBuilder::add_keys(std::span<Key> keys, std::uint64_t outside) {
  State& s = *state_;
  if (s.payload || !s.specs.empty())
    VOLA_THROW(InvalidArgument("stream builder: add_keys is for occupancy only (no attributes, no payloads)"));
  s.points_in += keys.size() + outside;
  s.points_outside += outside;
  if (keys.empty()) return;
  Key all = 0;
  for (const Key k : keys) all |= k;
  if (all >> (6 * s.quantizer.depth()))
    VOLA_THROW(InvalidArgument("stream builder: a key is too large for depth " + std::to_string(s.quantizer.depth())));
  s.push_keys(keys);
}

Tree StreamBuilder::finish() {
  State& s = *state_;
  Run all;
  all.partials.resize(s.specs.size());
  // The final unions' outputs outgrow every spare: give the memory back first.
  s.spare.clear();
  s.spare.shrink_to_fit();
  s.sort_buffer = KeyVector();
  s.chunk_keys = KeyVector();
  s.recycled = Run{};
  // A union is exact in any order, so merge the smallest (newest) runs first: each
  // voxel is then copied about twice, not once per run.
  if (!s.runs.empty()) {
    all = std::move(s.runs.back());
    s.runs.pop_back();
  }
  const bool occupancy_only = s.specs.empty() && !s.payload;
  while (!s.runs.empty()) {
    if (occupancy_only) {
      s.unite(s.runs.back(), all);
      s.spare.clear();
    } else {
      merge_into(s.runs.back(), all, s.specs, s.payload, s.merge_plan);
    }
    all = std::move(s.runs.back());
    s.runs.pop_back();
  }
  s.merge_plan = {};
  const int depth = s.quantizer.depth();
  Tree tree = occupancy_only ? detail::emit_block_levels(all.keys, all.bits, depth)
                             : detail::emit_levels(all.keys, depth, all.payloads, s.payload);
  if (s.payload) tree.set_voxel_payloads(std::vector<std::uint64_t>(all.payloads.begin(), all.payloads.end()));
  const std::size_t voxels = all.keys.size();
  for (std::size_t a = 0; a < s.specs.size(); ++a) {
    const AttributeSpec& spec = s.specs[a];
    Partial& p = all.partials[a];
    AttributeColumn column(spec.name, spec.type, spec.reduction, voxels);
    if (spec.reduction == Reduction::majority) {
      store_majority(all.keys, p, column);
    } else {
      const bool counted = spec.reduction == Reduction::mean;  // points per voxel are kept for means only
      const bool nans = !p.nans.empty();
      for (std::size_t v = 0; v < voxels; ++v) {
        const std::uint64_t with_value = counted ? all.points[v] - (nans ? p.nans[v] : 0) : 1;
        column.set(v, detail::finish(spec.reduction, p.value[v], with_value));
      }
    }
    p = Partial{};  // the column holds it now
    tree.attributes().add(std::move(column));
  }
  tree.set_frame(s.quantizer.frame());
  return tree;
}

VOLA_INLINE_NAMESPACE_END
}  // namespace vola
