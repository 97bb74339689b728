#include "vola/stream_builder.hpp"

#include <algorithm>
#include <bit>
#include <limits>
#include <memory>
#include <new>
#include <utility>

#include "emit.hpp"

#if defined(__linux__)
#include <sys/mman.h>
#endif
#include "vola/error.hpp"

namespace vola {
VOLA_INLINE_NAMESPACE_BEGIN

namespace {

// One attribute's partial reduction over the voxels of a run.
struct Partial {
  std::vector<double> value;          // mean: sum; max, min, last: the value
  std::vector<std::uint32_t> count;   // mean: number of points
  // majority: for voxel i, (histogram_value, histogram_count)[offsets[i] .. offsets[i+1])
  // sorted by value
  std::vector<std::uint64_t> offsets;
  std::vector<double> histogram_value;
  std::vector<std::uint32_t> histogram_count;

  std::size_t memory_bytes() const noexcept {
    return value.capacity() * 8 + count.capacity() * 4 + offsets.capacity() * 8 + histogram_value.capacity() * 8 +
           histogram_count.capacity() * 4;
  }
};

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

// Sorted unique voxel keys with their partial reductions; occupancy only (no
// attributes, no payloads): sorted unique leaf block keys (voxel key >> 6) with their
// 64 voxel bits each in `bits`, a word per block instead of a key per voxel.
struct Run {
  KeyVector keys;
  KeyVector bits;
  std::vector<std::uint64_t> payloads;
  std::vector<Partial> partials;

