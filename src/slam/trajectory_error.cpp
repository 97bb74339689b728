#include "vola/slam/trajectory_error.hpp"

#include <Eigen/SVD>
#include <algorithm>
#include <cmath>

#include "vola/error.hpp"

namespace vola::slam {

namespace {

std::vector<std::pair<std::size_t, std::size_t>> pairs_of(const std::vector<StampedPose>& groundtruth,
                                                         const std::vector<StampedPose>& estimate, double max_difference) {
  std::vector<double> te, tg;
  for (const auto& p : estimate) te.push_back(p.timestamp);
  for (const auto& p : groundtruth) tg.push_back(p.timestamp);
  return associate(te, tg, max_difference);  // (estimate index, groundtruth index)
}

}  // namespace

AbsoluteError absolute_trajectory_error(const std::vector<StampedPose>& groundtruth,
                                        const std::vector<StampedPose>& estimate, double max_difference) {
  const auto pairs = pairs_of(groundtruth, estimate, max_difference);
  if (pairs.size() < 3)
    throw InvalidArgument("ATE needs at least 3 associated poses, found " + std::to_string(pairs.size()));
  const auto n = static_cast<Eigen::Index>(pairs.size());
  Eigen::Matrix3Xd model(3, n), data(3, n);  // model = estimate, data = ground truth
  for (Eigen::Index i = 0; i < n; ++i) {
    model.col(i) = estimate[pairs[i].first].pose.translation();
    data.col(i) = groundtruth[pairs[i].second].pose.translation();
  }
  // Horn: rotation from the SVD of the cross-covariance of the centred point sets.
  const Eigen::Vector3d model_mean = model.rowwise().mean(), data_mean = data.rowwise().mean();
  const Eigen::Matrix3Xd mc = model.colwise() - model_mean, dc = data.colwise() - data_mean;
  const Eigen::Matrix3d w = dc * mc.transpose();
  const Eigen::JacobiSVD<Eigen::Matrix3d> svd(w, Eigen::ComputeFullU | Eigen::ComputeFullV);
  Eigen::Matrix3d s = Eigen::Matrix3d::Identity();
  if (svd.matrixU().determinant() * svd.matrixV().determinant() < 0) s(2, 2) = -1;  // a rotation, not a reflection
  const Eigen::Matrix3d rotation = svd.matrixU() * s * svd.matrixV().transpose();
  AbsoluteError error;
  error.pairs = pairs.size();
  error.alignment.linear() = rotation;
  error.alignment.translation() = data_mean - rotation * model_mean;
  std::vector<double> residuals;
  double squares = 0.0, sum = 0.0;
  for (Eigen::Index i = 0; i < n; ++i) {
    const double r = (error.alignment * Eigen::Vector3d(model.col(i)) - data.col(i)).norm();
    residuals.push_back(r);
    squares += r * r;
    sum += r;
  }
  error.rmse = std::sqrt(squares / static_cast<double>(n));
  error.mean = sum / static_cast<double>(n);
  error.max = *std::max_element(residuals.begin(), residuals.end());
  std::sort(residuals.begin(), residuals.end());
  const std::size_t m = residuals.size();
  error.median = m % 2 ? residuals[m / 2] : (residuals[m / 2 - 1] + residuals[m / 2]) / 2;
  return error;
}

RelativeError relative_pose_error(const std::vector<StampedPose>& groundtruth, const std::vector<StampedPose>& estimate,
                                  std::size_t delta, double max_difference) {
  if (delta == 0) throw InvalidArgument("RPE delta must be at least 1 frame");
  const auto pairs = pairs_of(groundtruth, estimate, max_difference);
  if (pairs.size() <= delta)
    throw InvalidArgument("RPE needs more than " + std::to_string(delta) + " associated poses, found " +
                          std::to_string(pairs.size()));
  RelativeError error;
  double t2 = 0.0, t1 = 0.0, r2 = 0.0, r1 = 0.0;
  for (std::size_t i = 0; i + delta < pairs.size(); ++i) {
    const Pose& p0 = estimate[pairs[i].first].pose;
    const Pose& p1 = estimate[pairs[i + delta].first].pose;
    const Pose& g0 = groundtruth[pairs[i].second].pose;
    const Pose& g1 = groundtruth[pairs[i + delta].second].pose;
    const Pose e = (g0.inverse() * g1).inverse() * (p0.inverse() * p1);
    const double t = e.translation().norm();
    // Angle of the rotation, as evaluate_rpe.py: arccos((trace - 1) / 2), clamped.
    const double c = std::clamp((e.linear().trace() - 1.0) / 2.0, -1.0, 1.0);
    const double r = std::acos(c) * 180.0 / M_PI;
    t2 += t * t;
    t1 += t;
    r2 += r * r;
    r1 += r;
    ++error.pairs;
  }
  const auto n = static_cast<double>(error.pairs);
  error.translation_rmse = std::sqrt(t2 / n);
  error.translation_mean = t1 / n;
  error.rotation_rmse_degrees = std::sqrt(r2 / n);
  error.rotation_mean_degrees = r1 / n;
  return error;
}

}  // namespace vola::slam
