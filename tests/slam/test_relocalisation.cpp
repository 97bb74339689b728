// Colour features and relocalisation: ORB registration of a wide-baseline pair of
// generated frames against their exact relative pose, and a tracked sequence whose
// frame is blanked (lost) before the camera jumps back to its first view: the jump is
// relocalised against the keyframes, not dropped. Without features the same jump is lost.
#include <gtest/gtest.h>

#include <random>

#include "slam_test_support.hpp"
#include "vola/slam/features.hpp"
#include "vola/slam/fuse_sequence.hpp"
#include "vola/slam/fusion.hpp"
#include "vola/slam/sequence_generator.hpp"

namespace {

using namespace vola::slam;

double angle_degrees(const Pose& a, const Pose& b) {
  return Eigen::AngleAxisd((a.inverse() * b).linear()).angle() * 180.0 / M_PI;
}

struct Rendered {
  std::vector<Pose> poses;
  std::vector<RenderedFrame> frames;
  GeneratorOptions options;
};

// Frames of the room loop at 320 x 240 with the Kinect noise model.
const Rendered& rendered() {
  static const Rendered r = [] {
    static const vola::Tree scene = room_scene(0.01);
    const vola::raycast::RayCaster caster(scene);
    Rendered out;
    out.options.width = 320;
    out.options.height = 240;
    out.options.intrinsics = {262.5, 262.5, 159.5, 119.5};
    out.options.threads = 2;
    // 16 frames of the loop at 2 degrees per frame where the cabinet, the boxes and the
    // floor's tiles are in view (the bare walls elsewhere give ORB few corners).
    const std::vector<Pose> loop = room_trajectory(180, 2.0);
    out.poses.assign(loop.begin() + 12, loop.begin() + 28);
    std::mt19937_64 rng(7);
    for (const Pose& p : out.poses) out.frames.push_back(render_frame(caster, p, out.options, rng));
    return out;
  }();
  return r;
}

TEST(SlamRelocalisation, FeaturesRegisterAWideBaselinePair) {
  if (!features_available()) {
    if (std::getenv("CI")) FAIL() << "vola was built without OpenCV (libopencv-dev): no colour features";
    GTEST_SKIP() << "built without OpenCV";
  }
  const Rendered& r = rendered();
  const FeatureParams fp;
  // 4 degrees of turn apart and the ellipse's translation (frame-to-model ICP lost 8 of
  // 12 frames at 3 degrees and 6 cm per frame, issue 25). Wider pairs
  // of this scene register less reliably: the floor's tiles repeat (12 degrees: no
  // registration; 6 degrees: 30 inliers but 7.7 cm off), which this test documents.
  const std::size_t a = 0, b = 2;
  ASSERT_GT(angle_degrees(r.poses[a], r.poses[b]), 3.5);
  const FeatureFrame fa = extract_features(r.frames[a].rgb, r.frames[a].depth, r.options.intrinsics, fp);
  const FeatureFrame fb = extract_features(r.frames[b].rgb, r.frames[b].depth, r.options.intrinsics, fp);
  ASSERT_GT(fa.size(), 50u);
  ASSERT_GT(fb.size(), 50u);
  const auto reg = register_features(fa, fb, fp);
  ASSERT_TRUE(reg);
  EXPECT_GE(reg->inliers, fp.min_inliers);
  const Pose truth = r.poses[a].inverse() * r.poses[b];  // b's camera in a's
  EXPECT_LT((reg->transform.translation() - truth.translation()).norm(), 0.03);
  EXPECT_LT(angle_degrees(reg->transform, truth), 1.5);
  // Unrelated descriptors do not register: the same points with descriptors shuffled.
  FeatureFrame shuffled = fb;
  std::mt19937_64 rng(3);
  std::shuffle(shuffled.descriptors.begin(), shuffled.descriptors.end(), rng);
  const auto bad = register_features(fa, shuffled, fp);
  EXPECT_FALSE(bad && bad->inliers > reg->inliers / 2);
}

// Frames 0..15 tracked, a blank frame (no depth: lost), then frames 1 and 2: 28 degrees
// back from the last tracked view, where frame-to-model ICP cannot reach.
std::vector<FrameResult> run_with_loss(const FusionParams& p) {
  const Rendered& r = rendered();
  SparseTsdfStore store(centred_geometry(r.poses[0].translation(), p.voxel_size, 1024));
  Fusion<SparseTsdfStore> fusion(store, r.options.intrinsics, r.options.width, r.options.height, p);
  std::vector<FrameResult> out;
  for (std::size_t i = 0; i < r.poses.size(); ++i)
    out.push_back(fusion.process(r.frames[i].depth, &r.frames[i].rgb, r.poses[0]));
  DepthImage blank = r.frames[0].depth;
  std::fill(blank.metres.begin(), blank.metres.end(), 0.0f);
  out.push_back(fusion.process(blank, &r.frames[0].rgb, r.poses[0]));
  for (std::size_t i : {1, 2}) out.push_back(fusion.process(r.frames[i].depth, &r.frames[i].rgb, r.poses[0]));
  return out;
}

TEST(SlamRelocalisation, ALostFrameIsFollowedByRelocalisationAgainstKeyframes) {
  if (!features_available()) {
    if (std::getenv("CI")) FAIL() << "vola was built without OpenCV (libopencv-dev): no colour features";
    GTEST_SKIP() << "built without OpenCV";
  }
  const Rendered& r = rendered();
  const std::vector<FrameResult> results = run_with_loss(vola_slam_test::small_scene_params());
  ASSERT_EQ(results.size(), r.poses.size() + 3);
  for (std::size_t i = 0; i < r.poses.size(); ++i) {
    EXPECT_TRUE(results[i].tracked) << "frame " << i;
    EXPECT_LT((results[i].pose.translation() - r.poses[i].translation()).norm(), 0.03) << "frame " << i;
  }
  EXPECT_FALSE(results[r.poses.size()].tracked);  // the blank frame
  for (std::size_t k = 1; k <= 2; ++k) {
    const FrameResult& f = results[r.poses.size() + k];
    EXPECT_TRUE(f.tracked) << "frame " << k << " after the loss";
    EXPECT_LT((f.pose.translation() - r.poses[k].translation()).norm(), 0.03) << "frame " << k << " after the loss";
    EXPECT_LT(angle_degrees(f.pose, r.poses[k]), 1.5) << "frame " << k << " after the loss";
  }
  EXPECT_TRUE(results[r.poses.size() + 1].relocalised);
  // ICP alone cannot make the jump back.
  FusionParams icp_only = vola_slam_test::small_scene_params();
  icp_only.features = false;
  const std::vector<FrameResult> without = run_with_loss(icp_only);
  const FrameResult& jump = without[r.poses.size() + 1];
  EXPECT_TRUE(!jump.tracked || (jump.pose.translation() - r.poses[1].translation()).norm() > 0.05);
}

}  // namespace
