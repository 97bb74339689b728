#include <algorithm>
#include <bit>
#include <string>
#include <vector>

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

}  // namespace

std::vector<Key> enclosed_keys(std::span<const Key> surface, std::uint64_t max_cells) {
  if (surface.empty()) return {};
  Voxel low = decode(surface[0]), high = low;
  for (Key k : surface) {
    const Voxel v = decode(k);
    low = {std::min(low.x, v.x), std::min(low.y, v.y), std::min(low.z, v.z)};
    high = {std::max(high.x, v.x), std::max(high.y, v.y), std::max(high.z, v.z)};
  }
  const std::uint64_t nx = high.x - low.x + 1, ny = high.y - low.y + 1, nz = high.z - low.z + 1;
  if (nx * ny * nz > max_cells)
    throw InvalidArgument("solid fill: the surface's bounding box of " + std::to_string(nx) + " x " +
                          std::to_string(ny) + " x " + std::to_string(nz) + " voxels holds more than " +
                          std::to_string(max_cells) + " cells; use a smaller depth or a larger voxel size");
  // The box padded by one cell per side: the padding is outside and connects all of it.
  const std::uint64_t width = nx + 2, height = ny + 2, depth = nz + 2;
  const auto cell = [&](std::uint64_t x, std::uint64_t y, std::uint64_t z) { return (z * height + y) * width + x; };
  // One bit per cell: surface voxels, then also every outside cell the fill reaches.
  Bits blocked(width * height * depth);
  for (Key k : surface) {
    const Voxel v = decode(k);
    blocked.set(cell(v.x - low.x + 1, v.y - low.y + 1, v.z - low.z + 1));
  }

  // Scanline fill: a popped seed grows to its whole clear run along x, which is marked,
  // and every clear run of the four neighbouring rows that the run overlaps gets a seed.
  std::vector<std::uint64_t> seeds{cell(0, 0, 0)};
  while (!seeds.empty()) {
    const std::uint64_t at = seeds.back();
    seeds.pop_back();
    if (blocked.test(at)) continue;
    const std::uint64_t row = at / width;
    const std::uint64_t row_begin = row * width;
    const std::uint64_t x0 = blocked.clear_run_start(at, row_begin) - row_begin;
    const std::uint64_t x1 = blocked.next(at, row_begin + width, true) - row_begin;
    blocked.set_range(row_begin + x0, row_begin + x1);
    const std::uint64_t y = row % height, z = row / height;
    const auto seed_row = [&](std::uint64_t neighbour_row) {
      const std::uint64_t begin = neighbour_row * width + x0, end = neighbour_row * width + x1;
      for (std::uint64_t p = blocked.next(begin, end, false); p < end; p = blocked.next(p, end, false)) {
        seeds.push_back(p);
        p = blocked.next(p, end, true);
      }
    };
    if (y > 0) seed_row(row - 1);
    if (y + 1 < height) seed_row(row + 1);
    if (z > 0) seed_row(row - height);
    if (z + 1 < depth) seed_row(row + height);
  }

  std::vector<Key> inside;
  for (std::uint64_t z = 1; z <= nz; ++z)
    for (std::uint64_t y = 1; y <= ny; ++y) {
      const std::uint64_t begin = cell(1, y, z), end = cell(nx + 1, y, z);
      for (std::uint64_t p = blocked.next(begin, end, false); p < end; p = blocked.next(p + 1, end, false))
        inside.push_back(encode(static_cast<std::uint32_t>(low.x + (p - begin)), static_cast<std::uint32_t>(low.y + y - 1),
                                static_cast<std::uint32_t>(low.z + z - 1)));
    }
  return inside;
}

}  // namespace vola::mesh
