// Fuzz entry point for the mesh code: bytes -> a quantizer and up to 16 triangles (raw
// doubles, so NaN, infinities, huge and subnormal values all come up, or 16-bit fixed
// point, so that vertices land exactly on cell faces) -> surface voxels, the solid fill
// and terrain columns. Only vola::Error may escape; a crash, a sanitizer report or a
// broken invariant (abort) is a finding:
//   - surface keys are sorted, unique and inside the grid, and each one's cell box
//     touches a usable triangle (the exact test); on small grids they are exactly
//     the brute force over every voxel;
//   - the solid tree is the surface plus enclosed_keys, nothing else;
//   - terrain columns stay inside the grid and within their voxel limit.
#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <vector>

#include "vola/builder.hpp"
#include "vola/error.hpp"
#include "vola/mesh/solid.hpp"
#include "vola/mesh/terrain.hpp"
#include "vola/mesh/voxelize.hpp"

namespace {

void check(bool invariant) {
  if (!invariant) std::abort();
}

class ByteReader {
 public:
  ByteReader(const std::uint8_t* data, std::size_t size) : data_(data), size_(size) {}
  std::size_t left() const noexcept { return size_ - at_; }
  std::uint8_t byte() { return at_ < size_ ? data_[at_++] : 0; }
  double raw_double() {
    std::uint64_t bits = 0;
    for (int i = 0; i < 8; ++i) bits |= std::uint64_t{byte()} << (8 * i);
    double d;
    std::memcpy(&d, &bits, 8);
    return d;
  }
  double fixed() {  // int16 / 64: [-512, 512) in steps of 1/64
    const auto lo = byte(), hi = byte();
    return static_cast<std::int16_t>(lo | (hi << 8)) / 64.0;
  }

 private:
  const std::uint8_t* data_;
  std::size_t size_;
  std::size_t at_ = 0;
};

void exercise(const vola::Quantizer& q, const std::vector<vola::mesh::Triangle>& triangles, bool solid,
              double base) {
  const std::uint32_t side = vola::side_of(q.depth());
  vola::mesh::VoxelizeReport report;
  const std::vector<vola::Key> keys = vola::mesh::surface_keys(triangles, q, &report);
  check(report.triangles == triangles.size() && report.surface_voxels == keys.size());
  check(report.skipped + report.outside <= triangles.size());
  const std::vector<vola::mesh::TriangleBoxTest> tests(triangles.begin(), triangles.end());
  for (std::size_t i = 0; i < keys.size(); ++i) {
    check(i == 0 || keys[i - 1] < keys[i]);
    const vola::Voxel v = vola::decode(keys[i]);
    check(v.x < side && v.y < side && v.z < side);
    const vola::Box cell = q.cell_box(v);
    check(std::any_of(tests.begin(), tests.end(), [&](const auto& t) { return t.overlaps(cell); }));
  }
  if (std::uint64_t{side} * side * side * triangles.size() <= 1u << 16) {
    std::vector<vola::Key> brute;
    for (std::uint32_t z = 0; z < side; ++z)
      for (std::uint32_t y = 0; y < side; ++y)
        for (std::uint32_t x = 0; x < side; ++x)
          for (const auto& t : tests)
            if (t.overlaps(q.cell_box({x, y, z}))) {
              brute.push_back(vola::encode(x, y, z));
              break;
            }
    std::sort(brute.begin(), brute.end());
    check(brute == keys);
  }
  if (solid) {
    const std::vector<vola::Key> inside = vola::mesh::enclosed_keys(keys);
    const vola::Tree tree = vola::mesh::solid_tree(keys, q.depth());
    check(tree.voxel_count() == keys.size() + inside.size());
    for (vola::Key k : keys) check(tree.contains(vola::decode(k)));
    for (vola::Key k : inside) check(tree.contains(vola::decode(k)));
  }
  vola::PointCloud points;
  for (const auto& t : triangles)
    for (const auto& p : t) points.xyz.insert(points.xyz.end(), p.begin(), p.end());
  vola::mesh::TerrainOptions terrain;
  terrain.base = base;
  terrain.max_voxels = 1u << 16;
  try {
    const vola::Tree columns = vola::mesh::terrain_columns(points, q, terrain);
    check(columns.voxel_count() <= terrain.max_voxels);
  } catch (const vola::InvalidArgument&) {
    // over the voxel limit: refusing is the expected outcome
  }
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  ByteReader in(data, size);
  const std::uint8_t flags = in.byte();
  const bool grid = flags & 1u, solid = flags & 2u, fixed = flags & 4u;
  const int depth = 1 + (flags >> 3) % 3;
  const auto value = [&] { return fixed ? in.fixed() : in.raw_double(); };
  try {
    vola::Quantizer q = vola::Quantizer::toolkit({}, 1);
    if (grid) {
      const vola::Point origin{value(), value(), value()};
      q = vola::Quantizer::grid(origin, fixed ? std::abs(value()) : in.raw_double(), depth);
    } else {
      vola::Box box{{value(), value(), value()}, {value(), value(), value()}};
      for (int a = 0; a < 3; ++a)
        if (box.min[a] > box.max[a]) std::swap(box.min[a], box.max[a]);
      q = vola::Quantizer::toolkit(box, depth);
    }
    const double base = value();
    const std::size_t bytes_per_triangle = fixed ? 18 : 72;
    std::vector<vola::mesh::Triangle> triangles;
    while (in.left() >= bytes_per_triangle && triangles.size() < 16) {
      vola::mesh::Triangle t;
      for (auto& p : t)
        for (auto& c : p) c = value();
      triangles.push_back(t);
    }
    exercise(q, triangles, solid, base);
  } catch (const vola::Error&) {
    // a quantizer the arguments do not allow: refused with the library's error
  }
  return 0;
}
