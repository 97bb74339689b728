#include "vola/stream_builder.hpp"

#include <algorithm>
#include <bit>
#include <cmath>
#include <functional>
#include <limits>
#include <memory>
#include <new>
#include <utility>

#include "emit.hpp"
#include "reductions.hpp"

#if defined(__linux__)
#include <sys/mman.h>
#endif
#include "vola/error.hpp"

namespace vola {
VOLA_INLINE_NAMESPACE_BEGIN

namespace {

// Key buffers: resize() leaves new elements uninitialized (the sorts and merges write
// every element; zeroing tens of megabytes first cost time), and a large buffer is
// 2 MiB aligned and advised as transparent huge pages: touching fresh memory one 4 KiB
// page at a time (a page fault each) took half of an occupancy conversion on a
// virtual machine, and the runs are fresh memory at every merge.
template <class T>
struct KeyAllocator {
  using value_type = T;
  static constexpr std::size_t kHuge = std::size_t{2} << 20;
  KeyAllocator() = default;
  template <class U>
  KeyAllocator(const KeyAllocator<U>&) noexcept {}
  T* allocate(std::size_t n) {
    const std::size_t bytes = n * sizeof(T);
    if (bytes < 2 * kHuge) return static_cast<T*>(::operator new(bytes));
    void* p = ::operator new(bytes, std::align_val_t{kHuge});
#ifdef MADV_HUGEPAGE
    ::madvise(p, bytes / kHuge * kHuge, MADV_HUGEPAGE);
#endif
    return static_cast<T*>(p);
  }
  void deallocate(T* p, std::size_t n) noexcept {
    const std::size_t bytes = n * sizeof(T);
    if (bytes < 2 * kHuge) ::operator delete(p);
    else ::operator delete(p, std::align_val_t{kHuge});
  }
  template <class U>
  void construct(U* p) noexcept {
    ::new (static_cast<void*>(p)) U;
  }
  template <class U, class... Args>
  void construct(U* p, Args&&... args) {
    ::new (static_cast<void*>(p)) U(std::forward<Args>(args)...);
  }
  friend bool operator==(const KeyAllocator&, const KeyAllocator&) noexcept { return true; }
};
using KeyVector = std::vector<Key, KeyAllocator<Key>>;
// The same for the per-voxel columns of runs with attributes: every element is written.
template <class T>
using Column = std::vector<T, KeyAllocator<T>>;

// Occupancy only: sorts the voxel keys[0, n) by leaf block (key >> 6; LSD radix over
// only the block bits that vary among them, in digits of at most 12 bits, a pass
// skipped when its digit is the same in every key) and collapses each block's keys
// into its 64 voxel bits. `buffer` holds n keys; `counts` is scratch. Returns the
// number of blocks m: their sorted unique keys in blocks[0, m), their bits in
// bits[0, m), where (blocks, bits) is (keys, buffer) or (buffer, keys).
std::size_t sort_blocks(Key* keys, Key* buffer, std::size_t n, std::vector<std::uint32_t>& counts, Key*& blocks,
                        Key*& bits) {
  blocks = keys;
  bits = buffer;
  if (n == 0) return 0;
  const Key first = keys[0];
  Key differ = 0;
  for (std::size_t i = 0; i < n; ++i) differ |= keys[i] ^ first;
  differ >>= 6;
  Key* from = keys;
  Key* to = buffer;
  if (differ != 0) {
    const int low = 6 + std::countr_zero(differ), bits_varying = static_cast<int>(std::bit_width(differ)) + 6 - low;
    constexpr int kMaxDigit = 12;
    const int passes = (bits_varying + kMaxDigit - 1) / kMaxDigit;
    const int digit = (bits_varying + passes - 1) / passes;
    const std::size_t buckets = std::size_t{1} << digit;
    const Key mask = buckets - 1;
    counts.assign(buckets * static_cast<std::size_t>(passes), 0);
    std::uint32_t* count = counts.data();
    if (passes == 1) {
      for (std::size_t i = 0; i < n; ++i) ++count[(keys[i] >> low) & mask];
    } else {
      for (std::size_t i = 0; i < n; ++i) {
        const Key k = keys[i] >> low;
        for (int p = 0; p < passes; ++p) ++count[p * buckets + ((k >> (p * digit)) & mask)];
      }
    }
    for (int p = 0; p < passes; ++p) {
      std::uint32_t* c = count + p * buckets;
      const int shift = low + p * digit;
      if (c[(from[0] >> shift) & mask] == n) continue;  // the same digit in every key
      std::uint32_t offset = 0;
      for (std::size_t b = 0; b < buckets; ++b) {
        const std::uint32_t here = c[b];
        c[b] = offset;
        offset += here;
      }
      for (std::size_t i = 0; i < n; ++i) {
        const Key k = from[i];
        to[c[(k >> shift) & mask]++] = k;
      }
      std::swap(from, to);
    }
  }
  // Equal blocks are adjacent now: block u's key goes to from[u] (u <= i: already read),
  // its bits to to[u]; written at every step, so the last write of a block holds all.
  Key block = from[0] >> 6, acc = 0;
  std::size_t u = 0;
  for (std::size_t i = 0; i < n; ++i) {
    const Key k = from[i], b = k >> 6;
    const bool same = b == block;
    u += !same;
    acc = (same ? acc : 0) | (Key{1} << (k & 63));
    from[u] = b;
    to[u] = acc;
    block = b;
  }
  blocks = from;
  bits = to;
  return u + 1;
}

// Blocks in both of the sorted unique block lists a and b (only where their ranges
// overlap: chunks of a survey often cover their own stretch of the key space).
std::size_t common_blocks(std::span<const Key> a, std::span<const Key> b) {
  if (a.empty() || b.empty()) return 0;
  const Key lo = std::max(a.front(), b.front()), hi = std::min(a.back(), b.back());
  if (lo > hi) return 0;
  std::size_t i = static_cast<std::size_t>(std::lower_bound(a.begin(), a.end(), lo) - a.begin());
  std::size_t j = static_cast<std::size_t>(std::lower_bound(b.begin(), b.end(), lo) - b.begin());
  const std::size_t i_end = static_cast<std::size_t>(std::upper_bound(a.begin() + static_cast<std::ptrdiff_t>(i), a.end(), hi) - a.begin());
  const std::size_t j_end = static_cast<std::size_t>(std::upper_bound(b.begin() + static_cast<std::ptrdiff_t>(j), b.end(), hi) - b.begin());
  std::size_t common = 0;
  while (i < i_end && j < j_end) {
    const Key x = a[i], y = b[j];
    common += x == y;
    i += x <= y;
    j += y <= x;
  }
  return common;
}

// The union of the sorted unique blocks a (with bits) and b (with bits) into a itself,
// from the back, the bits of a block in both OR-ed. a's vectors need room for
// `united` blocks (a.size() + b.size() - common_blocks(a, b)). A block is written at
// or after the position it is read from, so nothing is overwritten before it is read,
// and the blocks of a below b's first stay where they are.
void unite_in_place(KeyVector& a, KeyVector& a_bits, std::span<const Key> b, std::span<const Key> b_bits,
                    std::size_t united) {
  std::size_t i = a.size(), j = b.size(), o = united;
  a.resize(united);  // uninitialized: KeyAllocator
  a_bits.resize(united);
  Key* ak = a.data();
  Key* ab = a_bits.data();
  while (i > 0 && j > 0) {
    const Key x = ak[i - 1], y = b[j - 1];
    const bool from_a = x >= y, from_b = y >= x;
    --o;
    const Key bits = (from_a ? ab[i - 1] : 0) | (from_b ? b_bits[j - 1] : 0);
    ak[o] = from_a ? x : y;
    ab[o] = bits;
    i -= from_a;
    j -= from_b;
  }
  std::copy(b.begin(), b.begin() + static_cast<std::ptrdiff_t>(j), ak);  // b's blocks below all of a's
  std::copy(b_bits.begin(), b_bits.begin() + static_cast<std::ptrdiff_t>(j), ab);
}

// One attribute's partial reduction over the voxels of a run.
struct Partial {
  // mean: the sum; max, min, last: the value; one per voxel (majority: unused)
  Column<double> value;
  // majority: the run's distinct (voxel key, value) pairs, sorted, with the number of
  // points of each: flat arrays, so that merging two runs is one linear pass
  KeyVector pair_key;
  Column<double> pair_value;
  Column<std::uint32_t> pair_count;

