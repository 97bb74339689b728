#include "vola/slam/tsdf_store.hpp"

#include <algorithm>
#include <bit>
#include <cmath>

#include "vola/error.hpp"

namespace vola::slam {

namespace {
// Index levels: the smallest L with 4^L >= bricks_per_side.
int levels_for(std::uint32_t bricks_per_side) {
  int levels = 1;
  while ((1u << (2 * levels)) < bricks_per_side) ++levels;
  return levels;
}
}  // namespace

void VolumeGeometry::check() const {
  if (!(voxel_size > 0.0) || !std::isfinite(voxel_size)) throw InvalidArgument("voxel size must be positive");
  if (!origin.allFinite()) throw InvalidArgument("volume origin must be finite");
  if (bricks_per_side == 0 || bricks_per_side > (1u << 17))
    throw InvalidArgument("volume extent must be 1 .. 2^17 bricks per side");
}

SparseTsdfStore::SparseTsdfStore(const VolumeGeometry& geometry)
    : geometry_(geometry), index_((geometry.check(), levels_for(geometry.bricks_per_side))) {}

TsdfVoxel* SparseTsdfStore::brick(const BrickCoord& c) noexcept {
  const auto found = index_.find(c.x, c.y, c.z);
  return found ? voxels_[*found].get() : nullptr;
}
const TsdfVoxel* SparseTsdfStore::brick(const BrickCoord& c) const noexcept {
  const auto found = index_.find(c.x, c.y, c.z);
  return found ? voxels_[*found].get() : nullptr;
}

TsdfVoxel* SparseTsdfStore::allocate(const BrickCoord& c) {
  if (TsdfVoxel* existing = brick(c)) return existing;
  const std::uint32_t n = geometry_.bricks_per_side;
  if (c.x >= n || c.y >= n || c.z >= n) throw InvalidArgument("brick outside the volume");
  index_.insert(c.x, c.y, c.z, static_cast<std::uint32_t>(voxels_.size()));
  voxels_.push_back(std::make_unique<TsdfVoxel[]>(kBrickVoxels));
  coords_.push_back(c);
  return voxels_.back().get();
}

void SparseTsdfStore::clear() {
  index_ = BrickIndex(levels_for(geometry_.bricks_per_side));
  voxels_.clear();
  coords_.clear();
}

std::size_t SparseTsdfStore::memory_bytes() const noexcept {
  return voxels_.size() * (kBrickVoxels * sizeof(TsdfVoxel) + sizeof(std::unique_ptr<TsdfVoxel[]>)) +
         coords_.capacity() * sizeof(BrickCoord) + index_.memory_bytes();
}

DenseTsdfStore::DenseTsdfStore(const VolumeGeometry& geometry) : geometry_(geometry) {
  geometry.check();
  const std::size_t bricks = std::size_t{geometry.bricks_per_side} * geometry.bricks_per_side * geometry.bricks_per_side;
  voxels_.resize(bricks * kBrickVoxels);
  touched_.resize(bricks);
}

TsdfVoxel* DenseTsdfStore::brick(const BrickCoord& c) noexcept {
  const std::uint32_t n = geometry_.bricks_per_side;
  if (c.x >= n || c.y >= n || c.z >= n) return nullptr;
  const std::size_t at = linear(c);
  return touched_[at] ? voxels_.data() + at * kBrickVoxels : nullptr;
}
const TsdfVoxel* DenseTsdfStore::brick(const BrickCoord& c) const noexcept {
  return const_cast<DenseTsdfStore*>(this)->brick(c);
}

TsdfVoxel* DenseTsdfStore::allocate(const BrickCoord& c) {
  const std::uint32_t n = geometry_.bricks_per_side;
  if (c.x >= n || c.y >= n || c.z >= n) throw InvalidArgument("brick outside the volume");
  const std::size_t at = linear(c);
  if (!touched_[at]) {
    touched_[at] = true;
    touched_order_.push_back(at);
    ++touched_count_;
  }
  return voxels_.data() + at * kBrickVoxels;
}

void DenseTsdfStore::clear() {
  for (const std::size_t at : touched_order_) {
    std::fill_n(voxels_.begin() + static_cast<std::ptrdiff_t>(at * kBrickVoxels), kBrickVoxels, TsdfVoxel{});
    touched_[at] = false;
  }
  touched_order_.clear();
  touched_count_ = 0;
}

BrickCoord DenseTsdfStore::coord_of(std::size_t at) const noexcept {
  const std::size_t n = geometry_.bricks_per_side;
  return {static_cast<std::uint32_t>(at % n), static_cast<std::uint32_t>((at / n) % n),
          static_cast<std::uint32_t>(at / (n * n))};
}

std::size_t DenseTsdfStore::memory_bytes() const noexcept {
  return voxels_.capacity() * sizeof(TsdfVoxel) + touched_.capacity() / 8 + touched_order_.capacity() * sizeof(std::size_t);
}

}  // namespace vola::slam
