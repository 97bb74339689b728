// The reflecting surface of a voxel scene as planar patches: what the image-source method
// and the ray tracer of room_response.hpp reflect from.
//
// Why patches and not voxels: a flat wall of n voxels is one mirror. Summing every voxel's
// reflection as if each were a small mirror adds n coherent contributions and the level
// grows each time the voxel size halves; one image per patch gives the image-source value
// whatever the voxel size.
//
// How they are made, in grid coordinates (a voxel is a unit cube):
//   elements: every exposed face of a surface voxel (surface.hpp), at the face's centre;
//   normals:  per element, the plane fitted (PCA: the covariance's smallest eigenvector)
//             through the centres of the elements facing the same way within
//             kNormalRadius voxels, turned to point out of the face. A flat wall gets its
//             exact axis normal; a voxelised slope (a staircase of faces) gets the slope's
//             normal. Too few or collinear neighbours keep the face's own normal;
//   patches:  elements joined by region growing (breadth first) over touching voxels when
//             their material is the same, their normal within kMaxNormalAngle degrees of
//             the patch's mean normal so far and their centre within kMaxPlaneDistance
//             voxels of its plane so far.
// A patch's plane is the area-weighted mean normal through the area-weighted centroid;
// its area is the sum of its faces projected on that plane (a staircase has the area of
// the slope it approximates).
#pragma once

#include <cstdint>
#include <vector>

#include "vola/audio/materials.hpp"
#include "vola/audio/surface.hpp"
#include "vola/frame.hpp"
#include "vola/tree.hpp"

namespace vola::audio {

inline constexpr int kNormalRadius = 2;
inline constexpr double kMaxNormalAngle = 20.0;
inline constexpr double kMaxPlaneDistance = 0.75;

struct SurfacePatch {
  Point normal{};            // unit, pointing into the empty side
  Point centroid{};          // on the plane (grid coordinates)
  double area = 0.0;         // projected face area (voxel faces, i.e. grid units squared)
  Point lo{}, hi{};          // bounding box of the faces' centres (grid)
  std::uint32_t faces = 0;
  std::uint16_t slot = 0;    // material slot (VoxelMaterials)
};

class SurfacePatches {
 public:
  SurfacePatches(const Tree& tree, const VoxelMaterials& materials, const std::vector<LeafBlock>& blocks);

  const std::vector<SurfacePatch>& patches() const noexcept { return patches_; }
  // The patch holding face `face` (Face bit order: 0 = -x .. 5 = +z) of voxel v, or -1
  // when that face is not exposed.
  std::int64_t patch_of(const Voxel& v, int face) const noexcept;
  // Whether any exposed face of v belongs to patch p.
  bool voxel_in_patch(const Voxel& v, std::uint32_t p) const noexcept;
  // The exposed faces ("elements"), numbered 0 .. element_count() - 1: the index of face
  // `face` of voxel v, or -1 when that face is not exposed.
  std::int64_t element_of(const Voxel& v, int face) const noexcept;
  // The same, and the element's patch into `patch` (when not -1): one lookup.
  std::int64_t element_of(const Voxel& v, int face, std::uint32_t& patch) const noexcept;
  std::size_t element_count() const noexcept { return elements_.size(); }

 private:
  struct Element {
    std::uint32_t patch = 0;
    std::uint8_t face = 0;
  };
  // Per surface voxel (x, y, z packed in 20 bits each) its exposed faces (Face bits) and
  // its first element; a voxel's elements are consecutive, in face order.
  // Per surface voxel its exposed faces (Face bits, low 8 bits) and its first element
  // (above them); a voxel's elements are consecutive, in face order. Found through its
  // 4x4x4 block in an open-addressing table (linear probing, a power-of-two size at least
  // twice the blocks) whose entry has a bit per surface voxel and where the block's voxels
  // start in voxel_faces_: both small enough to stay in cache, where a lookup per voxel in
  // a node-based map misses it several times (a lookup per reflection of the traced tail).
  static constexpr std::uint64_t kNoKey = ~std::uint64_t{0};
  struct Block {
    std::uint64_t key = kNoKey;
    std::uint64_t voxels = 0;
    std::uint64_t offset = 0;
  };
  // The packed faces of surface voxel (x, y, z), or nullptr.
  const std::uint64_t* find(std::uint64_t x, std::uint64_t y, std::uint64_t z) const noexcept;
  Block& insert(std::uint64_t key);
  std::vector<Block> blocks_;
  std::uint64_t slot_mask_ = 0;
  int slot_shift_ = 64;
  std::vector<std::uint64_t> voxel_faces_;
  std::vector<Element> elements_;
  std::vector<SurfacePatch> patches_;
};

// Signed distance (grid units) of p from the patch's plane, positive on the empty side.
inline double plane_distance(const SurfacePatch& patch, const Point& p) noexcept {
  return (p[0] - patch.centroid[0]) * patch.normal[0] + (p[1] - patch.centroid[1]) * patch.normal[1] +
         (p[2] - patch.centroid[2]) * patch.normal[2];
}

// p mirrored in the patch's plane.
inline Point mirror(const SurfacePatch& patch, const Point& p) noexcept {
  const double d = 2.0 * plane_distance(patch, p);
  return {p[0] - d * patch.normal[0], p[1] - d * patch.normal[1], p[2] - d * patch.normal[2]};
}

}  // namespace vola::audio