  std::size_t memory_bytes() const noexcept {
    return value.capacity() * 8 + pair_key.capacity() * 8 + pair_value.capacity() * 8 + pair_count.capacity() * 4;
  }
};

// Sorted unique voxel keys with their partial reductions; occupancy only (no
// attributes, no payloads): sorted unique leaf block keys (voxel key >> 6) with their
// 64 voxel bits each in `bits`, a word per block instead of a key per voxel.
struct Run {
  KeyVector keys;
  KeyVector bits;
  Column<std::uint32_t> points;  // points per voxel, when an attribute is a mean
  Column<std::uint64_t> payloads;
  std::vector<Partial> partials;

  std::size_t memory_bytes() const noexcept {
    std::size_t bytes = keys.capacity() * 8 + bits.capacity() * 8 + points.capacity() * 4 + payloads.capacity() * 8;
    for (const auto& p : partials) bytes += p.memory_bytes();
    return bytes;
  }
};

bool has_mean(std::span<const AttributeSpec> specs) {
  return std::any_of(specs.begin(), specs.end(), [](const AttributeSpec& s) { return s.reduction == Reduction::mean; });
}

// Where a voxel of a merge comes from: the older run, the newer, or both (same key).
enum Source : std::uint8_t { kOlder = 1, kNewer = 2, kBoth = 3 };

// The source of each key of the sorted union of the keys a and b, in order, into
// `from`; returns the union's size.
std::size_t plan_merge(std::span<const Key> a, std::span<const Key> b, std::vector<Source>& from) {
  from.resize(a.size() + b.size());
  std::size_t i = 0, j = 0, o = 0;
  while (i < a.size() && j < b.size()) {
    const Key x = a[i], y = b[j];
    const bool take_a = x <= y, take_b = y <= x;
    from[o++] = static_cast<Source>(take_a | take_b << 1);
    i += take_a;
    j += take_b;
  }
  std::fill(from.begin() + static_cast<std::ptrdiff_t>(o), from.begin() + static_cast<std::ptrdiff_t>(o + a.size() - i), kOlder);
  o += a.size() - i;
  std::fill(from.begin() + static_cast<std::ptrdiff_t>(o), from.begin() + static_cast<std::ptrdiff_t>(o + b.size() - j), kNewer);
  return o + b.size() - j;
}

// n elements (uninitialized beyond the old size); room for as much again when the
// vector has to move, so that the next merges into it stay in place.
template <class T>
void grow(Column<T>& column, std::size_t n) {
  if (column.capacity() < n) column.reserve(2 * n);
  column.resize(n);
}

// One per-voxel column of a merge, in place in the older run's column a: a voxel in
// both runs gets both(older's value, newer's value). From the back: output o is at or
// after every older value not yet read, so nothing is overwritten before it is read.
// Merging in place instead of into new vectors halves the fresh memory, whose page
// faults and zeroing by the kernel took half of the conversion.
template <class T, class Both>
void merge_column(Column<T>& a, const Column<T>& b, std::span<const Source> plan, Both both) {
  std::size_t i = a.size(), j = b.size();
  grow(a, plan.size());
  T* out = a.data();
  for (std::size_t o = plan.size(); o-- > 0;) {
    switch (plan[o]) {
      case kOlder: out[o] = out[--i]; break;
      case kNewer: out[o] = b[--j]; break;
      case kBoth:
        --i;
        out[o] = both(out[i], b[--j]);
        break;
    }
  }
}

// Majority partials: the union of two sorted (key, value) pair lists in place in a,
// counts of equal pairs added; from the back, as merge_column.
void merge_pairs(Partial& a, const Partial& b) {
  const std::size_t na = a.pair_key.size(), nb = b.pair_key.size();
  auto before = [](Key x, double u, Key y, double w) { return x < y || (x == y && detail::value_before(u, w)); };
  std::size_t united = 0, i = 0, j = 0;
  while (i < na && j < nb) {
    const bool take_a = !before(b.pair_key[j], b.pair_value[j], a.pair_key[i], a.pair_value[i]);
    const bool take_b = !before(a.pair_key[i], a.pair_value[i], b.pair_key[j], b.pair_value[j]);
    i += take_a;
    j += take_b;
    ++united;
  }
  united += (na - i) + (nb - j);
  grow(a.pair_key, united);
  grow(a.pair_value, united);
  grow(a.pair_count, united);
  Key* key = a.pair_key.data();
  double* value = a.pair_value.data();
  std::uint32_t* count = a.pair_count.data();
  i = na;
  j = nb;
  for (std::size_t o = united; o-- > 0;) {
    const bool has_a = i > 0, has_b = j > 0;
    const bool take_a = has_a && (!has_b || !before(key[i - 1], value[i - 1], b.pair_key[j - 1], b.pair_value[j - 1]));
    const bool take_b = has_b && (!has_a || !before(b.pair_key[j - 1], b.pair_value[j - 1], key[i - 1], value[i - 1]));
    if (take_a && take_b) {
      --i;
      --j;
      key[o] = key[i];
      value[o] = value[i];
      count[o] = count[i] + b.pair_count[j];
    } else if (take_a) {
      --i;
      key[o] = key[i];
      value[o] = value[i];
      count[o] = count[i];
    } else {
      --j;
      key[o] = b.pair_key[j];
      value[o] = b.pair_value[j];
      count[o] = b.pair_count[j];
    }
  }
}

// The union of two runs with attributes or payloads, left in `older`; voxels in both
// combine their partials (the newer's payload wins: it holds the later point). Column
// by column, so that each pass is a tight loop over arrays.
void merge_into(Run& older, const Run& newer, std::span<const AttributeSpec> specs, bool payload,
                std::vector<Source>& plan_buffer) {
  const std::size_t voxels = plan_merge(older.keys, newer.keys, plan_buffer);
  const std::span<const Source> plan(plan_buffer.data(), voxels);
  merge_column(older.keys, newer.keys, plan, [](Key k, Key) { return k; });
  if (has_mean(specs)) merge_column(older.points, newer.points, plan, std::plus<>());
  if (payload) merge_column(older.payloads, newer.payloads, plan, [](std::uint64_t, std::uint64_t n) { return n; });
  for (std::size_t a = 0; a < specs.size(); ++a) {
    Column<double>& p = older.partials[a].value;
    const Column<double>& r = newer.partials[a].value;
    if (specs[a].reduction == Reduction::majority) {
      merge_pairs(older.partials[a], newer.partials[a]);
      continue;
    }
    detail::with_reduction(specs[a].reduction, [&](auto reduction) {
      merge_column(p, r, plan, [](double x, double y) { return detail::combine<decltype(reduction)::value>(x, y); });
    });
  }
}

// expect_points() reserves at most this many voxels per column (1 GiB of address space
// for 8-byte values): the kernel refuses single allocations far beyond its memory, and
// beyond this the columns grow as they go.
constexpr std::uint64_t kMaxReservedVoxels = std::uint64_t{1} << 27;

// Room for `voxels` in every column the run uses (address space only).
void reserve_voxels(Run& run, std::span<const AttributeSpec> specs, bool payload, std::uint64_t voxels) {
  run.keys.reserve(voxels);
  if (has_mean(specs)) run.points.reserve(voxels);
  if (payload) run.payloads.reserve(voxels);
  run.partials.resize(specs.size());
  for (std::size_t a = 0; a < specs.size(); ++a) {
    Partial& p = run.partials[a];
    if (specs[a].reduction != Reduction::majority) {
      p.value.reserve(voxels);
    } else {
      p.pair_key.reserve(voxels);
      p.pair_value.reserve(voxels);
      p.pair_count.reserve(voxels);
    }
  }
}

// Majority partials of one chunk: per voxel (starts: its points' range in index), its
// sorted distinct values and their counts.
void reduce_majority(std::span<const Key> voxel_keys, const double* values, const std::uint32_t* index,
                     const std::vector<std::uint32_t>& starts, Partial& p, std::vector<double>& scratch) {
  const std::size_t voxels = voxel_keys.size(), points = starts.back();
  p.pair_key.resize(points);  // at most one pair per point; trimmed below
  p.pair_value.resize(points);
  p.pair_count.resize(points);
  std::size_t o = 0;
  for (std::size_t v = 0; v < voxels; ++v) {
    const std::uint32_t b = starts[v], e = starts[v + 1];
    if (e - b == 1) {  // the common case: one point
      p.pair_key[o] = voxel_keys[v];
      p.pair_value[o] = values[index[b]];
      p.pair_count[o++] = 1;
      continue;
    }
    scratch.clear();
    for (std::uint32_t k = b; k < e; ++k) scratch.push_back(values[index[k]]);
    detail::distinct_counts(scratch, [&](double value, std::uint32_t count) {
      p.pair_key[o] = voxel_keys[v];
      p.pair_value[o] = value;
      p.pair_count[o++] = count;
    });
  }
  p.pair_key.resize(o);
  p.pair_value.resize(o);
  p.pair_count.resize(o);
}

// The most frequent value of each voxel (ties to the smallest: values are sorted),
// stored at the voxel's rank in keys.
void store_majority(std::span<const Key> keys, const Partial& p, AttributeColumn& column) {
  std::size_t k = 0;
  for (std::size_t v = 0; v < keys.size(); ++v) {
    std::size_t best = k;
    for (; k < p.pair_key.size() && p.pair_key[k] == keys[v]; ++k)
      if (p.pair_count[k] > p.pair_count[best]) best = k;
    column.set(v, p.pair_value[best]);
  }
}

}  // namespace

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
  for (std::size_t i = 0; i < n; ++i) {
    Voxel v;
    if (!s.quantizer.to_voxel({xyz[3 * i], xyz[3 * i + 1], xyz[3 * i + 2]}, v)) {
      ++s.points_outside;
      continue;
    }
    s.keys.push_back(encode(v));
    if (per_point) s.index.push_back(static_cast<std::uint32_t>(i));
  }
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
      for (std::size_t v = 0; v < voxels; ++v)
        column.set(v, detail::finish(spec.reduction, p.value[v], counted ? all.points[v] : 1));
    }
    p = Partial{};  // the column holds it now
    tree.attributes().add(std::move(column));
  }
  tree.set_frame(s.quantizer.frame());
  return tree;
}

VOLA_INLINE_NAMESPACE_END
}  // namespace vola
