// End to end on generated room sequences: the tracked trajectory against the exact
// poses (ATE, RPE), the map's memory against a dense grid, and the same pipeline on a
// dense grid giving the identical trajectory and surface.
#include <gtest/gtest.h>

#include "slam_test_support.hpp"
#include "vola/error.hpp"
#include "vola/slam/fuse_sequence.hpp"
#include "vola/slam/map_export.hpp"
#include "vola/slam/sequence_generator.hpp"
#include "vola/slam/trajectory_error.hpp"

namespace {

using namespace vola::slam;
using vola_slam_test::ScratchDir;

// One generated sequence shared by the tests of this file (generation is the slow part).
class SlamFusionSequence : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    dir_ = new ScratchDir("room");
    vola_slam_test::make_room_sequence(dir_->path(), kFrames, 160, 120, 1.2, true);
  }
  static void TearDownTestSuite() {
    delete dir_;
    dir_ = nullptr;
  }
  static FuseOptions options(const Sequence& s) {
    FuseOptions o;
    o.intrinsics = *s.intrinsics;
    o.params.voxel_size = 0.02;
    o.params.truncation = 0.08;
    o.params.threads = 2;
    return o;
  }
  static constexpr std::size_t kFrames = 40;
  static ScratchDir* dir_;
};
ScratchDir* SlamFusionSequence::dir_ = nullptr;

TEST_F(SlamFusionSequence, TracksTheRoomWithinOneCentimetreInAFractionOfTheDenseMemory) {
  const Sequence s = read_sequence(dir_->path().string());
  ASSERT_EQ(s.frames.size(), kFrames);
  ASSERT_EQ(s.groundtruth.size(), kFrames);
  ASSERT_TRUE(s.intrinsics);
  const FuseOptions o = options(s);
  SparseTsdfStore store(centred_geometry(Eigen::Vector3d::Zero(), o.params.voxel_size, 1024));
  const FuseResult r = fuse_sequence(s, o, store);
  EXPECT_EQ(r.lost, 0u);
  EXPECT_TRUE(r.coloured);
  ASSERT_EQ(r.trajectory.size(), kFrames);
  const AbsoluteError ate = absolute_trajectory_error(s.groundtruth, r.trajectory);
  EXPECT_EQ(ate.pairs, kFrames);
  EXPECT_LT(ate.rmse, 0.01);  // measured 3.4 mm (the same sequence through vola fuse)
  const RelativeError rpe = relative_pose_error(s.groundtruth, r.trajectory);
  EXPECT_LT(rpe.translation_rmse, 0.005);  // measured 1.2 mm
  EXPECT_LT(rpe.rotation_rmse_degrees, 0.5);
  // The camera has turned 48 degrees: the sparse map holds a fraction of the box it spans.
  const MapMemory memory = map_memory(store);
  EXPECT_GT(memory.bricks, 100u);
  EXPECT_LT(memory.sparse_bytes * 4, memory.dense_bytes);
  // The surface, as a VOLA tree, sits on the room's walls: every surface voxel mapped
  // into the ground-truth frame lies inside the room's box (with a margin for noise).
  const auto surface = surface_voxels(store);
  ASSERT_GT(surface.size(), 5000u);
  const Pose to_world = s.groundtruth[0].pose;  // the estimate starts at identity = the first true pose
  std::size_t outside = 0;
  for (const auto& v : surface) {
    const Eigen::Vector3d p =
        to_world * (store.geometry().origin + o.params.voxel_size * Eigen::Vector3d(v.x + 0.5, v.y + 0.5, v.z + 0.5));
    outside += p.x() < -0.1 || p.x() > 4.1 || p.y() < -0.1 || p.y() > 5.1 || p.z() < -0.1 || p.z() > 2.7;
  }
  EXPECT_LT(outside, surface.size() / 100);
  const vola::Tree tree = surface_tree(surface, store.geometry(), true);
  EXPECT_EQ(tree.voxel_count(), surface.size());
}

TEST_F(SlamFusionSequence, DenseGridGivesTheIdenticalTrajectoryAndSurface) {
  const Sequence s = read_sequence(dir_->path().string());
  FuseOptions o = options(s);
  o.max_frames = 15;
  o.params.voxel_size = 0.04;
  o.params.truncation = 0.12;
  // 20 bricks of 32 cm: a 6.4 m cube around the first camera, the dense grid 94 MiB.
  const VolumeGeometry geometry = centred_geometry(Eigen::Vector3d::Zero(), o.params.voxel_size, 20);
  SparseTsdfStore sparse(geometry);
  DenseTsdfStore dense(geometry);
  const FuseResult a = fuse_sequence(s, o, sparse);
  const FuseResult b = fuse_sequence(s, o, dense);
  ASSERT_EQ(a.trajectory.size(), b.trajectory.size());
  for (std::size_t i = 0; i < a.trajectory.size(); ++i)
    EXPECT_EQ(a.trajectory[i].pose.matrix(), b.trajectory[i].pose.matrix()) << "frame " << i;
  EXPECT_EQ(sparse.brick_count(), dense.brick_count());
  const auto sa = surface_voxels(sparse), sb = surface_voxels(dense);
  ASSERT_EQ(sa.size(), sb.size());
  for (std::size_t i = 0; i < sa.size(); ++i)
    ASSERT_TRUE(sa[i].x == sb[i].x && sa[i].y == sb[i].y && sa[i].z == sb[i].z && sa[i].r == sb[i].r);
  EXPECT_LT(sparse.memory_bytes() * 4, dense.memory_bytes());
  // And the tracking is real: the poses move, and follow the truth.
  EXPECT_GT(a.trajectory.back().pose.translation().norm(), 0.05);
  EXPECT_LT(absolute_trajectory_error(s.groundtruth, a.trajectory).rmse, 0.03);
}

