// Occlusion in the physical response: exact voxel ray casts on the direct path and on
// every leg of every image-source path, on by default, off on request.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <tuple>

#include "vola/audio/room_response.hpp"
#include "vola/builder.hpp"

namespace test_audio_room_occlusion {
namespace {

using namespace vola;
using namespace vola::audio;

constexpr double kVoxel = 0.1;

RoomOptions options(bool occlusion) {
  RoomOptions o;
  o.order = 1;
  o.rays = 0;
  o.max_length = 0.1;
  o.occlusion = occlusion;
  o.threads = 1;
  o.fractional_delay = false;  // each arrival on one sample: amplitudes read exactly
  return o;
}

// A floor (z = 0, top face at 0.1 m) 6.4 m square, and optionally a wall across it at
// x = 3.2 m (1 m high) and a box standing on it.
Tree scene_tree(bool wall, bool box) {
  std::vector<Voxel> voxels;
  for (std::uint32_t y = 0; y < 64; ++y)
    for (std::uint32_t x = 0; x < 64; ++x) {
      voxels.push_back({x, y, 0});
      if (wall && x == 32)
        for (std::uint32_t z = 1; z <= 10; ++z) voxels.push_back({x, y, z});
    }
  if (box)  // 0.4 m cube on the floor around (1.8, 3.2): between the source and the floor's reflection point
    for (std::uint32_t z = 1; z <= 4; ++z)
      for (std::uint32_t y = 30; y < 34; ++y)
        for (std::uint32_t x = 16; x < 20; ++x) voxels.push_back({x, y, z});
  std::sort(voxels.begin(), voxels.end(), [](const Voxel& a, const Voxel& b) {
    return std::tie(a.z, a.y, a.x) < std::tie(b.z, b.y, b.x);
  });
  voxels.erase(std::unique(voxels.begin(), voxels.end()), voxels.end());
  Tree tree = build_from_voxels(voxels, 4);
  tree.set_frame(Frame{Quantization::grid, {0, 0, 0}, kVoxel});
  return tree;
}

TEST(AudioRoomOcclusion, AWallBetweenSourceAndListenerSilencesTheDirectSound) {
  const Tree tree = scene_tree(true, false);
  const AcousticScene scene(tree, scene_material(0.9));
  const Room room(scene);
  const Point s{1.05, 3.15, 0.55}, l{5.05, 3.25, 0.65};
  const RoomResponse r = room_response(room, s, l, options(true));
  EXPECT_TRUE(r.direct_blocked);
  EXPECT_EQ(r.direct_amplitude, 0.0);
  EXPECT_EQ(r.ir[r.direct_sample], 0.0);
  // The floor's reflection point (x = 2.85) lies on the source's side: the wall hides its listener leg.
  EXPECT_TRUE(r.early.images.empty());
  const RoomResponse open = room_response(room, s, l, options(false));
  EXPECT_FALSE(open.direct_blocked);
  const double d = std::sqrt(4.0 * 4.0 + 0.1 * 0.1 + 0.1 * 0.1);
  EXPECT_DOUBLE_EQ(open.direct_distance, d);
  EXPECT_DOUBLE_EQ(open.direct_amplitude, 1.0 / d);
  EXPECT_DOUBLE_EQ(open.ir[open.direct_sample], 1.0 / d);
  EXPECT_FALSE(open.early.images.empty());
}

TEST(AudioRoomOcclusion, ABoxOnTheFloorHidesTheFloorsReflection) {
  // Source and listener 0.25 m above the floor; the floor reflects at x = 2.55 m, y = 3.2:
  // the box (x 1.6..2.0, 0.4 m high) stands on the source's leg and on the direct path.
  const Point s{1.05, 3.21, 0.35}, l{4.05, 3.19, 0.35};
  const Tree with_box = scene_tree(false, true), without = scene_tree(false, false);
  const AcousticScene open_scene(without, scene_material(0.9)), box_scene(with_box, scene_material(0.9));
  const Room open_room(open_scene), box_room(box_scene);
  const RoomResponse free_floor = room_response(open_room, s, l, options(true));
  ASSERT_EQ(free_floor.early.images.size(), 1u);
  const RoomResponse hidden = room_response(box_room, s, l, options(true));
  for (const ImageSource& is : hidden.early.images)
    EXPECT_GT(std::abs(is.points[0][2] - 0.1), 1e-9) << "the floor's reflection passed through the box";
  EXPECT_TRUE(hidden.direct_blocked);
  // Without occlusion the floor's reflection is back, as in the open scene.
  const RoomResponse unchecked = room_response(box_room, s, l, options(false));
  bool floor = false;
  for (const ImageSource& is : unchecked.early.images) floor = floor || std::abs(is.points[0][2] - 0.1) < 1e-9;
  EXPECT_TRUE(floor);
}

}  // namespace
}  // namespace test_audio_room_occlusion
