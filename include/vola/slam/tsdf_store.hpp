// Storage of a truncated signed distance field (TSDF) in bricks of 8^3 voxels.
//
// The grid: voxel (i, j, k) is the cube origin + [i, i+1) x [j, j+1) x [k, k+1) times
// voxel_size; brick (a, b, c) holds voxels 8a..8a+7 etc. Two stores share one
// interface, so the fusion pipeline (fusion.hpp) is the same code over either:
//   SparseTsdfStore: only bricks near observed surfaces exist, found through a mutable
//     VOLA-style index (one 64-bit occupancy word per 4x4x4 node, children in popcount
//     rank order, brick_index.hpp);
//   DenseTsdfStore: every voxel of the extent in one array (what KinectFusion keeps),
//     plus one bit per brick saying whether the pipeline has touched it.
// A brick that was never allocated reads as nullptr in both, so the pipeline sees the
// same values and takes the same decisions whichever store holds them.
#pragma once

#include <cstddef>
#include <cstdint>
#include <memory>
#include <vector>

#include <Eigen/Geometry>

#include "vola/slam/brick_index.hpp"

namespace vola::slam {

inline constexpr int kBrickSide = 8;
inline constexpr int kBrickVoxels = kBrickSide * kBrickSide * kBrickSide;

struct TsdfVoxel {
  float tsdf = 1.0f;    // signed distance / truncation, in [-1, 1]
  float weight = 0.0f;  // 0 = never observed
  std::uint8_t r = 0, g = 0, b = 0, pad = 0;
};

struct BrickCoord {
  std::uint32_t x = 0, y = 0, z = 0;
  friend bool operator==(const BrickCoord&, const BrickCoord&) = default;
  friend auto operator<=>(const BrickCoord&, const BrickCoord&) = default;
};

// Voxel (i, j, k) within its brick: i + 8 (j + 8 k).
inline int local_index(std::uint32_t x, std::uint32_t y, std::uint32_t z) noexcept {
  return static_cast<int>((x & 7u) | (y & 7u) << 3 | (z & 7u) << 6);
}

struct VolumeGeometry {
  Eigen::Vector3d origin = Eigen::Vector3d::Zero();  // world position of voxel (0,0,0)'s corner
  double voxel_size = 0.01;
  std::uint32_t bricks_per_side = 1024;  // the extent: bricks_per_side * 8 voxels per axis (at most 2^17 bricks)
  std::uint32_t voxels_per_side() const noexcept { return bricks_per_side * kBrickSide; }
  // Throws InvalidArgument for a non-positive voxel size or an empty or too large extent.
  void check() const;
};

class SparseTsdfStore {
 public:
  explicit SparseTsdfStore(const VolumeGeometry& geometry);
  const VolumeGeometry& geometry() const noexcept { return geometry_; }
  TsdfVoxel* brick(const BrickCoord& c) noexcept;
  const TsdfVoxel* brick(const BrickCoord& c) const noexcept;
  // The brick's voxels, created (all unobserved) when missing. c must be in the extent.
  TsdfVoxel* allocate(const BrickCoord& c);
  // Every brick removed (the map starts again, same geometry).
  void clear();
  std::size_t brick_count() const noexcept { return coords_.size(); }
  // f(coord, voxels) for every allocated brick, in allocation order.
  template <class F>
  void for_each_brick(F&& f) const {
    for (std::size_t i = 0; i < coords_.size(); ++i) f(coords_[i], voxels_[i].get());
  }
  // Voxel payloads plus the index.
  std::size_t memory_bytes() const noexcept;
  const BrickIndex& index() const noexcept { return index_; }

 private:
  VolumeGeometry geometry_;
  BrickIndex index_;
  std::vector<std::unique_ptr<TsdfVoxel[]>> voxels_;
  std::vector<BrickCoord> coords_;
};

class DenseTsdfStore {
 public:
  // Allocates the whole extent: bricks_per_side^3 * 512 voxels.
  explicit DenseTsdfStore(const VolumeGeometry& geometry);
  const VolumeGeometry& geometry() const noexcept { return geometry_; }
  TsdfVoxel* brick(const BrickCoord& c) noexcept;
  const TsdfVoxel* brick(const BrickCoord& c) const noexcept;
  TsdfVoxel* allocate(const BrickCoord& c);
  // Every touched brick back to unobserved and untouched.
  void clear();
  std::size_t brick_count() const noexcept { return touched_count_; }
  template <class F>
  void for_each_brick(F&& f) const {
    for (std::size_t i = 0; i < touched_order_.size(); ++i) {
      const std::size_t at = touched_order_[i];
      f(coord_of(at), voxels_.data() + at * kBrickVoxels);
    }
  }
  std::size_t memory_bytes() const noexcept;

 private:
  std::size_t linear(const BrickCoord& c) const noexcept {
    const std::size_t n = geometry_.bricks_per_side;
    return c.x + n * (c.y + n * std::size_t{c.z});
  }
  BrickCoord coord_of(std::size_t at) const noexcept;
  VolumeGeometry geometry_;
  std::vector<TsdfVoxel> voxels_;
  std::vector<bool> touched_;
  std::vector<std::size_t> touched_order_;  // same order as the sparse store's allocations
  std::size_t touched_count_ = 0;
};

}  // namespace vola::slam
