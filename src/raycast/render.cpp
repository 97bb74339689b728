#include "vola/raycast/render.hpp"

#include <algorithm>
#include <atomic>
#include <cmath>

#include "vola/parallel.hpp"

namespace vola::raycast {
VoxelColours::VoxelColours(const Tree& tree) : tree_(tree) {
  const Attributes& a = tree.attributes();
  channels_ = {a.find("red"), a.find("green"), a.find("blue")};
  if (!channels_[0] || !channels_[1] || !channels_[2]) return;
  double top = 0.0;
  for (const AttributeColumn* c : channels_)
    for (std::size_t i = 0; i < c->size(); ++i) top = std::max(top, c->get(i));
  scale_ = top > 255.0 ? 1.0 / 257.0 : 1.0;  // LAS stores colours as 16 bits, most often
  present_ = true;
}

std::array<double, 3> VoxelColours::at(const Voxel& v) const {
  if (!present_) return {200, 200, 200};
  const auto rank = tree_.rank(v);
  std::array<double, 3> c{};
  for (int i = 0; i < 3; ++i) c[i] = rank && *rank < channels_[i]->size() ? channels_[i]->get(*rank) * scale_ : 0;
  return c;
}

void shade_pixel(const std::array<double, 3>& colour, const std::array<int, 3>& normal, std::uint8_t* rgb) {
  const double shade = lambert(normal);
  for (int i = 0; i < 3; ++i) rgb[i] = static_cast<std::uint8_t>(std::clamp(colour[i] * shade, 0.0, 255.0));
}

double lambert(const std::array<int, 3>& normal) {
  constexpr std::array<double, 3> kLight{0.42426406871192851, 0.56568542494923801, 0.70710678118654757};
  if (normal == std::array<int, 3>{0, 0, 0}) return 1.0;  // the eye is inside the voxel
  double d = 0.0;
  for (int a = 0; a < 3; ++a) d += normal[a] * kLight[a];
  return 0.3 + 0.7 * std::abs(d);
}

Rendering render(const RayCaster& caster, const PinholeCamera& camera, unsigned threads) {
  camera.check();
  Rendering out;
  out.width = camera.width;
  out.height = camera.height;
  const std::size_t pixels = std::size_t{camera.width} * camera.height;
  out.depth.assign(pixels, std::numeric_limits<double>::infinity());
  out.rgb.assign(pixels * 3, 0);
  const VoxelColours colours(caster.tree());
  std::atomic<std::uint64_t> hits{0};
  ParallelOptions parallel;
  parallel.threads = threads;
  parallel.grain = kRaysPerChunk;
  parallel.name = "raycast.render";
  const auto render_pixels = [&](std::size_t begin, std::size_t end) {
    std::uint64_t local = 0;
    for (std::size_t p = begin; p < end; ++p) {
      const auto hit = caster.cast(camera.ray(static_cast<std::uint32_t>(p % camera.width),
                                              static_cast<std::uint32_t>(p / camera.width)));
      if (!hit) continue;
      ++local;
      out.depth[p] = hit->t;
      shade_pixel(colours.at(hit->voxel), hit->normal, &out.rgb[3 * p]);
    }
    hits += local;
  };
  parallel_for(pixels, render_pixels, parallel);
  out.hits = hits;
  return out;
}

PinholeCamera overview_camera(const Tree& tree, const PinholeCamera& settings) {
  // The corners of the occupied cells of level min(depth - 1, 2): at most 16^3 cells.
  const int level = std::min(tree.depth() - 1, 2);
  const double cell = std::ldexp(1.0, 2 * (tree.depth() - 1 - level));
  std::vector<Point> corners;
  tree.for_each_node(level, [&](const Voxel& c) {
    for (int k = 0; k < 8; ++k)
      corners.push_back({(c.x + (k & 1)) * cell, (c.y + (k >> 1 & 1)) * cell, (c.z + (k >> 2 & 1)) * cell});
  });
  if (corners.empty()) corners.push_back({0, 0, 0});  // an empty tree: any view shows nothing
  return framing(corners, settings);
}

}  // namespace vola::raycast
