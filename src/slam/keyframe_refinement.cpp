#include "vola/slam/keyframe_refinement.hpp"

#include <Eigen/SparseCholesky>
#include <algorithm>
#include <cmath>
#include <string>

#include "vola/error.hpp"
#include "vola/parallel.hpp"

namespace vola::slam {

namespace {

using Matrix6 = Eigen::Matrix<double, 6, 6>;
using Vector6 = Eigen::Matrix<double, 6, 1>;

// What one ordered pair (source i, target j) adds to the normal equations.
struct PairSums {
  Matrix6 hii = Matrix6::Zero(), hij = Matrix6::Zero(), hjj = Matrix6::Zero();
  Vector6 gi = Vector6::Zero(), gj = Vector6::Zero();
  double cost = 0.0;
  std::size_t associated = 0;
};

struct Pair {
  std::size_t source = 0, target = 0;
};

// Kinect's axial depth noise (Nguyen, Izadi and Lovell 2012), metres at depth z.
double depth_sigma(double z) { return 0.0012 + 0.0019 * (z - 0.4) * (z - 0.4); }

// A rigid motion from a 6-vector (translation, rotation vector), applied on the left.
Pose small_motion(const Vector6& step) {
  Pose m = Pose::Identity();
  const Eigen::Vector3d omega = step.tail<3>();
  const double angle = omega.norm();
  if (angle > 0.0) m.linear() = Eigen::AngleAxisd(angle, omega / angle).toRotationMatrix();
  m.translation() = step.head<3>();
  return m;
}

double rotation_degrees(const Pose& a, const Pose& b) {
  return Eigen::AngleAxisd(a.linear().transpose() * b.linear()).angle() * 180.0 / M_PI;
}

class PairAligner {
 public:
  PairAligner(const std::vector<VertexMap>& views, const Intrinsics& k, const KeyframeRefinementParams& params)
      : views_(views), k_(k), params_(params), min_cos_(std::cos(params.max_angle_degrees * M_PI / 180.0)) {}

  std::size_t samples(std::size_t view) const {
    std::size_t n = 0;
    for_samples(view, [&](const Eigen::Vector3f&, const Eigen::Vector3f&) { ++n; });
    return n;
  }

  // The pair's sums at `poses`, associating points within max_distance of the surface.
  PairSums align(const Pair& pair, const std::vector<Pose>& poses, double max_distance) const {
    PairSums sums;
    const Pose& source_pose = poses[pair.source];
    const Pose& target_pose = poses[pair.target];
    const Pose source_to_target = target_pose.inverse() * source_pose;
    const VertexMap& target = views_[pair.target];
    for_samples(pair.source, [&](const Eigen::Vector3f& p, const Eigen::Vector3f& np) {
      const Eigen::Vector3d in_target = source_to_target * p.cast<double>();
      const double z = in_target.z();
      if (!(z > params_.min_depth)) return;
      const double u = std::round(k_.fx * in_target.x() / z + k_.cx);
      const double v = std::round(k_.fy * in_target.y() / z + k_.cy);
      if (!(u >= 0 && v >= 0 && u < target.width && v < target.height)) return;
      const std::size_t index = static_cast<std::size_t>(v) * target.width + static_cast<std::size_t>(u);
      if (!target.valid(index)) return;
      const Eigen::Vector3d q = target.vertices[index].cast<double>();
      if (q.z() < params_.min_depth || q.z() > params_.max_depth) return;
      const Eigen::Vector3d n_world = target_pose.linear() * target.normals[index].cast<double>();
      if ((source_pose.linear() * np.cast<double>()).dot(n_world) < min_cos_) return;
      const Eigen::Vector3d x = source_pose * p.cast<double>();
      const Eigen::Vector3d y = target_pose * q;
      const double r = n_world.dot(x - y);
      if (std::abs(r) > max_distance) return;
      const double sigma = depth_sigma(q.z());
      double weight = 1.0 / (sigma * sigma);
      if (std::abs(r) > 2.0 * sigma) weight *= 2.0 * sigma / std::abs(r);  // Huber
      sums.cost += weight * r * r;
      ++sums.associated;
      Vector6 ji, jj;
      ji << n_world, x.cross(n_world);
      jj << -n_world, -y.cross(n_world);
      sums.hii.noalias() += weight * ji * ji.transpose();
      sums.hij.noalias() += weight * ji * jj.transpose();
      sums.hjj.noalias() += weight * jj * jj.transpose();
      sums.gi += weight * r * ji;
      sums.gj += weight * r * jj;
    });
    return sums;
  }

