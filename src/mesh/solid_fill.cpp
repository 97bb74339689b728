#include <algorithm>
#include <bit>
#include <string>
#include <vector>

#include "vola/builder.hpp"
#include "vola/error.hpp"
#include "vola/mesh/solid.hpp"

namespace vola::mesh {

namespace {

// A flat bit array with the run searches a scanline fill needs.
class Bits {
 public:
  explicit Bits(std::uint64_t size) : words_((size + 63) / 64, 0) {}

  bool test(std::uint64_t i) const noexcept { return (words_[i >> 6] >> (i & 63)) & 1u; }
  void set(std::uint64_t i) noexcept { words_[i >> 6] |= std::uint64_t{1} << (i & 63); }
  void clear(std::uint64_t i) noexcept { words_[i >> 6] &= ~(std::uint64_t{1} << (i & 63)); }
  // Bits [pos, pos + n) as the low n bits of a word, 1 <= n <= 32.
  std::uint64_t get(std::uint64_t pos, unsigned n) const noexcept {
    const unsigned bit = static_cast<unsigned>(pos & 63);
    std::uint64_t v = words_[pos >> 6] >> bit;
    if (bit + n > 64) v |= words_[(pos >> 6) + 1] << (64 - bit);
    return v & ((std::uint64_t{1} << n) - 1);
  }

  void set_range(std::uint64_t begin, std::uint64_t end) noexcept {
    while (begin < end) {
      const std::uint64_t bit = begin & 63;
      const std::uint64_t n = std::min<std::uint64_t>(64 - bit, end - begin);
      const std::uint64_t mask = n == 64 ? ~std::uint64_t{0} : ((std::uint64_t{1} << n) - 1) << bit;
      words_[begin >> 6] |= mask;
      begin += n;
    }
  }

  // The first bit in [begin, end) equal to `value`, or end.
  std::uint64_t next(std::uint64_t begin, std::uint64_t end, bool value) const noexcept {
    if (begin >= end) return end;
    std::uint64_t w = begin >> 6;
    std::uint64_t word = (value ? words_[w] : ~words_[w]) & (~std::uint64_t{0} << (begin & 63));
    for (;;) {
      if (word) return std::min(end, (w << 6) + static_cast<std::uint64_t>(std::countr_zero(word)));
      if (++w << 6 >= end) return end;
      word = value ? words_[w] : ~words_[w];
    }
  }

  // The smallest s >= begin with every bit of [s, pos) clear.
  std::uint64_t clear_run_start(std::uint64_t pos, std::uint64_t begin) const noexcept {
    if (pos <= begin) return begin;
    const std::uint64_t last = pos - 1;
    std::uint64_t w = last >> 6;
    const unsigned top = static_cast<unsigned>(last & 63);
    std::uint64_t word = words_[w] & (top == 63 ? ~std::uint64_t{0} : (std::uint64_t{2} << top) - 1);
    for (;;) {
      if (word) return std::max(begin, (w << 6) + 64 - static_cast<std::uint64_t>(std::countl_zero(word)));
      if (w << 6 <= begin) return begin;
      word = words_[--w];
    }
  }

 private:
  std::vector<std::uint64_t> words_;
};

// The surface's bounding box padded by one cell per side (the padding is outside and
// connects all of it), one bit per cell: first the surface, then also every outside
// cell the fill reaches.
class OutsideFill {
 public:
  OutsideFill(std::span<const Key> surface, std::uint64_t max_cells) {
    low_ = high_ = decode(surface[0]);
    for (Key k : surface) {
      const Voxel v = decode(k);
      low_ = {std::min(low_.x, v.x), std::min(low_.y, v.y), std::min(low_.z, v.z)};
      high_ = {std::max(high_.x, v.x), std::max(high_.y, v.y), std::max(high_.z, v.z)};
    }
    const std::uint64_t nx = high_.x - low_.x + 1, ny = high_.y - low_.y + 1, nz = high_.z - low_.z + 1;
    if (nx * ny * nz > max_cells)
      throw InvalidArgument("solid fill: the surface's bounding box of " + std::to_string(nx) + " x " +
                            std::to_string(ny) + " x " + std::to_string(nz) + " voxels holds more than " +
                            std::to_string(max_cells) + " cells; use a smaller depth or a larger voxel size");
    width_ = nx + 2;
    height_ = ny + 2;
    layers_ = nz + 2;
    blocked_ = Bits(width_ * height_ * layers_);
    for (Key k : surface) blocked_.set(index(decode(k)));
    fill();
  }

  const Voxel& low() const noexcept { return low_; }
  const Voxel& high() const noexcept { return high_; }
  // Bit of voxel v (inside the bounding box): surface or outside.
  std::uint64_t index(const Voxel& v) const noexcept { return cell(v.x - low_.x + 1, v.y - low_.y + 1, v.z - low_.z + 1); }
  const Bits& blocked() const noexcept { return blocked_; }
  // After this, a set bit means outside, a clear one surface or enclosed.
  void clear_surface(std::span<const Key> surface) noexcept {
    for (Key k : surface) blocked_.clear(index(decode(k)));
  }

 private:
  std::uint64_t cell(std::uint64_t x, std::uint64_t y, std::uint64_t z) const noexcept {
    return (z * height_ + y) * width_ + x;
  }

