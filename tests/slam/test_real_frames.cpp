// The real ICL-NUIM frames (slambook2 ch12, 5 frames with poses) fused at their poses:
// the map holds the room, and a rendered view from the first pose sees most of it. Then
// both real sequences (ICL-NUIM, and slambook2 ch5's Kinect frames) tracked as vola fuse
// tracks them (its defaults, the intrinsics and depth units of docs/BENCHMARKS.md): up
// to 40 degrees and 0.8 m between frames, no frame may be lost, and the ATE after
// alignment must stay within the figures measured.
#include <gtest/gtest.h>

#include "slam_test_support.hpp"
#include "vola/slam/fuse_sequence.hpp"
#include "vola/slam/map_export.hpp"
#include "vola/slam/trajectory_error.hpp"

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
  SparseTsdfStore store(centred_geometry(Eigen::Vector3d::Zero(), o.params.voxel_size, 1024));
  const FuseResult r = fuse_sequence(s, o, store);
  ASSERT_EQ(r.trajectory.size(), 5u);
  EXPECT_TRUE(r.coloured);
  const auto surface = surface_voxels(store);
  EXPECT_GT(surface.size(), 20000u);
  // Seen from the first pose, the fused map covers most of the first frame's view.
  const RgbImage view = render_view(store, o.intrinsics, r.width, r.height, to_local(r.trajectory[0].pose, r.origin), o.params, true);
  std::size_t lit = 0;
  for (std::size_t i = 0; i < view.rgb.size(); i += 3) lit += view.rgb[i] | view.rgb[i + 1] | view.rgb[i + 2] ? 1 : 0;
  EXPECT_GT(lit, std::size_t{640} * 480 * 8 / 10);
  const MapMemory memory = map_memory(store);
  EXPECT_LT(memory.sparse_bytes * 4, memory.dense_bytes);
}

// vola fuse SEQUENCE --intrinsics ... --depth-factor F --max-depth D, as in BENCHMARKS.md.
FuseResult track_real(const Sequence& s, const Intrinsics& k, double depth_factor, double max_depth,
                      bool refine_keyframes = true) {
  FuseOptions o;
  o.params.refine_keyframes = refine_keyframes;
  o.intrinsics = k;
  o.depth_factor = depth_factor;
  o.params.max_depth = max_depth;
  o.params.threads = 2;
  SparseTsdfStore store(centred_geometry(Eigen::Vector3d::Zero(), o.params.voxel_size, 4096));
  return fuse_sequence(s, o, store);
}

TEST(SlamRealFrames, IclNuimTracksEveryFrameWithinTwoCentimetres) {
  VOLA_REQUIRE_RGBD(rgbd);
  if (!features_available()) FAIL() << "vola was built without OpenCV (libopencv-dev): wide baselines cannot be tracked";
  const Sequence s = read_sequence((rgbd / "iclnuim_slambook2_ch12").string());
  const FuseResult r = track_real(s, {481.2, -480.0, 319.5, 239.5}, 5000.0, 8.0);
  ASSERT_EQ(r.trajectory.size(), 5u);
  // The target: no frame lost, ATE under 2 cm. Frame 2, turned 49 degrees from
  // frame 1, shares no geometrically consistent set of ORB matches with any other frame;
  // SIFT relocalises it against frame 1 (35 inliers), and ICP refines it. Frame 3 is
  // placed against frame 1 (0.94 m, 42 degrees away), frame 4 (a bare corner, 9 ORB
  // inliers) against the keyframes with ICP confirming it, frame 5 from frame 4.
  // Measured: 0 lost, ATE 0.33 cm (5.51 cm with frame 2 lost, before SIFT).
  EXPECT_EQ(r.lost, 0u);
  EXPECT_GT(r.trajectory[2].pose.translation().norm(), 0.5);  // frame 3 was placed, 0.94 m from frame 1
  const AbsoluteError ate = absolute_trajectory_error(s.groundtruth, r.trajectory);
  EXPECT_EQ(ate.pairs, 5u);
  EXPECT_LT(ate.rmse, 0.02);
}

TEST(SlamRealFrames, KinectTracksEveryFrameAcrossWideBaselines) {
  VOLA_REQUIRE_RGBD(rgbd);
  if (!features_available()) FAIL() << "vola was built without OpenCV (libopencv-dev): wide baselines cannot be tracked";
  const Sequence s = read_sequence((rgbd / "kinect_slambook2_ch5").string());
  const FuseResult r = track_real(s, {518.0, 519.0, 325.5, 253.5}, 1000.0, 7.0);
  ASSERT_EQ(r.trajectory.size(), 5u);
  EXPECT_EQ(r.lost, 0u);  // frame 2 is lost at first, then placed against frame 3
  EXPECT_EQ(r.recovered, std::vector<std::size_t>{2});
  const AbsoluteError ate = absolute_trajectory_error(s.groundtruth, r.trajectory);
  EXPECT_EQ(ate.pairs, 5u);
  // The target: 3 cm. Tracking alone places the frames 4.61 cm off (frames
  // 0.4-2 m apart, each placed against the ones before it); keyframe refinement, which
  // aligns every frame's depth with all the others' at once, moves them by up to 13 cm
  // and brings it to 2.13 cm (measured).
  EXPECT_TRUE(r.refined);
  EXPECT_LT(ate.rmse, 0.03);
}

TEST(SlamRealFrames, KinectWithoutKeyframeRefinementMissesThreeCentimetres) {
  VOLA_REQUIRE_RGBD(rgbd);
  if (!features_available()) FAIL() << "vola was built without OpenCV (libopencv-dev): wide baselines cannot be tracked";
  const Sequence s = read_sequence((rgbd / "kinect_slambook2_ch5").string());
  const FuseResult r = track_real(s, {518.0, 519.0, 325.5, 253.5}, 1000.0, 7.0, false);
  EXPECT_FALSE(r.refined);
  EXPECT_EQ(r.refinement_pairs, 0u);
  // Measured 4.61 cm: what the refinement above is for.
  EXPECT_GT(absolute_trajectory_error(s.groundtruth, r.trajectory).rmse, 0.03);
}

}  // namespace
