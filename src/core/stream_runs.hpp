// Internal to StreamBuilder: the sorted runs it keeps (voxel keys with their partial
// reductions, or leaf blocks with their voxel bits) and how two runs merge, in place.
#pragma once

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <new>
#include <span>
#include <utility>
#include <vector>

#if defined(__linux__)
#include <sys/mman.h>
#endif

#include "vola/attributes.hpp"
#include "vola/key.hpp"
#include "vola/stream_builder.hpp"
#include "vola/version.hpp"

namespace vola {
VOLA_INLINE_NAMESPACE_BEGIN
namespace stream {

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

// One attribute's partial reduction over the voxels of a run.
struct Partial {
  // mean: the sum; max, min, last: the value; one per voxel (majority: unused)
  Column<double> value;
  // mean: the points without a value (NaN) per voxel; empty while the run has none
  Column<std::uint32_t> nans;
  // majority: the run's distinct (voxel key, value) pairs, sorted, with the number of
  // points of each: flat arrays, so that merging two runs is one linear pass
  KeyVector pair_key;
  Column<double> pair_value;
  Column<std::uint32_t> pair_count;

  std::size_t memory_bytes() const noexcept {
    return value.capacity() * 8 + nans.capacity() * 4 + pair_key.capacity() * 8 + pair_value.capacity() * 8 +
           pair_count.capacity() * 4;
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

inline bool has_mean(std::span<const AttributeSpec> specs) {
  return std::any_of(specs.begin(), specs.end(), [](const AttributeSpec& s) { return s.reduction == Reduction::mean; });
}

// Where a voxel of a merge comes from: the older run, the newer, or both (same key).
enum Source : std::uint8_t { kOlder = 1, kNewer = 2, kBoth = 3 };


// The source of each key of the sorted union of the keys a and b, in order, into
// `from`; returns the union's size.
std::size_t plan_merge(std::span<const Key> a, std::span<const Key> b, std::vector<Source>& from);

// The union of two runs with attributes or payloads, left in `older`; voxels in both
// combine their partials (the newer's payload wins: it holds the later point). Column
// by column, so that each pass is a tight loop over arrays.
void merge_into(Run& older, const Run& newer, std::span<const AttributeSpec> specs, bool payload,
                std::vector<Source>& plan_buffer);

// expect_points() reserves at most this many voxels per column (1 GiB of address space
// for 8-byte values): the kernel refuses single allocations far beyond its memory, and
// beyond this the columns grow as they go.
constexpr std::uint64_t kMaxReservedVoxels = std::uint64_t{1} << 27;

// Room for `voxels` in every column the run uses (address space only).
void reserve_voxels(Run& run, std::span<const AttributeSpec> specs, bool payload, std::uint64_t voxels);

// Majority partials of one chunk: per voxel (starts: its points' range in index), its
// sorted distinct values and their counts.
void reduce_majority(std::span<const Key> voxel_keys, const double* values, const std::uint32_t* index,
                     const std::vector<std::uint32_t>& starts, Partial& p, std::vector<double>& scratch);

// The most frequent value of each voxel (ties to the smallest: values are sorted),
// stored at the voxel's rank in keys.
void store_majority(std::span<const Key> keys, const Partial& p, AttributeColumn& column);

// Occupancy only: sorts the voxel keys[0, n) by leaf block (key >> 6; LSD radix over
// only the block bits that vary among them, in digits of at most 12 bits, a pass
// skipped when its digit is the same in every key) and collapses each block's keys
// into its 64 voxel bits. `buffer` holds n keys; `counts` is scratch. Returns the
// number of blocks m: their sorted unique keys in blocks[0, m), their bits in
// bits[0, m), where (blocks, bits) is (keys, buffer) or (buffer, keys).
std::size_t sort_blocks(Key* keys, Key* buffer, std::size_t n, std::vector<std::uint32_t>& counts, Key*& blocks,
                        Key*& bits);

// Blocks in both of the sorted unique block lists a and b (only where their ranges
// overlap: chunks of a survey often cover their own stretch of the key space).
std::size_t common_blocks(std::span<const Key> a, std::span<const Key> b);

// The union of the sorted unique blocks a (with bits) and b (with bits) into a itself,
// from the back, the bits of a block in both OR-ed. a's vectors need room for
// `united` blocks (a.size() + b.size() - common_blocks(a, b)). A block is written at
// or after the position it is read from, so nothing is overwritten before it is read,
// and the blocks of a below b's first stay where they are.
void unite_in_place(KeyVector& a, KeyVector& a_bits, std::span<const Key> b, std::span<const Key> b_bits,
                    std::size_t united);

}  // namespace stream
VOLA_INLINE_NAMESPACE_END
}  // namespace vola
