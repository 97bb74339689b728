// StreamBuilder without attributes or payloads keeps leaf blocks (key >> 6) with their 64
// voxel bits: sorting a chunk's keys into blocks and uniting two block lists in place.
#include "stream_runs.hpp"

namespace vola {
VOLA_INLINE_NAMESPACE_BEGIN
namespace stream {

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


}  // namespace stream
VOLA_INLINE_NAMESPACE_END
}  // namespace vola
