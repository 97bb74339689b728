// Trajectory errors as TUM RGB-D's tools define them (evaluate_ate.py, evaluate_rpe.py).
#pragma once

#include <vector>

#include "vola/slam/sequence.hpp"

namespace vola::slam {

struct AbsoluteError {
  std::size_t pairs = 0;  // associated pose pairs
  double rmse = 0.0, mean = 0.0, median = 0.0, max = 0.0;  // metres
  Pose alignment = Pose::Identity();  // applied to the estimate: groundtruth ~ alignment * estimate
};

// Associates by timestamp (within max_difference), aligns the estimated positions onto
// the ground truth with the rigid (rotation + translation, no scale) least-squares
// transform (Horn's method), and reports the translational residuals. Throws
// InvalidArgument when fewer than 3 pairs associate.
AbsoluteError absolute_trajectory_error(const std::vector<StampedPose>& groundtruth,
                                        const std::vector<StampedPose>& estimate, double max_difference = 0.02);

struct RelativeError {
  std::size_t pairs = 0;
  double translation_rmse = 0.0, translation_mean = 0.0;  // metres per `delta` frames
  double rotation_rmse_degrees = 0.0, rotation_mean_degrees = 0.0;
};

// For associated frames i and i + delta (in the estimate's associated order): the error
// E = (G_i^-1 G_{i+delta})^-1 (P_i^-1 P_{i+delta}); its translation norm and rotation angle.
RelativeError relative_pose_error(const std::vector<StampedPose>& groundtruth, const std::vector<StampedPose>& estimate,
                                  std::size_t delta = 1, double max_difference = 0.02);

}  // namespace vola::slam
