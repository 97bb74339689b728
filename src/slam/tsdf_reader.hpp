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
    double sum = 0.0;
    if ((x & 7) != 7 && (y & 7) != 7 && (z & 7) != 7) {
      // All eight in one brick (7 cells in 8 per axis): one brick lookup, not eight.
      const TsdfVoxel* b = brick_at(x >> 3, y >> 3, z >> 3);
      if (!b) return false;
      const TsdfVoxel* base = b + local_index(static_cast<std::uint32_t>(x), static_cast<std::uint32_t>(y),
                                              static_cast<std::uint32_t>(z));
      constexpr int kOffsets[8] = {0, 1, kBrickSide, kBrickSide + 1, kBrickSide * kBrickSide,
                                   kBrickSide * kBrickSide + 1, kBrickSide * kBrickSide + kBrickSide,
                                   kBrickSide * kBrickSide + kBrickSide + 1};
      for (int c = 0; c < 8; ++c) {
        const TsdfVoxel& v = base[kOffsets[c]];
        if (!(v.weight > 0.0f)) return false;
        sum += ((c & 1) ? ax : 1 - ax) * ((c & 2) ? ay : 1 - ay) * ((c & 4) ? az : 1 - az) * v.tsdf;
      }
      f = sum;
      return true;
    }
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
