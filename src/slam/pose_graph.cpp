#include "vola/slam/pose_graph.hpp"

#include <Eigen/SparseCholesky>
#include <Eigen/SparseCore>
#include <cmath>

#include "vola/error.hpp"

namespace vola::slam {

namespace {

using Vec6 = Eigen::Matrix<double, 6, 1>;
using Mat6 = Eigen::Matrix<double, 6, 6>;

// exp of (rotation vector, translation) applied on the left.
Eigen::Isometry3d perturbed(const Eigen::Isometry3d& t, const Vec6& delta) {
  Eigen::Isometry3d d = Eigen::Isometry3d::Identity();
  const Eigen::Vector3d w = delta.head<3>();
  const double angle = w.norm();
  if (angle > 0.0) d.linear() = Eigen::AngleAxisd(angle, w / angle).toRotationMatrix();
  d.translation() = delta.tail<3>();
  return d * t;
}

Vec6 residual(const Eigen::Isometry3d& from, const Eigen::Isometry3d& to, const PoseGraphEdge& e) {
  const Eigen::Isometry3d error = e.measured.inverse() * from.inverse() * to;
  const Eigen::AngleAxisd aa(error.linear());
  Vec6 r;
  r.head<3>() = std::sqrt(e.rotation_weight) * aa.angle() * aa.axis();
  r.tail<3>() = std::sqrt(e.translation_weight) * error.translation();
  return r;
}

double cost(const std::vector<Eigen::Isometry3d>& poses, const std::vector<PoseGraphEdge>& edges) {
  double c = 0.0;
  for (const auto& e : edges) c += residual(poses[e.from], poses[e.to], e).squaredNorm();
  return c;
}

}  // namespace

PoseGraphResult optimise_pose_graph(std::vector<Eigen::Isometry3d>& poses, const std::vector<PoseGraphEdge>& edges,
                                    int max_iterations) {
  for (const auto& e : edges)
    if (e.from >= poses.size() || e.to >= poses.size() || e.from == e.to)
      throw InvalidArgument("pose graph: an edge names a missing node or joins a node to itself");
  PoseGraphResult result;
  result.initial_cost = result.final_cost = cost(poses, edges);
  const std::size_t n = poses.size();
  if (n < 2 || edges.empty()) return result;
  const auto unknowns = static_cast<Eigen::Index>(6 * (n - 1));  // node 0 is fixed
  const double h = 1e-6;
  for (int iteration = 0; iteration < max_iterations; ++iteration) {
    std::vector<Eigen::Triplet<double>> triplets;
    Eigen::VectorXd b = Eigen::VectorXd::Zero(unknowns);
    for (const auto& e : edges) {
      const Vec6 r = residual(poses[e.from], poses[e.to], e);
      Eigen::Matrix<double, 6, 12> j;
      for (int k = 0; k < 6; ++k) {
        Vec6 d = Vec6::Zero();
        d[k] = h;
        j.col(k) = (residual(perturbed(poses[e.from], d), poses[e.to], e) -
                    residual(perturbed(poses[e.from], -d), poses[e.to], e)) / (2 * h);
        j.col(6 + k) = (residual(poses[e.from], perturbed(poses[e.to], d), e) -
                        residual(poses[e.from], perturbed(poses[e.to], -d), e)) / (2 * h);
      }
      const std::size_t nodes[2] = {e.from, e.to};
      for (int a = 0; a < 2; ++a) {
        if (nodes[a] == 0) continue;
        const auto ra = static_cast<Eigen::Index>(6 * (nodes[a] - 1));
        b.segment<6>(ra) -= j.middleCols<6>(6 * a).transpose() * r;
        for (int c = 0; c < 2; ++c) {
          if (nodes[c] == 0) continue;
          const auto rc = static_cast<Eigen::Index>(6 * (nodes[c] - 1));
          const Mat6 block = j.middleCols<6>(6 * a).transpose() * j.middleCols<6>(6 * c);
          for (int x = 0; x < 6; ++x)
            for (int y = 0; y < 6; ++y) triplets.emplace_back(ra + x, rc + y, block(x, y));
        }
      }
    }
    Eigen::SparseMatrix<double> a(unknowns, unknowns);
    a.setFromTriplets(triplets.begin(), triplets.end());
    for (Eigen::Index i = 0; i < unknowns; ++i) a.coeffRef(i, i) += 1e-9;  // nodes no edge reaches stay put
    Eigen::SimplicialLDLT<Eigen::SparseMatrix<double>> solver(a);
    if (solver.info() != Eigen::Success) break;
    const Eigen::VectorXd delta = solver.solve(b);
    if (!delta.allFinite()) break;
    std::vector<Eigen::Isometry3d> next = poses;
    for (std::size_t i = 1; i < n; ++i) next[i] = perturbed(poses[i], delta.segment<6>(static_cast<Eigen::Index>(6 * (i - 1))));
    const double c = cost(next, edges);
    ++result.iterations;
    if (!(c < result.final_cost)) break;
    const double gain = result.final_cost - c;
    poses = std::move(next);
    result.final_cost = c;
    if (gain < 1e-12 * (1.0 + c)) break;
  }
  return result;
}

}  // namespace vola::slam
