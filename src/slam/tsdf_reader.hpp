// Reading voxels of either TSDF store with recently used bricks remembered (internal).
#pragma once

#include <Eigen/Geometry>
#include <array>
#include <cmath>
#include <cstdint>

#include "vola/slam/tsdf_store.hpp"

namespace vola::slam {

// Voxel reads with the bricks last used remembered in a small direct-mapped cache (rays
// and neighbours stay in a few bricks for many reads; a trilinear read at a brick's
// corner touches up to eight, which a single remembered brick kept evicting: the index
// lookups were a quarter of vola fuse's time). One per thread.
template <class Store>
class TsdfReader {
 public:
  explicit TsdfReader(const Store& store) : store_(store), side_(store.geometry().bricks_per_side) {}
  const TsdfVoxel* brick_at(std::int64_t bx, std::int64_t by, std::int64_t bz) {
    if (bx < 0 || by < 0 || bz < 0 || bx >= side_ || by >= side_ || bz >= side_) return nullptr;
    const auto key = static_cast<std::uint64_t>(bx) | static_cast<std::uint64_t>(by) << 21 |
                     static_cast<std::uint64_t>(bz) << 42;
    Entry& e = cache_[static_cast<std::size_t>((bx * 73856093) ^ (by * 19349663) ^ (bz * 83492791)) & (kCache - 1)];
    if (e.key != key) {
      e.key = key;
      e.brick = store_.brick(
          BrickCoord{static_cast<std::uint32_t>(bx), static_cast<std::uint32_t>(by), static_cast<std::uint32_t>(bz)});
    }
    return e.brick;
  }
  // The observed voxel (weight > 0) at integer coordinates, or nullptr.
  const TsdfVoxel* voxel(std::int64_t x, std::int64_t y, std::int64_t z) {
    const TsdfVoxel* b = brick_at(x >> 3, y >> 3, z >> 3);
    if (!b) return nullptr;
    const TsdfVoxel* v = b + local_index(static_cast<std::uint32_t>(x), static_cast<std::uint32_t>(y),
                                         static_cast<std::uint32_t>(z));
    return v->weight > 0.0f ? v : nullptr;
  }
  // Trilinear TSDF at grid position g (voxel centres at integer + 0.5); false unless all
  // eight voxels are observed.
  bool trilinear(const Eigen::Vector3d& g, double& f) {
    const Eigen::Vector3d s = g - Eigen::Vector3d::Constant(0.5);
    const double fx = std::floor(s.x()), fy = std::floor(s.y()), fz = std::floor(s.z());
    const auto x = static_cast<std::int64_t>(fx), y = static_cast<std::int64_t>(fy), z = static_cast<std::int64_t>(fz);
    const double ax = s.x() - fx, ay = s.y() - fy, az = s.z() - fz;
    if ((x & 7) != 7 && (y & 7) != 7 && (z & 7) != 7) {
      // All eight in one brick (7 cells in 8 per axis): one brick lookup, not eight.
      const TsdfVoxel* b = brick_at(x >> 3, y >> 3, z >> 3);
      if (!b) return false;
      const TsdfVoxel* base = b + local_index(static_cast<std::uint32_t>(x), static_cast<std::uint32_t>(y),
                                              static_cast<std::uint32_t>(z));
      // Straight-line: all eight weights tested at once, then seven lerps (a loop with
      // a test and three selects per corner was a sixth of vola fuse's time).
      constexpr int kY = kBrickSide, kZ = kBrickSide * kBrickSide;
      const TsdfVoxel *v000 = base, *v100 = base + 1, *v010 = base + kY, *v110 = base + kY + 1, *v001 = base + kZ,
                      *v101 = base + kZ + 1, *v011 = base + kZ + kY, *v111 = base + kZ + kY + 1;
      const bool observed = (v000->weight > 0.0f) & (v100->weight > 0.0f) & (v010->weight > 0.0f) &
                            (v110->weight > 0.0f) & (v001->weight > 0.0f) & (v101->weight > 0.0f) &
                            (v011->weight > 0.0f) & (v111->weight > 0.0f);
      if (!observed) return false;
      const auto lerp = [](double from, double to, double t) { return from + (to - from) * t; };
      const double y0 = lerp(lerp(v000->tsdf, v100->tsdf, ax), lerp(v010->tsdf, v110->tsdf, ax), ay);
      const double y1 = lerp(lerp(v001->tsdf, v101->tsdf, ax), lerp(v011->tsdf, v111->tsdf, ax), ay);
      f = lerp(y0, y1, az);
      return true;
    }
    double sum = 0.0;
    for (int c = 0; c < 8; ++c) {
      const TsdfVoxel* v = voxel(x + (c & 1), y + ((c >> 1) & 1), z + (c >> 2));
      if (!v) return false;
      sum += ((c & 1) ? ax : 1 - ax) * ((c & 2) ? ay : 1 - ay) * ((c & 4) ? az : 1 - az) * v->tsdf;
    }
    f = sum;
    return true;
  }

 private:
  static constexpr std::size_t kCache = 64;
  struct Entry {
    std::uint64_t key = ~std::uint64_t{0};  // no brick has it (coordinates are under 2^21)
    const TsdfVoxel* brick = nullptr;
  };
  const Store& store_;
  std::int64_t side_;
  std::array<Entry, kCache> cache_{};
};

}  // namespace vola::slam
