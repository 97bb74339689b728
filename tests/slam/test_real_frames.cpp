// The real ICL-NUIM frames (slambook2 ch12, 5 frames with poses) fused at their poses:
// the map holds the room, and a rendered view from the first pose sees most of it.
#include <gtest/gtest.h>

#include "slam_test_support.hpp"
#include "vola/slam/fuse_sequence.hpp"
#include "vola/slam/map_export.hpp"

namespace {

using namespace vola::slam;

TEST(SlamRealFrames, IclNuimFusesIntoARoomAtItsPoses) {
  VOLA_REQUIRE_RGBD(rgbd);
  const Sequence s = read_sequence((rgbd / "iclnuim_slambook2_ch12").string());
  FuseOptions o;
  o.intrinsics = {481.2, -480.0, 319.5, 239.5};  // the data's README
  o.params.voxel_size = 0.02;
  o.params.truncation = 0.08;
  o.params.max_depth = 6.0;
  o.params.threads = 2;
  o.groundtruth_poses = true;
  SparseTsdfStore store(centred_geometry(s.groundtruth[0].pose.translation(), o.params.voxel_size, 1024));
  const FuseResult r = fuse_sequence(s, o, store);
  ASSERT_EQ(r.trajectory.size(), 5u);
  EXPECT_TRUE(r.coloured);
  const auto surface = surface_voxels(store);
  EXPECT_GT(surface.size(), 20000u);
  // Seen from the first pose, the fused map covers most of the first frame's view.
  const RgbImage view = render_view(store, o.intrinsics, r.width, r.height, r.trajectory[0].pose, o.params, true);
  std::size_t lit = 0;
  for (std::size_t i = 0; i < view.rgb.size(); i += 3) lit += view.rgb[i] | view.rgb[i + 1] | view.rgb[i + 2] ? 1 : 0;
  EXPECT_GT(lit, std::size_t{640} * 480 * 8 / 10);
  const MapMemory memory = map_memory(store);
  EXPECT_LT(memory.sparse_bytes * 4, memory.dense_bytes);
}

}  // namespace
