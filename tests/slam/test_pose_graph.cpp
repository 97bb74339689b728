// Pose-graph correction on a generated loop: odometry that drifts (a small bias in
// every step's rotation and translation) plus one loop edge back to the start; the
// optimised keyframes return to the true loop.
#include <gtest/gtest.h>

#include <cmath>

#include "vola/error.hpp"
#include "vola/slam/pose_graph.hpp"

namespace {

using namespace vola::slam;
using Iso = Eigen::Isometry3d;

std::vector<Iso> circle(std::size_t n) {
  std::vector<Iso> out;
  for (std::size_t i = 0; i < n; ++i) {
    const double a = 2 * M_PI * static_cast<double>(i) / static_cast<double>(n);
    Iso p = Iso::Identity();
    p.linear() = Eigen::AngleAxisd(a, Eigen::Vector3d::UnitZ()).toRotationMatrix();
    p.translation() = Eigen::Vector3d(2 * std::cos(a), 2 * std::sin(a), 0.1 * std::sin(3 * a));
    out.push_back(p);
  }
  return out;
}

double worst_position_error(const std::vector<Iso>& a, const std::vector<Iso>& b) {
  double worst = 0.0;
  for (std::size_t i = 0; i < a.size(); ++i) worst = std::max(worst, (a[i].translation() - b[i].translation()).norm());
  return worst;
}

TEST(SlamPoseGraph, ALoopEdgeRemovesTheOdometryDrift) {
  const std::size_t n = 24;
  const std::vector<Iso> truth = circle(n);
  // Drifting odometry: each step's measured motion is off by 0.5 degrees and 1 cm.
  Iso bias = Iso::Identity();
  bias.linear() = Eigen::AngleAxisd(0.5 * M_PI / 180, Eigen::Vector3d(0.3, 0.2, 1).normalized()).toRotationMatrix();
  bias.translation() = Eigen::Vector3d(0.01, -0.005, 0.003);
  std::vector<PoseGraphEdge> edges;
  std::vector<Iso> poses{truth[0]};
  for (std::size_t i = 1; i < n; ++i) {
    const Iso step = truth[i - 1].inverse() * truth[i] * bias;
    edges.push_back({i - 1, i, step, 1.0 / (0.01 * 0.01), 1.0 / (0.01 * 0.01)});
    poses.push_back(poses.back() * step);
  }
  const double drift = worst_position_error(poses, truth);
  ASSERT_GT(drift, 0.2);  // the chain alone ends far from the start
  // The loop: the last keyframe registered against the first (exact, more certain).
  edges.push_back({n - 1, 0, truth[n - 1].inverse() * truth[0], 1.0 / (0.002 * 0.002), 1.0 / (0.002 * 0.002)});
  const PoseGraphResult r = optimise_pose_graph(poses, edges);
  EXPECT_LT(r.final_cost, r.initial_cost * 1e-2);
  EXPECT_GT(r.iterations, 0);
  const double corrected = worst_position_error(poses, truth);
  // A bias in every step bends the whole chain; one loop edge spreads the closing error
  // but cannot straighten the bend: measured 8.8 cm from 41 cm.
  EXPECT_LT(corrected, drift / 4) << "drift " << drift;
  EXPECT_LT(corrected, 0.1);
  // The loop closes: the last pose's motion to the first is the loop edge's.
  const Iso closing = poses[n - 1].inverse() * poses[0];
  const Iso expected = truth[n - 1].inverse() * truth[0];
  EXPECT_LT((closing.translation() - expected.translation()).norm(), 0.01);
  EXPECT_EQ(poses[0].matrix(), truth[0].matrix());  // node 0 is held
}

TEST(SlamPoseGraph, EdgesToMissingNodesAreRefused) {
  std::vector<Iso> poses(3, Iso::Identity());
  EXPECT_THROW(optimise_pose_graph(poses, {{0, 3, Iso::Identity(), 1, 1}}), vola::InvalidArgument);
  EXPECT_THROW(optimise_pose_graph(poses, {{1, 1, Iso::Identity(), 1, 1}}), vola::InvalidArgument);
}

}  // namespace
