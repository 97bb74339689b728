// Renders a tree through a pinhole camera (grid coordinates): a depth image and a
// shaded image. Shading: the hit face's normal against a fixed light, times the voxel's
// colour from its red/green/blue attributes when the tree has them, else light grey.
#pragma once

#include <array>
#include <cstdint>
#include <vector>

#include "vola/raycast/camera.hpp"
#include "vola/raycast/ray_caster.hpp"

namespace vola::raycast {

struct Rendering {
  std::uint32_t width = 0, height = 0;
  std::vector<double> depth;       // entry distance in voxels per pixel, +inf for a miss
  std::vector<std::uint8_t> rgb;   // 3 bytes per pixel, row 0 at the top; misses black
  std::uint64_t hits = 0;
};

// Per-voxel colour from a tree's red/green/blue attribute columns (8- or 16-bit values:
// a column whose largest value passes 255 is read as 16-bit), light grey (200) without
// them. Keeps a reference to the tree.
class VoxelColours {
 public:
  explicit VoxelColours(const Tree& tree);
  std::array<double, 3> at(const Voxel& v) const;  // 0..255 per channel

 private:
  const Tree& tree_;
  std::array<const AttributeColumn*, 3> channels_{};
  double scale_ = 1.0;
  bool present_ = false;
};

// Brightness of a face with axis normal `normal` under a fixed light from above and to
// the side (0.3 ambient + 0.7 Lambert); 1 for the zero normal (the eye inside a voxel).
double lambert(const std::array<int, 3>& normal);

// A hit pixel: the colour (0..255 per channel) times lambert(normal), into rgb[0..2].
void shade_pixel(const std::array<double, 3>& colour, const std::array<int, 3>& normal, std::uint8_t* rgb);

Rendering render(const RayCaster& caster, const PinholeCamera& camera, unsigned threads = 0);

// The default view of a tree (grid coordinates; up, field of view and image size from
// `settings`): its occupied cells of level min(depth - 1, 2) framed whole from above one
// corner of their box (framing()).
PinholeCamera overview_camera(const Tree& tree, const PinholeCamera& settings = {});

}  // namespace vola::raycast