  std::size_t memory_bytes() const noexcept {
    std::size_t bytes = keys.capacity() * 8 + bits.capacity() * 8 + payloads.capacity() * 8;
    for (const auto& p : partials) bytes += p.memory_bytes();
    return bytes;
  }
};

// Appends voxel `i` of `from` to `to` (as a new voxel).
void append(const Run& from, std::size_t i, Run& to, std::span<const AttributeSpec> specs, bool payload) {
  to.keys.push_back(from.keys[i]);
  if (payload) to.payloads.push_back(from.payloads[i]);
  for (std::size_t a = 0; a < specs.size(); ++a) {
    const Partial& p = from.partials[a];
    Partial& q = to.partials[a];
    if (specs[a].reduction == Reduction::majority) {
      q.histogram_value.insert(q.histogram_value.end(), p.histogram_value.begin() + p.offsets[i],
                               p.histogram_value.begin() + p.offsets[i + 1]);
      q.histogram_count.insert(q.histogram_count.end(), p.histogram_count.begin() + p.offsets[i],
                               p.histogram_count.begin() + p.offsets[i + 1]);
      q.offsets.push_back(q.histogram_value.size());
    } else {
      q.value.push_back(p.value[i]);
      if (specs[a].reduction == Reduction::mean) q.count.push_back(p.count[i]);
    }
  }
}

// Appends the combination of voxel i of `older` and voxel j of `newer` (same key).
void append_combined(const Run& older, std::size_t i, const Run& newer, std::size_t j, Run& to,
                     std::span<const AttributeSpec> specs, bool payload) {
  to.keys.push_back(older.keys[i]);
  if (payload) to.payloads.push_back(newer.payloads[j]);  // the later point wins
  for (std::size_t a = 0; a < specs.size(); ++a) {
    const Partial& p = older.partials[a];
    const Partial& r = newer.partials[a];
    Partial& q = to.partials[a];
    switch (specs[a].reduction) {
      case Reduction::mean:
        q.value.push_back(p.value[i] + r.value[j]);
        q.count.push_back(p.count[i] + r.count[j]);
        break;
      case Reduction::max: q.value.push_back(std::max(p.value[i], r.value[j])); break;
      case Reduction::min: q.value.push_back(std::min(p.value[i], r.value[j])); break;
      case Reduction::last: q.value.push_back(r.value[j]); break;
      case Reduction::majority: {
        std::uint64_t x = p.offsets[i], y = r.offsets[j];
        const std::uint64_t x_end = p.offsets[i + 1], y_end = r.offsets[j + 1];
        while (x < x_end || y < y_end) {
          if (y == y_end || (x < x_end && p.histogram_value[x] < r.histogram_value[y])) {
            q.histogram_value.push_back(p.histogram_value[x]);
            q.histogram_count.push_back(p.histogram_count[x++]);
          } else if (x == x_end || r.histogram_value[y] < p.histogram_value[x]) {
            q.histogram_value.push_back(r.histogram_value[y]);
            q.histogram_count.push_back(r.histogram_count[y++]);
          } else {
            q.histogram_value.push_back(p.histogram_value[x]);
            q.histogram_count.push_back(p.histogram_count[x++] + r.histogram_count[y++]);
          }
        }
        q.offsets.push_back(q.histogram_value.size());
        break;
      }
    }
  }
}

// Majority partials of one chunk: per voxel, the sorted distinct values and their counts.
void reduce_majority(const double* values, const std::uint32_t* index, const std::vector<std::uint32_t>& starts,
                     Partial& p) {
  std::vector<double> scratch;
  const std::size_t voxels = starts.size() - 1;
  p.offsets.reserve(voxels + 1);
  for (std::size_t v = 0; v < voxels; ++v) {
    const std::uint32_t b = starts[v], e = starts[v + 1];
    if (e - b == 1) {  // the common case: one point
      p.histogram_value.push_back(values[index[b]]);
      p.histogram_count.push_back(1);
    } else {
      scratch.clear();
      for (std::uint32_t k = b; k < e; ++k) scratch.push_back(values[index[k]]);
      std::sort(scratch.begin(), scratch.end());
      for (std::size_t k = 0; k < scratch.size();) {
        std::size_t l = k;
        while (l < scratch.size() && scratch[l] == scratch[k]) ++l;
        p.histogram_value.push_back(scratch[k]);
        p.histogram_count.push_back(static_cast<std::uint32_t>(l - k));
        k = l;
      }
    }
    p.offsets.push_back(p.histogram_value.size());
  }
}

Run empty_run(std::span<const AttributeSpec> specs) {
  Run run;
  run.partials.resize(specs.size());
  for (std::size_t a = 0; a < specs.size(); ++a)
    if (specs[a].reduction == Reduction::majority) run.partials[a].offsets.push_back(0);
  return run;
}

Run merge(const Run& older, const Run& newer, std::span<const AttributeSpec> specs, bool payload) {
  Run out = empty_run(specs);
  out.keys.reserve(older.keys.size() + newer.keys.size());
  std::size_t i = 0, j = 0;
  while (i < older.keys.size() || j < newer.keys.size()) {
    if (j == newer.keys.size() || (i < older.keys.size() && older.keys[i] < newer.keys[j])) {
      append(older, i++, out, specs, payload);
    } else if (i == older.keys.size() || newer.keys[j] < older.keys[i]) {
      append(newer, j++, out, specs, payload);
    } else {
      append_combined(older, i++, newer, j++, out, specs, payload);
    }
  }
  return out;
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
    KeyVector keys = take(united, 2 * united), bits = take(united, 2 * united);
    keys.resize(older.keys.size());
    bits.resize(older.keys.size());
    std::copy(older.keys.begin(), older.keys.end(), keys.begin());
    std::copy(older.bits.begin(), older.bits.end(), bits.begin());
    std::swap(keys, older.keys);
    std::swap(bits, older.bits);
    const std::size_t live = older.keys.capacity() + older.bits.capacity();
    give(std::move(keys), live);
    give(std::move(bits), live);
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
  run.keys = take(m);
  run.bits = take(m);
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
      runs[runs.size() - 2] = merge(runs[runs.size() - 2], runs.back(), specs, payload);
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

  Run run = empty_run(s.specs);
  {
    // Runs of equal keys hold one voxel's points in input order: [starts[v], starts[v+1]).
    std::vector<std::uint32_t>& starts = s.starts;
    starts.clear();
    for (std::size_t k = 0; k < s.keys.size(); ++k) {
      if (k == 0 || s.keys[k] != s.keys[k - 1]) {
        starts.push_back(static_cast<std::uint32_t>(k));
        run.keys.push_back(s.keys[k]);
      }
    }
    starts.push_back(static_cast<std::uint32_t>(s.keys.size()));
    const std::size_t voxels = run.keys.size();
    const std::uint32_t* index = s.index.data();
    if (s.payload) {
      run.payloads.resize(voxels);
      for (std::size_t v = 0; v < voxels; ++v) run.payloads[v] = payloads[index[starts[v + 1] - 1]];
    }
    // Attribute by attribute, each with a tight loop over the voxels.
    for (std::size_t a = 0; a < s.specs.size(); ++a) {
      const double* values_of = values[a].data();
      Partial& p = run.partials[a];
      const Reduction reduction = s.specs[a].reduction;
      if (reduction == Reduction::majority) {
        reduce_majority(values_of, index, starts, p);
        continue;
      }
      p.value.resize(voxels);
      if (reduction == Reduction::mean) p.count.resize(voxels);
      for (std::size_t v = 0; v < voxels; ++v) {
        const std::uint32_t b = starts[v], e = starts[v + 1];
        double r = values_of[index[reduction == Reduction::last ? e - 1 : b]];
        switch (reduction) {
          case Reduction::mean:
            for (std::uint32_t k = b + 1; k < e; ++k) r += values_of[index[k]];
            p.count[v] = e - b;
            break;
          case Reduction::max:
            for (std::uint32_t k = b + 1; k < e; ++k) r = std::max(r, values_of[index[k]]);
            break;
          case Reduction::min:
            for (std::uint32_t k = b + 1; k < e; ++k) r = std::min(r, values_of[index[k]]);
            break;
          default: break;
        }
        p.value[v] = r;
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
  Run all = empty_run(s.specs);
  // The final unions' outputs outgrow every spare: give the memory back first.
  s.spare.clear();
  s.spare.shrink_to_fit();
  s.sort_buffer = KeyVector();
  s.chunk_keys = KeyVector();
  if (s.specs.empty() && !s.payload && !s.runs.empty()) {
    // Occupancy only: a union is exact in any order, so merge the smallest (newest)
    // runs first: each key is then copied about twice, not once per run.
    all = std::move(s.runs.back());
    s.runs.pop_back();
    while (!s.runs.empty()) {
      s.unite(s.runs.back(), all);
      all = std::move(s.runs.back());
      s.runs.pop_back();
      s.spare.clear();
    }
  }
  for (auto& run : s.runs) {
    all = merge(all, run, s.specs, s.payload);
    run = Run{};
  }
  s.runs.clear();
  const int depth = s.quantizer.depth();
  Tree tree = s.specs.empty() && !s.payload ? detail::emit_block_levels(all.keys, all.bits, depth)
                                            : detail::emit_levels(all.keys, depth, all.payloads, s.payload);
  if (s.payload) tree.set_voxel_payloads(std::move(all.payloads));
  const std::size_t voxels = all.keys.size();
  for (std::size_t a = 0; a < s.specs.size(); ++a) {
    const AttributeSpec& spec = s.specs[a];
    const Partial& p = all.partials[a];
    AttributeColumn column(spec.name, spec.type, spec.reduction, voxels);
    for (std::size_t v = 0; v < voxels; ++v) {
      switch (spec.reduction) {
        case Reduction::mean: column.set(v, p.value[v] / p.count[v]); break;
        case Reduction::majority: {
          // The most frequent value; ties go to the smallest (the histogram is sorted).
          std::uint64_t best = p.offsets[v];
          for (std::uint64_t k = p.offsets[v]; k < p.offsets[v + 1]; ++k)
            if (p.histogram_count[k] > p.histogram_count[best]) best = k;
          column.set(v, p.histogram_value[best]);
          break;
        }
        default: column.set(v, p.value[v]); break;
      }
    }
    tree.attributes().add(std::move(column));
  }
  tree.set_frame(s.quantizer.frame());
  return tree;
}

VOLA_INLINE_NAMESPACE_END
}  // namespace vola
