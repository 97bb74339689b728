// Keyframe refinement (keyframe_refinement.hpp): keyframes of a generated room, moved
// off their true poses, are brought back by aligning their depth jointly; the result
// does not depend on the thread count; bad input is refused.
#include <gtest/gtest.h>

#include <cmath>

#include "slam_test_support.hpp"
#include "vola/error.hpp"
#include "vola/slam/fuse_sequence.hpp"
#include "vola/slam/keyframe_refinement.hpp"

namespace {

using namespace vola::slam;
using vola_slam_test::ScratchDir;
namespace fs = vola_slam_test::fs;

struct Keyframes {
  std::vector<VertexMap> views;
  std::vector<Pose> truth;
  Intrinsics k;
};

// Every fourth frame of a generated room (Kinect noise, 3 degrees per frame): keyframes
// 12 degrees apart.
Keyframes room_keyframes(const fs::path& dir) {
  vola_slam_test::make_room_sequence(dir, 21, 320, 240, 3.0, true);
  const Sequence s = read_sequence(dir.string());
  Keyframes out;
  const FusionParams params;  // the views vola fuse aligns: half size, bilateral-filtered
  out.k = keyframe_view_intrinsics(*s.intrinsics, params.refine_level);
  for (std::size_t f = 0; f < s.frames.size(); f += 4) {
    out.views.push_back(keyframe_view(read_depth(s.frames[f].depth_path, 5000.0), *s.intrinsics, params, params.refine_level));
    out.truth.push_back(s.groundtruth.at(f).pose);
  }
  return out;
}

// Each keyframe but the first moved by 2-4 cm and 1-2 degrees, differently each.
std::vector<Pose> perturbed(const std::vector<Pose>& truth) {
  std::vector<Pose> out = truth;
  for (std::size_t i = 1; i < out.size(); ++i) {
    const double a = static_cast<double>(i);
    Pose d = Pose::Identity();
    d.linear() = Eigen::AngleAxisd((1.0 + 0.25 * a) * M_PI / 180, Eigen::Vector3d(std::sin(a), 1, std::cos(a)).normalized())
                     .toRotationMatrix();
    d.translation() = Eigen::Vector3d(0.03 * std::sin(2 * a), 0.02 * std::cos(a), 0.025 * (i % 2 ? 1 : -1));
    out[i] = out[i] * d;  // in the camera's frame: the camera itself moves 2-4 cm
  }
  return out;
}

struct Error {
  double metres = 0.0, degrees = 0.0;
};
Error worst(const std::vector<Pose>& poses, const std::vector<Pose>& truth) {
  Error e;
  for (std::size_t i = 0; i < poses.size(); ++i) {
    e.metres = std::max(e.metres, (poses[i].translation() - truth[i].translation()).norm());
    e.degrees = std::max(e.degrees,
                         Eigen::AngleAxisd(poses[i].linear().transpose() * truth[i].linear()).angle() * 180 / M_PI);
  }
  return e;
}

TEST(SlamKeyframeRefinement, MovedKeyframesOfAGeneratedRoomReturnToTheirPoses) {
  ScratchDir dir("refine_room");
  const Keyframes kf = room_keyframes(dir.path());
  ASSERT_EQ(kf.views.size(), 6u);
  const std::vector<Pose> start = perturbed(kf.truth);
  const Error before = worst(start, kf.truth);
  ASSERT_GT(before.metres, 0.02);
  ASSERT_GT(before.degrees, 1.0);
  KeyframeRefinementParams p;
  p.threads = 2;
  const KeyframeRefinementResult r = refine_keyframes(kf.views, start, kf.k, p);
  EXPECT_TRUE(r.improved);
  EXPECT_LT(r.final_cost, r.initial_cost);
  EXPECT_GE(r.pairs, 10u);  // each keyframe with at least two others
  ASSERT_EQ(r.poses.size(), start.size());
  EXPECT_TRUE(r.poses[0].isApprox(start[0]));  // the first keyframe is held
  const Error after = worst(r.poses, kf.truth);
  EXPECT_LT(after.metres, 0.005) << "before " << before.metres << " m";
  EXPECT_LT(after.degrees, 0.3) << "before " << before.degrees << " degrees";
  EXPECT_GT(r.max_move_metres, 0.015);
}

TEST(SlamKeyframeRefinement, TheResultDoesNotDependOnTheThreadCount) {
  ScratchDir dir("refine_threads");
  const Keyframes kf = room_keyframes(dir.path());
  const std::vector<Pose> start = perturbed(kf.truth);
  KeyframeRefinementParams p;
  p.threads = 1;
  const KeyframeRefinementResult one = refine_keyframes(kf.views, start, kf.k, p);
  p.threads = 2;
  const KeyframeRefinementResult two = refine_keyframes(kf.views, start, kf.k, p);
  ASSERT_EQ(one.poses.size(), two.poses.size());
  for (std::size_t i = 0; i < one.poses.size(); ++i) EXPECT_TRUE(one.poses[i].matrix() == two.poses[i].matrix()) << i;
  EXPECT_EQ(one.final_cost, two.final_cost);
}

TEST(SlamKeyframeRefinement, KeyframesThatSeeNothingInCommonStayWhereTheyAre) {
  ScratchDir dir("refine_apart");
  Keyframes kf = room_keyframes(dir.path());
  // Two keyframes, the second 50 m away: no pair overlaps, nothing moves.
  std::vector<Pose> poses{kf.truth[0], kf.truth[1]};
  poses[1].translation() += Eigen::Vector3d(50, 0, 0);
  kf.views.resize(2);
  const KeyframeRefinementResult r = refine_keyframes(kf.views, poses, kf.k);
  EXPECT_EQ(r.pairs, 0u);
  EXPECT_FALSE(r.improved);
  EXPECT_TRUE(r.poses[1].isApprox(poses[1]));
}

TEST(SlamKeyframeRefinement, ViewsShrinkToTheMemoryBudgetOrTheRefinementIsSkipped) {
  ScratchDir dir("refine_budget");
  vola_slam_test::make_room_sequence(dir.path(), 12, 320, 240, 3.0, true);
  const Sequence s = read_sequence(dir.path().string());
  FuseOptions o;
  o.intrinsics = *s.intrinsics;
  o.params = vola_slam_test::small_scene_params();
  const auto fuse = [&](std::size_t budget) {
    o.params.refine_memory = budget;
    SparseTsdfStore store(centred_geometry(Eigen::Vector3d::Zero(), o.params.voxel_size, 512));
    return fuse_sequence(s, o, store);
  };
  const FuseResult roomy = fuse(std::size_t{512} << 20);
  EXPECT_EQ(roomy.refinement_level, 1);
  EXPECT_GT(roomy.refinement_pairs, 0u);
  EXPECT_TRUE(roomy.warnings.empty());
  ASSERT_GE(roomy.keyframes, 2u);
  // Room for the quarter-size views of every keyframe, not the half-size ones.
  const FuseResult tight = fuse(roomy.keyframes * keyframe_view_bytes(320, 240, 2));
  EXPECT_EQ(tight.refinement_level, 2);
  const FuseResult none = fuse(1);
  EXPECT_EQ(none.refinement_level, -1);
  EXPECT_EQ(none.refinement_pairs, 0u);
  ASSERT_EQ(none.warnings.size(), 1u);
  EXPECT_NE(none.warnings[0].find("keyframe refinement skipped"), std::string::npos);
  // Only the refinement differs: the tracked trajectory is the same.
  ASSERT_EQ(none.trajectory.size(), roomy.trajectory.size());
}

TEST(SlamKeyframeRefinement, BadInputIsRefused) {
  const Intrinsics k;
  VertexMap small{2, 2, std::vector<Eigen::Vector3f>(4), std::vector<Eigen::Vector3f>(4)};
  VertexMap other{3, 2, std::vector<Eigen::Vector3f>(6), std::vector<Eigen::Vector3f>(6)};
  EXPECT_THROW(refine_keyframes({small, small}, {Pose::Identity()}, k), vola::InvalidArgument);
  EXPECT_THROW(refine_keyframes({small, other}, {Pose::Identity(), Pose::Identity()}, k), vola::InvalidArgument);
  KeyframeRefinementParams p;
  p.sample_step = 0;
  EXPECT_THROW(refine_keyframes({small}, {Pose::Identity()}, k, p), vola::InvalidArgument);
  p = {};
  p.max_depth = p.min_depth;
  EXPECT_THROW(refine_keyframes({small}, {Pose::Identity()}, k, p), vola::InvalidArgument);
  p = {};
  p.min_overlap = 1.5;
  EXPECT_THROW(refine_keyframes({small}, {Pose::Identity()}, k, p), vola::InvalidArgument);
}

}  // namespace