TEST_F(SlamFusionSequence, GroundTruthPosesMapWithoutTracking) {
  const Sequence s = read_sequence(dir_->path().string());
  FuseOptions o = options(s);
  o.groundtruth_poses = true;
  o.max_frames = 5;
  SparseTsdfStore store(centred_geometry(Eigen::Vector3d::Zero(), o.params.voxel_size, 1024));
  const FuseResult r = fuse_sequence(s, o, store);
  ASSERT_EQ(r.trajectory.size(), 5u);
  EXPECT_EQ(r.origin, s.groundtruth[0].pose.translation());
  for (std::size_t i = 0; i < 5; ++i) EXPECT_TRUE(r.trajectory[i].pose.isApprox(s.groundtruth[i].pose, 1e-12));
  // World coordinates now (the store's frame placed at r.origin): the wall the first
  // frames face (x = 4 m) is in the map.
  std::size_t wall = 0;
  for (const auto& v : surface_voxels(store)) {
    const double x = r.origin.x() + store.geometry().origin.x() + (v.x + 0.5) * o.params.voxel_size;
    wall += std::abs(x - 4.0) < 0.03;
  }
  EXPECT_GT(wall, 500u);
}

// The same sequence placed at UTM-like coordinates (millions of metres): tracking works
// relative to the first frame (fuse_origin), so it is as good as at the origin. Fusion
// computes in single precision, which keeps about half a metre there: before the local
// frame, the same 40 frames of `vola fuse --start-at-groundtruth` were 170 times worse.
TEST_F(SlamFusionSequence, SurveyCoordinatesTrackAsWellAsLocalOnes) {
  Sequence s = read_sequence(dir_->path().string());
  FuseOptions o = options(s);
  o.start_at_groundtruth = true;
  o.max_frames = 20;
  SparseTsdfStore near(centred_geometry(Eigen::Vector3d::Zero(), o.params.voxel_size, 1024));
  const FuseResult local = fuse_sequence(s, o, near);
  const Eigen::Vector3d far(500000.0, 4600000.0, 100.0);
  for (auto& g : s.groundtruth) g.pose = to_world(g.pose, far);
  SparseTsdfStore store(centred_geometry(Eigen::Vector3d::Zero(), o.params.voxel_size, 1024));
  const FuseResult placed = fuse_sequence(s, o, store);
  EXPECT_EQ(placed.origin, s.groundtruth[0].pose.translation());
  ASSERT_EQ(placed.trajectory.size(), local.trajectory.size());
  for (std::size_t i = 0; i < placed.trajectory.size(); ++i)
    EXPECT_LT((placed.trajectory[i].pose.translation() - far - local.trajectory[i].pose.translation()).norm(), 1e-3);
  EXPECT_LT(absolute_trajectory_error(s.groundtruth, placed.trajectory).rmse, 0.01);
}

// Frames 70-95 of the 300-frame room loop: from frame 81 on the camera sees only the
// wall at y = 5 m and the sofa in front of it, so no depth normal lies along the wall
// and point-to-plane ICP can hardly observe the slide along it (on the 640 x 480
// sequence the 6x6 system's smallest eigenvalue falls to ~2e-5 of its largest, and the
// tracker without the motion prior slid up to 29 mm there). With the prior deciding that
// direction, these frames track within millimetres. (At this test's 320 x 240 the
// tracker without the prior also stays within 2 mm here, so the test guards the prior
// against harm on a near-degenerate view; room300 in docs/BENCHMARKS.md shows the gain.)
TEST(SlamMotionPrior, WallAndSofaFramesTrackWithinMillimetres) {
  static const vola::Tree scene = room_scene(0.01);
  const std::vector<Pose> loop = room_trajectory(300);
  const std::vector<Pose> poses(loop.begin() + 70, loop.begin() + 96);
  ScratchDir dir("wall");
  GeneratorOptions g;
  g.width = 320;
  g.height = 240;
  g.intrinsics = {262.5, 262.5, 159.5, 119.5};
  g.threads = 2;
  generate_sequence(scene, poses, g, dir.path().string());
  const Sequence s = read_sequence(dir.path().string());
  FuseOptions o;
  o.intrinsics = *s.intrinsics;
  o.start_at_groundtruth = true;
  o.params.voxel_size = 0.01;
  o.params.threads = 2;
  ASSERT_GT(o.params.motion_prior, 0.0);  // on by default
  SparseTsdfStore store(centred_geometry(Eigen::Vector3d::Zero(), o.params.voxel_size, 1024));
  const FuseResult r = fuse_sequence(s, o, store);
  EXPECT_EQ(r.lost, 0u);
  EXPECT_LT(absolute_trajectory_error(s.groundtruth, r.trajectory).rmse, 0.006);
  const RelativeError rpe = relative_pose_error(s.groundtruth, r.trajectory);
  EXPECT_LT(rpe.translation_rmse, 0.003);
}

TEST(SlamMotionPrior, OutOfRangeWeightsAreRefused) {
  FusionParams p;
  p.motion_prior = -0.1;
  EXPECT_THROW(p.check(), vola::InvalidArgument);
  p.motion_prior = 1.0;
  EXPECT_THROW(p.check(), vola::InvalidArgument);
  p.motion_prior = 0.0;
  EXPECT_NO_THROW(p.check());
  for (const double confidence : {0.0, -0.5, 1.5}) {
    FusionParams q;
    q.feature.ransac_confidence = confidence;
    EXPECT_THROW(q.check(), vola::InvalidArgument) << confidence;
  }
}

}  // namespace
