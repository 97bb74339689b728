// Loop closure in vola fuse: the trajectory correction from keyframes and loop edges
// (every frame moves with its keyframe), and a generated room loop closed end to end
// with the map integrated again at the corrected poses.
#include <gtest/gtest.h>

#include <cmath>

#include "slam_test_support.hpp"
#include "vola/error.hpp"
#include "vola/slam/fuse_sequence.hpp"
#include "vola/slam/loop_closure.hpp"
#include "vola/slam/map_export.hpp"
#include "vola/slam/trajectory_error.hpp"

namespace {

using namespace vola::slam;
using vola_slam_test::ScratchDir;

// A circle of radius 2 m, the camera turning with it: frame i of n.
Pose on_circle(std::size_t i, std::size_t n) {
  const double a = 2 * M_PI * static_cast<double>(i) / static_cast<double>(n);
  Pose p = Pose::Identity();
  p.linear() = Eigen::AngleAxisd(a, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  p.translation() = Eigen::Vector3d(2 * std::cos(a), 2 * std::sin(a), 0.1 * std::sin(3 * a));
  return p;
}

TEST(SlamLoopClosure, EveryFrameMovesWithItsKeyframeAndTheLoopCloses) {
  const std::size_t frames = 72, every = 3;  // a keyframe every third frame
  std::vector<Pose> truth, tracked;
  Pose bias = Pose::Identity();  // the tracker's error in every frame-to-frame step
  bias.linear() = Eigen::AngleAxisd(0.2 * M_PI / 180, Eigen::Vector3d(0.3, 0.2, 1).normalized()).toRotationMatrix();
  bias.translation() = Eigen::Vector3d(0.004, -0.002, 0.001);
  for (std::size_t f = 0; f < frames; ++f) {
    truth.push_back(on_circle(f, frames));
    tracked.push_back(f ? Pose(tracked.back() * truth[f - 1].inverse() * truth[f] * bias) : truth[0]);
  }
  std::vector<KeyframePose> keyframes;
  for (std::size_t f = 0; f < frames; f += every) keyframes.push_back({f, tracked[f]});
  const std::size_t last = keyframes.size() - 1;
  // The last keyframe registered against the first: their true relative pose.
  const std::vector<LoopEdge> loops{{0, last, Pose(truth[0].inverse() * truth[keyframes[last].frame]), 100}};
  const auto worst = [&](const std::vector<Pose>& poses) {
    double w = 0.0;
    for (std::size_t f = 0; f < frames; ++f) w = std::max(w, (poses[f].translation() - truth[f].translation()).norm());
    return w;
  };
  const double drift = worst(tracked);
  ASSERT_GT(drift, 0.15);
  const LoopCorrection c = correct_trajectory(tracked, keyframes, loops);
  ASSERT_EQ(c.poses.size(), frames);
  EXPECT_LT(worst(c.poses), drift / 3) << "drift " << drift;
  EXPECT_GT(c.max_keyframe_move, 0.05);
  EXPECT_LT(c.graph.final_cost, c.graph.initial_cost);
  // Frames between keyframes keep their tracked pose relative to the keyframe before them.
  for (std::size_t f = 0; f < frames; ++f) {
    const std::size_t k = f / every * every;
    const Pose before = tracked[k].inverse() * tracked[f];
    const Pose after = c.poses[k].inverse() * c.poses[f];
    EXPECT_LT((before.translation() - after.translation()).norm(), 1e-9) << "frame " << f;
    EXPECT_LT((before.linear() - after.linear()).norm(), 1e-9) << "frame " << f;
  }
  // The first keyframe is held, and with no loop nothing moves.
  EXPECT_LT((c.poses[0].translation() - tracked[0].translation()).norm(), 1e-12);
  const LoopCorrection none = correct_trajectory(tracked, keyframes, {});
  for (std::size_t f = 0; f < frames; ++f) EXPECT_TRUE(none.poses[f].isApprox(tracked[f], 0.0)) << "frame " << f;
  EXPECT_EQ(none.max_keyframe_move, 0.0);
  // Indices that do not exist are refused.
  EXPECT_THROW(correct_trajectory(tracked, {{frames, tracked[0]}}, {}), vola::InvalidArgument);
  EXPECT_THROW(correct_trajectory(tracked, keyframes, {{0, last + 1, Pose::Identity(), 50}}), vola::InvalidArgument);
  // The loop's disagreement with the tracked keyframes is the drift it reveals.
  const LoopDisagreement d = loop_disagreement(keyframes, loops);
  EXPECT_GT(d.metres, 0.1);
  EXPECT_GT(d.degrees, 1.0);
  EXPECT_EQ(loop_disagreement(keyframes, {}).metres, 0.0);
}

TEST(SlamLoopClosure, StoresStartAgainWhenCleared) {
  const VolumeGeometry g = centred_geometry(Eigen::Vector3d::Zero(), 0.02, 8);
  SparseTsdfStore sparse(g);
  DenseTsdfStore dense(g);
  const BrickCoord c{3, 4, 5};
  sparse.allocate(c)[7].weight = 2.0f;
  dense.allocate(c)[7].weight = 2.0f;
  sparse.clear();
  dense.clear();
  EXPECT_EQ(sparse.brick_count(), 0u);
  EXPECT_EQ(dense.brick_count(), 0u);
  EXPECT_EQ(sparse.brick(c), nullptr);
  EXPECT_EQ(dense.brick(c), nullptr);
  EXPECT_EQ(dense.allocate(c)[7].weight, 0.0f);  // unobserved again
  EXPECT_EQ(sparse.allocate(c)[7].weight, 0.0f);
  EXPECT_EQ(sparse.brick_count(), 1u);
  EXPECT_EQ(dense.brick_count(), 1u);
}

// The room loop past a full turn (165 frames at 3 degrees): its textured part is seen
// again, keyframes there register against the first pass's, and the map is integrated
// again at the corrected poses.
TEST(SlamLoopClosure, AGeneratedRoomLoopIsClosedAndTheMapIntegratedAgain) {
  if (!features_available()) GTEST_SKIP() << "built without OpenCV: no colour features, no loop detection";
  ScratchDir dir("room_loop");
  vola_slam_test::make_room_sequence(dir.path(), 165, 320, 240, 3.0, true);
  const Sequence s = read_sequence(dir.path().string());
  FuseOptions o;
  o.intrinsics = *s.intrinsics;
  o.params = vola_slam_test::small_scene_params();
  o.params.loop_min_correction = 0.0;  // correct whatever the loops say, to test the correction
  o.params.loop_min_correction_degrees = 0.0;
  const VolumeGeometry g = centred_geometry(Eigen::Vector3d::Zero(), o.params.voxel_size, 1024);
  SparseTsdfStore closed_store(g);
  const FuseResult closed = fuse_sequence(s, o, closed_store);
  o.params.loop_closure = false;
  SparseTsdfStore open_store(g);
  const FuseResult open = fuse_sequence(s, o, open_store);
  EXPECT_EQ(closed.lost, 0u);
  EXPECT_GE(closed.loop_edges, 1u);
  EXPECT_TRUE(closed.loop_corrected);
  EXPECT_LT(closed.loop_disagreement.metres, 0.1);  // the loops agree with tracking to a few cm
  EXPECT_GT(closed.reintegration_seconds, 0.0);
  EXPECT_EQ(open.loop_edges, 0u);
  const double ate_closed = absolute_trajectory_error(s.groundtruth, closed.trajectory).rmse;
  const double ate_open = absolute_trajectory_error(s.groundtruth, open.trajectory).rmse;
  EXPECT_LT(ate_closed, 0.02);
  EXPECT_LT(ate_closed, ate_open + 0.002) << "open loop " << ate_open;
  // The map holds exactly what integrating every frame at its corrected pose gives.
  SparseTsdfStore again(g);
  Fusion<SparseTsdfStore> fusion(again, o.intrinsics, closed.width, closed.height, o.params);
  for (std::size_t f = 0; f < s.frames.size(); ++f) {
    const DepthImage depth = read_depth(s.frames[f].depth_path, o.depth_factor);
    const RgbImage rgb = read_rgb_png(s.frames[f].rgb_path);
    fusion.integrate_at_pose(depth, &rgb, closed.trajectory[f].pose);
  }
  const auto a = surface_voxels(closed_store), b = surface_voxels(again);
  ASSERT_EQ(a.size(), b.size());
  for (std::size_t i = 0; i < a.size(); ++i) ASSERT_TRUE(a[i].x == b[i].x && a[i].y == b[i].y && a[i].z == b[i].z) << i;
}

}  // namespace