  // Scanline fill: a popped seed grows to its whole clear run along x, which is marked,
  // and every clear run of the four neighbouring rows that the run overlaps gets a seed.
  void fill() {
    std::vector<std::uint64_t> seeds{cell(0, 0, 0)};
    while (!seeds.empty()) {
      const std::uint64_t at = seeds.back();
      seeds.pop_back();
      if (blocked_.test(at)) continue;
      const std::uint64_t row = at / width_;
      const std::uint64_t row_begin = row * width_;
      const std::uint64_t x0 = blocked_.clear_run_start(at, row_begin) - row_begin;
      const std::uint64_t x1 = blocked_.next(at, row_begin + width_, true) - row_begin;
      blocked_.set_range(row_begin + x0, row_begin + x1);
      const std::uint64_t y = row % height_, z = row / height_;
      const auto seed_row = [&](std::uint64_t neighbour_row) {
        const std::uint64_t begin = neighbour_row * width_ + x0, end = neighbour_row * width_ + x1;
        for (std::uint64_t p = blocked_.next(begin, end, false); p < end; p = blocked_.next(p, end, false)) {
          seeds.push_back(p);
          p = blocked_.next(p, end, true);
        }
      };
      if (y > 0) seed_row(row - 1);
      if (y + 1 < height_) seed_row(row + 1);
      if (z > 0) seed_row(row - height_);
      if (z + 1 < layers_) seed_row(row + height_);
    }
  }

  Voxel low_, high_;
  std::uint64_t width_ = 0, height_ = 0, layers_ = 0;
  Bits blocked_{0};
};

// Emits the sparse levels of "not outside" straight from the bits, depth first in key
// order: the words of each level come out in file order, and no voxel list is made.
class SolidLevels {
 public:
  SolidLevels(const OutsideFill& fill, int depth) : fill_(fill), depth_(depth), levels_(static_cast<std::size_t>(depth)) {}

  Tree tree() {
    levels_[0].push_back(block_word(0, {0, 0, 0}));
    std::vector<std::uint64_t> words;
    for (const auto& level : levels_) words.insert(words.end(), level.begin(), level.end());
    return Tree::from_levels(depth_, false, std::move(words), "solid fill");
  }

 private:
  // The word of the block whose cells at `level` are 4 * parent + (0..3) per axis;
  // the words of its non-empty children's blocks are appended to the deeper levels.
  std::uint64_t block_word(int level, const Voxel& parent) {
    const Voxel& lo = fill_.low();
    const Voxel& hi = fill_.high();
    if (level == depth_ - 1) return leaf_word(parent);
    const unsigned shift = 2u * static_cast<unsigned>(depth_ - 1 - level);  // voxels per cell: 4^shift per axis
    std::uint64_t word = 0;
    for (unsigned bit = 0; bit < 64; ++bit) {
      const Voxel c{4 * parent.x + (bit & 3u), 4 * parent.y + ((bit >> 2) & 3u), 4 * parent.z + (bit >> 4)};
      // The cell's voxels [c << shift, ((c + 1) << shift) - 1] must meet the bounding box.
      if ((std::uint64_t{c.x} << shift) > hi.x || (std::uint64_t{c.y} << shift) > hi.y ||
          (std::uint64_t{c.z} << shift) > hi.z || ((std::uint64_t{c.x} + 1) << shift) <= lo.x ||
          ((std::uint64_t{c.y} + 1) << shift) <= lo.y || ((std::uint64_t{c.z} + 1) << shift) <= lo.z)
        continue;
      const std::uint64_t child = block_word(level + 1, c);
      if (child) {
        word |= std::uint64_t{1} << bit;
        levels_[static_cast<std::size_t>(level + 1)].push_back(child);
      }
    }
    return word;
  }

  // A leaf block: its 16 rows of 4 voxels along x, each read from the bits at once.
  std::uint64_t leaf_word(const Voxel& parent) const noexcept {
    const Voxel& lo = fill_.low();
    const Voxel& hi = fill_.high();
    const std::uint32_t x0 = 4 * parent.x, from = std::max(x0, lo.x), to = std::min(x0 + 3, hi.x);
    if (from > to) return 0;
    const unsigned n = to - from + 1, offset = from - x0;
    std::uint64_t word = 0;
    for (unsigned row = 0; row < 16; ++row) {
      const std::uint32_t y = 4 * parent.y + (row & 3u), z = 4 * parent.z + (row >> 2);
      if (y < lo.y || y > hi.y || z < lo.z || z > hi.z) continue;
      const std::uint64_t outside = fill_.blocked().get(fill_.index({from, y, z}), n);
      word |= (~outside & ((std::uint64_t{1} << n) - 1)) << (4 * row + offset);
    }
    return word;
  }

  const OutsideFill& fill_;
  int depth_;
  std::vector<std::vector<std::uint64_t>> levels_;
};

}  // namespace

std::vector<Key> enclosed_keys(std::span<const Key> surface, std::uint64_t max_cells) {
  if (surface.empty()) return {};
  const OutsideFill fill(surface, max_cells);
  const Voxel& low = fill.low();
  const Voxel& high = fill.high();
  std::vector<Key> inside;
  for (std::uint32_t z = low.z; z <= high.z; ++z)
    for (std::uint32_t y = low.y; y <= high.y; ++y) {
      const std::uint64_t begin = fill.index({low.x, y, z}), end = begin + (high.x - low.x + 1);
      for (std::uint64_t p = fill.blocked().next(begin, end, false); p < end; p = fill.blocked().next(p + 1, end, false))
        inside.push_back(encode(static_cast<std::uint32_t>(low.x + (p - begin)), y, z));
    }
  return inside;
}

Tree solid_tree(std::span<const Key> surface, int depth, std::uint64_t max_cells) {
  if (surface.empty()) return build_from_sorted_keys({}, depth);
  OutsideFill fill(surface, max_cells);
  fill.clear_surface(surface);
  return SolidLevels(fill, depth).tree();
}

}  // namespace vola::mesh
