// ATE and RPE against hand-checked cases and against Eigen's Umeyama as the reference
// alignment.
#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <random>

#include "vola/error.hpp"
#include "vola/slam/trajectory_error.hpp"

namespace {

using namespace vola::slam;

StampedPose at(double t, const Eigen::Vector3d& p) {
  StampedPose s;
  s.timestamp = t;
  s.pose.translation() = p;
  return s;
}

Pose rigid(double angle, const Eigen::Vector3d& axis, const Eigen::Vector3d& t) {
  Pose p = Pose::Identity();
  p.linear() = Eigen::AngleAxisd(angle, axis.normalized()).toRotationMatrix();
  p.translation() = t;
  return p;
}

TEST(SlamTrajectoryError, HandCheckedAte) {
  // Ground truth on the x and y axes; the estimate is lifted by +d on the x-axis points
  // and -d on the y-axis ones. By symmetry no rotation or translation helps (any tilt
  // raises one point of each pair and lowers the other), so every residual is d and
  // the RMSE is d. Moving the whole estimate rigidly must not change that.
  const double d = 0.03;
  const std::vector<Eigen::Vector3d> truth = {{1, 0, 0}, {-1, 0, 0}, {0, 1, 0}, {0, -1, 0}};
  const Pose away = rigid(0.7, {1, 2, 3}, {5, -2, 1});
  std::vector<StampedPose> g, e;
  for (std::size_t i = 0; i < truth.size(); ++i) {
    const double lift = i < 2 ? d : -d;
    g.push_back(at(static_cast<double>(i), truth[i]));
    e.push_back(at(static_cast<double>(i) + 0.001, away * (truth[i] + Eigen::Vector3d(0, 0, lift))));
  }
  const AbsoluteError ate = absolute_trajectory_error(g, e);
  EXPECT_EQ(ate.pairs, 4u);
  EXPECT_NEAR(ate.rmse, d, 1e-12);
  EXPECT_NEAR(ate.mean, d, 1e-12);
  EXPECT_NEAR(ate.max, d, 1e-12);
  EXPECT_TRUE((ate.alignment * away).isApprox(Pose::Identity(), 1e-9));
}

TEST(SlamTrajectoryError, AlignmentMatchesUmeyama) {
  std::mt19937_64 rng(7);
  std::normal_distribution<double> n;
  for (int trial = 0; trial < 20; ++trial) {
    std::vector<StampedPose> g, e;
    const Pose away = rigid(n(rng), {n(rng), n(rng), n(rng)}, {n(rng), n(rng), n(rng)});
    Eigen::Matrix3Xd src(3, 30), dst(3, 30);
    for (int i = 0; i < 30; ++i) {
      const Eigen::Vector3d p(n(rng), n(rng), n(rng));
      const Eigen::Vector3d q = away * p + 0.05 * Eigen::Vector3d(n(rng), n(rng), n(rng));
      g.push_back(at(i, p));
      e.push_back(at(i, q));
      src.col(i) = q;
      dst.col(i) = p;
    }
    const Eigen::Matrix4d reference = Eigen::umeyama(src, dst, false);
    const AbsoluteError ate = absolute_trajectory_error(g, e);
    EXPECT_TRUE(ate.alignment.matrix().isApprox(reference, 1e-9)) << trial;
    double squares = 0.0;
    for (int i = 0; i < 30; ++i)
      squares += ((reference * src.col(i).homogeneous()).head<3>() - dst.col(i)).squaredNorm();
    EXPECT_NEAR(ate.rmse, std::sqrt(squares / 30), 1e-12);
  }
}

TEST(SlamTrajectoryError, HandCheckedRpe) {
  // Ground truth moves 1 m along x per frame, the estimate 1.1 m; the estimate also turns
  // 1 degree per frame about z where the truth does not.
  std::vector<StampedPose> g, e;
  for (int i = 0; i < 6; ++i) {
    g.push_back(at(i, {static_cast<double>(i), 0, 0}));
    StampedPose s = at(i, {1.1 * i, 0, 0});
    s.pose.linear() = Eigen::AngleAxisd(i * M_PI / 180.0, Eigen::Vector3d::UnitZ()).toRotationMatrix();
    e.push_back(s);
  }
  const RelativeError rpe = relative_pose_error(g, e);
  EXPECT_EQ(rpe.pairs, 5u);
  // E = (G_i^-1 G_j)^-1 (P_i^-1 P_j) has translation R_z(-i deg) (1.1, 0, 0) - (1, 0, 0).
  double squares = 0.0;
  for (int i = 0; i < 5; ++i) {
    const Eigen::Vector3d local = Eigen::AngleAxisd(-i * M_PI / 180.0, Eigen::Vector3d::UnitZ()) * Eigen::Vector3d(1.1, 0, 0);
    squares += (local - Eigen::Vector3d(1, 0, 0)).squaredNorm();
  }
  EXPECT_NEAR(rpe.translation_rmse, std::sqrt(squares / 5), 1e-12);
  EXPECT_NEAR(rpe.rotation_rmse_degrees, 1.0, 1e-9);
  EXPECT_NEAR(rpe.rotation_mean_degrees, 1.0, 1e-9);
}

TEST(SlamTrajectoryError, TooFewPairsIsAnError) {
  std::vector<StampedPose> g = {at(0, {0, 0, 0}), at(1, {1, 0, 0})};
  EXPECT_THROW(absolute_trajectory_error(g, g), vola::InvalidArgument);
  std::vector<StampedPose> far = {at(10, {0, 0, 0}), at(11, {0, 0, 0}), at(12, {0, 0, 0})};
  EXPECT_THROW(absolute_trajectory_error(far, g), vola::InvalidArgument);
}

}  // namespace