 private:
  template <class Visit>
  void for_samples(std::size_t view, const Visit& visit) const {
    const VertexMap& map = views_[view];
    const auto step = static_cast<std::uint32_t>(params_.sample_step);
    for (std::uint32_t y = 0; y < map.height; y += step)
      for (std::uint32_t x = 0; x < map.width; x += step) {
        const std::size_t i = std::size_t{y} * map.width + x;
        if (!map.valid(i)) continue;
        const float z = map.vertices[i].z();
        if (z < params_.min_depth || z > params_.max_depth) continue;
        visit(map.vertices[i], map.normals[i]);
      }
  }

  const std::vector<VertexMap>& views_;
  Intrinsics k_;
  KeyframeRefinementParams params_;
  double min_cos_;
};

std::vector<PairSums> align_all(const PairAligner& aligner, const std::vector<Pair>& pairs,
                                const std::vector<Pose>& poses, double max_distance, unsigned threads) {
  std::vector<PairSums> sums(pairs.size());
  ParallelOptions parallel;
  parallel.threads = threads;
  parallel.name = "slam.keyframe_refinement";
  parallel_for(
      pairs.size(),
      [&](std::size_t begin, std::size_t end) {
        for (std::size_t p = begin; p < end; ++p) sums[p] = aligner.align(pairs[p], poses, max_distance);
      },
      parallel);
  return sums;
}

double mean_cost(const std::vector<PairSums>& sums) {
  double cost = 0.0;
  std::size_t count = 0;
  for (const PairSums& s : sums) {
    cost += s.cost;
    count += s.associated;
  }
  return count ? cost / static_cast<double>(count) : 0.0;
}

std::size_t associated(const std::vector<PairSums>& sums) {
  std::size_t count = 0;
  for (const PairSums& s : sums) count += s.associated;
  return count;
}

// For each keyframe, the nearest others (translation + 1 m per radian of rotation) whose
// views overlap enough at the start, up to max_neighbours.
std::vector<Pair> overlapping_pairs(const PairAligner& aligner, const std::vector<Pose>& poses,
                                    const KeyframeRefinementParams& params, double max_distance) {
  const std::size_t n = poses.size();
  std::vector<Pair> candidates;
  for (std::size_t i = 0; i < n; ++i) {
    std::vector<std::pair<double, std::size_t>> nearest;
    for (std::size_t j = 0; j < n; ++j)
      if (j != i)
        nearest.push_back({(poses[i].translation() - poses[j].translation()).norm() +
                               rotation_degrees(poses[i], poses[j]) * M_PI / 180.0,
                           j});
    const std::size_t keep = std::min(nearest.size(), 2 * params.max_neighbours);
    std::partial_sort(nearest.begin(), nearest.begin() + static_cast<std::ptrdiff_t>(keep), nearest.end());
    for (std::size_t c = 0; c < keep; ++c) candidates.push_back({i, nearest[c].second});
  }
  const std::vector<PairSums> start = align_all(aligner, candidates, poses, max_distance, params.threads);
  std::vector<std::size_t> samples(n);
  for (std::size_t i = 0; i < n; ++i) samples[i] = aligner.samples(i);
  std::vector<Pair> pairs;
  std::vector<std::size_t> taken(n, 0);
  for (std::size_t c = 0; c < candidates.size(); ++c) {  // nearest first within each source
    const Pair& pair = candidates[c];
    if (taken[pair.source] >= params.max_neighbours) continue;
    if (static_cast<double>(start[c].associated) < params.min_overlap * static_cast<double>(samples[pair.source]))
      continue;
    pairs.push_back(pair);
    ++taken[pair.source];
  }
  return pairs;
}

// Levenberg-Marquardt at one association distance, nodes 1 .. n-1 free (node 0 is
// held): a step is kept only when the mean cost falls without losing more than a tenth
// of the stage's first associations; otherwise the damping grows and the step is tried
// again, smaller. Returns the steps tried.
int refine_stage(const PairAligner& aligner, const std::vector<Pair>& pairs, std::vector<Pose>& current,
                 double max_distance, const KeyframeRefinementParams& params) {
  const std::size_t n = current.size();
  const auto unknowns = static_cast<Eigen::Index>(6 * (n - 1));
  std::vector<PairSums> sums = align_all(aligner, pairs, current, max_distance, params.threads);
  const std::size_t first_associated = associated(sums);
  double damping = 1e-4;
  int iteration = 0;
  while (iteration < params.iterations) {
    ++iteration;
    std::vector<Eigen::Triplet<double>> triplets;
    Eigen::VectorXd gradient = Eigen::VectorXd::Zero(unknowns);
    Eigen::VectorXd diagonal = Eigen::VectorXd::Zero(unknowns);
    const auto add_block = [&](std::size_t a, std::size_t b, const Matrix6& block) {
      if (a == 0 || b == 0) return;
      for (int r = 0; r < 6; ++r)
        for (int c = 0; c < 6; ++c)
          triplets.emplace_back(static_cast<Eigen::Index>(6 * (a - 1) + r), static_cast<Eigen::Index>(6 * (b - 1) + c),
                                block(r, c));
    };
    const auto add_node = [&](std::size_t node, const Vector6& g, const Matrix6& h) {
      if (node == 0) return;
      gradient.segment<6>(static_cast<Eigen::Index>(6 * (node - 1))) += g;
      diagonal.segment<6>(static_cast<Eigen::Index>(6 * (node - 1))) += h.diagonal();
    };
    for (std::size_t p = 0; p < pairs.size(); ++p) {
      const std::size_t i = pairs[p].source, j = pairs[p].target;
      add_block(i, i, sums[p].hii);
      add_block(j, j, sums[p].hjj);
      add_block(i, j, sums[p].hij);
      add_block(j, i, sums[p].hij.transpose());
      add_node(i, sums[p].gi, sums[p].hii);
      add_node(j, sums[p].gj, sums[p].hjj);
    }
    // The damping scales each unknown's own curvature; the constant keeps a keyframe no
    // pair observes (or a direction none does) still.
    for (Eigen::Index d = 0; d < unknowns; ++d) triplets.emplace_back(d, d, damping * diagonal[d] + 1e-3);
    Eigen::SparseMatrix<double> normal(unknowns, unknowns);
    normal.setFromTriplets(triplets.begin(), triplets.end());
    const Eigen::SimplicialLDLT<Eigen::SparseMatrix<double>> solver(normal);
    if (solver.info() != Eigen::Success) break;
    const Eigen::VectorXd step = -solver.solve(gradient);
    if (!step.allFinite()) break;
    std::vector<Pose> trial = current;
    for (std::size_t node = 1; node < n; ++node)
      trial[node] = small_motion(step.segment<6>(static_cast<Eigen::Index>(6 * (node - 1)))) * current[node];
    std::vector<PairSums> trial_sums = align_all(aligner, pairs, trial, max_distance, params.threads);
    if (mean_cost(trial_sums) < mean_cost(sums) && 10 * associated(trial_sums) >= 9 * first_associated) {
      current = std::move(trial);
      sums = std::move(trial_sums);
      damping = std::max(damping / 10, 1e-6);
      if (step.cwiseAbs().maxCoeff() < 1e-4) break;  // 0.1 mm, 0.006 degrees
    } else if ((damping *= 10) > 1e4) {
      break;  // no step helps: a minimum
    }
  }
  return iteration;
}

}  // namespace

void KeyframeRefinementParams::check() const {
  if (sample_step < 1) throw InvalidArgument("keyframe refinement: sample_step must be at least 1");
  if (iterations < 0) throw InvalidArgument("keyframe refinement: iterations must not be negative");
  if (!(max_distance > 0.0)) throw InvalidArgument("keyframe refinement: max_distance must be positive");
  if (!(max_angle_degrees > 0.0 && max_angle_degrees <= 180.0))
    throw InvalidArgument("keyframe refinement: max_angle_degrees must lie in (0, 180]");
  if (!(min_overlap >= 0.0 && min_overlap <= 1.0))
    throw InvalidArgument("keyframe refinement: min_overlap must lie in [0, 1]");
  if (!(min_depth >= 0.0 && max_depth > min_depth))
    throw InvalidArgument("keyframe refinement: the depth range must be increasing and not negative");
}

Intrinsics keyframe_view_intrinsics(const Intrinsics& k, int level) {
  Intrinsics out = k;
  for (int l = 0; l < level; ++l) out = out.halved();
  return out;
}

std::size_t keyframe_view_bytes(std::uint32_t width, std::uint32_t height, int level) {
  return std::size_t{width >> level} * (height >> level) * 2 * sizeof(Eigen::Vector3f);
}

VertexMap keyframe_view(DepthImage depth, const Intrinsics& k, const FusionParams& params, int level) {
  for (float& d : depth.metres)
    if (!(d >= params.min_depth && d <= params.max_depth)) d = 0.0f;
  depth = bilateral_filter(depth, params.bilateral_radius, params.bilateral_sigma_space, params.bilateral_sigma_depth,
                           params.threads);
  for (int l = 0; l < level; ++l) depth = halve_depth(depth, params.bilateral_sigma_depth, params.threads);
  return vertex_normal_map(depth, keyframe_view_intrinsics(k, level), params.threads);
}

KeyframeRefinementResult refine_keyframes(const std::vector<VertexMap>& views, const std::vector<Pose>& poses,
                                          const Intrinsics& k, const KeyframeRefinementParams& params) {
  params.check();
  k.check();
  if (views.size() != poses.size())
    throw InvalidArgument("keyframe refinement: " + std::to_string(views.size()) + " views for " +
                          std::to_string(poses.size()) + " poses");
  for (const VertexMap& view : views)
    if (view.width != views.front().width || view.height != views.front().height ||
        view.vertices.size() != std::size_t{view.width} * view.height || view.normals.size() != view.vertices.size())
      throw InvalidArgument("keyframe refinement: the views differ in size");
  KeyframeRefinementResult result;
  result.poses = poses;
  const std::size_t n = poses.size();
  if (n < 2 || params.iterations == 0) return result;
  const PairAligner aligner(views, k, params);
  const std::vector<Pair> pairs = overlapping_pairs(aligner, poses, params, 4 * params.max_distance);
  result.pairs = pairs.size();
  if (pairs.empty()) return result;

  // Coarse to fine in the association distance: poses a few centimetres and degrees off
  // associate little at the final distance.
  std::vector<Pose> current = poses;
  const std::vector<PairSums> at_start = align_all(aligner, pairs, current, params.max_distance, params.threads);
  result.initial_cost = mean_cost(at_start);
  for (const double scale : {4.0, 2.0, 1.0})
    result.iterations += refine_stage(aligner, pairs, current, scale * params.max_distance, params);
  const std::vector<PairSums> at_end = align_all(aligner, pairs, current, params.max_distance, params.threads);
  result.final_cost = mean_cost(at_end);
  // A pose driven off the surface loses its associations and with them its cost, so a
  // lower mean counts only when the associations did not fall by more than a tenth.
  result.improved =
      result.final_cost < result.initial_cost && 10 * associated(at_end) >= 9 * associated(at_start);
  if (!result.improved) return result;
  result.poses = current;
  for (std::size_t node = 0; node < n; ++node) {
    result.max_move_metres =
        std::max(result.max_move_metres, (current[node].translation() - poses[node].translation()).norm());
    result.max_move_degrees = std::max(result.max_move_degrees, rotation_degrees(current[node], poses[node]));
  }
  return result;
}

}  // namespace vola::slam
