// A pose graph over keyframes, optimised by Gauss-Newton on SE(3): nodes are
// camera-to-world poses, edges measured relative poses (from -> to: T_from^-1 T_to) with
// weights for their translation and rotation residuals. Odometry edges join consecutive
// keyframes, loop edges a keyframe and an older one it was registered against; the
// optimum spreads a loop's disagreement along the chain.
#pragma once

#include <Eigen/Geometry>
#include <cstddef>
#include <vector>

namespace vola::slam {

struct PoseGraphEdge {
  std::size_t from = 0, to = 0;
  Eigen::Isometry3d measured = Eigen::Isometry3d::Identity();  // T_from^-1 T_to
  double translation_weight = 1.0;  // per metre^2
  double rotation_weight = 1.0;     // per radian^2
};

struct PoseGraphResult {
  int iterations = 0;
  double initial_cost = 0.0, final_cost = 0.0;
};

// Optimises `poses` in place (node 0 held fixed). Residual per edge: the translation
// and rotation vector (angle-axis) of measured^-1 T_from^-1 T_to, weighted; Jacobians by
// central differences of left perturbations exp(delta) T; sparse normal equations.
// Throws InvalidArgument for an edge naming a node that does not exist.
PoseGraphResult optimise_pose_graph(std::vector<Eigen::Isometry3d>& poses, const std::vector<PoseGraphEdge>& edges,
                                    int max_iterations = 20);

}  // namespace vola::slam
