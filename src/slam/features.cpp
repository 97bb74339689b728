#include "vola/slam/features.hpp"

#include <Eigen/Geometry>
#include <algorithm>
#include <bit>
#include <cmath>
#include <cstring>
#include <limits>
#include <random>

#include "orb_plugin.hpp"

namespace vola::slam {

bool features_available() noexcept { return VOLA_SLAM_WITH_OPENCV != 0; }

namespace {

// RANSAC draws at least this many samples whatever the consensus: on the Kinect frames,
// whose pairs share few matches, the adaptive bound alone (or a floor of 300) ended at
// other consensus sets and an ATE of 2.25 cm instead of 2.04 cm.
constexpr int kMinRansacSamples = 1000;

std::vector<std::uint8_t> grey_of(const RgbImage& rgb) {
  std::vector<std::uint8_t> grey(std::size_t{rgb.width} * rgb.height);
  for (std::size_t i = 0; i < grey.size(); ++i) {
    const std::uint8_t* c = &rgb.rgb[i * 3];
    grey[i] = static_cast<std::uint8_t>((299 * c[0] + 587 * c[1] + 114 * c[2] + 500) / 1000);
  }
  return grey;
}

bool usable(const RgbImage& rgb, const DepthImage& depth) {
  return features_available() && rgb.width == depth.width && rgb.height == depth.height && rgb.width >= 16 &&
         rgb.height >= 16;
}

// The camera-frame point of a keypoint, when its pixel has a depth and is not at a depth
// edge (the 3x3 neighbourhood within 5% of the centre).
std::optional<Eigen::Vector3d> keypoint_point(float x, float y, const DepthImage& depth, const Intrinsics& k) {
  const int u = static_cast<int>(std::lround(x)), v = static_cast<int>(std::lround(y));
  if (u < 1 || v < 1 || u + 1 >= static_cast<int>(depth.width) || v + 1 >= static_cast<int>(depth.height))
    return std::nullopt;
  const float z = depth.at(static_cast<std::uint32_t>(u), static_cast<std::uint32_t>(v));
  if (!(z > 0.0f)) return std::nullopt;
  for (int dv = -1; dv <= 1; ++dv)
    for (int du = -1; du <= 1; ++du) {
      const float n = depth.at(static_cast<std::uint32_t>(u + du), static_cast<std::uint32_t>(v + dv));
      if (!(n > 0.0f) || std::abs(n - z) > 0.05f * z) return std::nullopt;
    }
  return Eigen::Vector3d((x - k.cx) / k.fx * z, (y - k.cy) / k.fy * z, z);
}

}  // namespace

FeatureFrame extract_features(const RgbImage& rgb, const DepthImage& depth, const Intrinsics& k,
                              const FeatureParams& params) {
  FeatureFrame out;
  if (!usable(rgb, depth)) return out;
  const std::vector<std::uint8_t> grey = grey_of(rgb);
  // OpenCV is loaded on the first colour frame (libvola_opencv.so), not at every start.
  static const auto detect = reinterpret_cast<plugin::DetectOrbEntry>(
      vola::plugin::plugin_symbol("opencv", plugin::kDetectOrbSymbol, "ORB features of a colour frame"));
  std::vector<plugin::OrbKeypoint> keypoints;
  vola::plugin::PluginFailure failure;
  detect(grey.data(), rgb.width, rgb.height, params.max_features, params.fast_threshold, keypoints, failure);
  vola::plugin::throw_failure(failure);
  out.intrinsics = k;
  for (const plugin::OrbKeypoint& kp : keypoints) {
    const auto point = keypoint_point(kp.x, kp.y, depth, k);
    if (!point) continue;
    out.points.push_back(*point);
    out.pixels.emplace_back(kp.x, kp.y);
    Descriptor d;
    std::memcpy(d.data(), kp.descriptor.data(), 32);
    out.descriptors.push_back(d);
  }
  return out;
}

FeatureFrame extract_sift_features(const RgbImage& rgb, const DepthImage& depth, const Intrinsics& k,
                                   const FeatureParams& params) {
  FeatureFrame out;
  if (!usable(rgb, depth)) return out;
  const std::vector<std::uint8_t> grey = grey_of(rgb);
  static const auto detect = reinterpret_cast<plugin::DetectSiftEntry>(
      vola::plugin::plugin_symbol("opencv", plugin::kDetectSiftSymbol, "SIFT features of a colour frame"));
  std::vector<plugin::SiftKeypoint> keypoints;
  vola::plugin::PluginFailure failure;
  detect(grey.data(), rgb.width, rgb.height, params.sift_max_features, params.sift_contrast_threshold, keypoints,
         failure);
  vola::plugin::throw_failure(failure);
  out.intrinsics = k;
  for (const plugin::SiftKeypoint& kp : keypoints) {
    const auto point = keypoint_point(kp.x, kp.y, depth, k);
    if (!point) continue;
    out.points.push_back(*point);
    out.pixels.emplace_back(kp.x, kp.y);
    out.sift_descriptors.push_back(kp.descriptor);
  }
  return out;
}

namespace {

int hamming(const Descriptor& a, const Descriptor& b) noexcept {
  return std::popcount(a[0] ^ b[0]) + std::popcount(a[1] ^ b[1]) + std::popcount(a[2] ^ b[2]) +
         std::popcount(a[3] ^ b[3]);
}

// For each SIFT descriptor of `from`, the index of its nearest in `to` (Euclidean) when
// it passes the ratio test (else -1). The squared distances come from one matrix
// product, |a|^2 + |b|^2 - 2 a.b, which is what makes brute force affordable here.
std::vector<int> nearest_sift(const FeatureFrame& from, const FeatureFrame& to, const FeatureParams& params) {
  const auto matrix_of = [](const FeatureFrame& f) {
    Eigen::MatrixXf m(128, static_cast<Eigen::Index>(f.size()));
    for (std::size_t i = 0; i < f.size(); ++i)
      for (std::size_t j = 0; j < 128; ++j) m(static_cast<Eigen::Index>(j), static_cast<Eigen::Index>(i)) = f.sift_descriptors[i][j];
    return m;
  };
  const Eigen::MatrixXf a = matrix_of(from), b = matrix_of(to);
  const Eigen::MatrixXf dot = a.transpose() * b;
  const Eigen::VectorXf b_norms = b.colwise().squaredNorm().transpose();
  const float ratio2 = static_cast<float>(params.sift_ratio * params.sift_ratio);
  std::vector<int> out(from.size(), -1);
  for (Eigen::Index i = 0; i < dot.rows(); ++i) {
    float best = std::numeric_limits<float>::max(), second = best;
    int at = -1;
    for (Eigen::Index j = 0; j < dot.cols(); ++j) {
      const float d = b_norms[j] - 2.0f * dot(i, j);  // |a_i|^2 left out: the same for every j
      if (d < best) {
        second = best;
        best = d;
        at = static_cast<int>(j);
      } else if (d < second) {
        second = d;
      }
    }
    if (at < 0 || dot.cols() < 2) continue;
    const float own = a.col(i).squaredNorm();
    if (best + own < ratio2 * (second + own)) out[static_cast<std::size_t>(i)] = at;
  }
  return out;
}

// For each descriptor of `from`, the index of its nearest in `to` when it passes the
// ratio test and the distance limit (else -1).
std::vector<int> nearest(const FeatureFrame& from, const FeatureFrame& to, const FeatureParams& params) {
  if (from.sift() != to.sift()) return std::vector<int>(from.size(), -1);
  if (from.sift()) return nearest_sift(from, to, params);
  std::vector<int> out(from.size(), -1);
  for (std::size_t i = 0; i < from.size(); ++i) {
    int best = 1 << 20, second = 1 << 20, at = -1;
    for (std::size_t j = 0; j < to.size(); ++j) {
      const int d = hamming(from.descriptors[i], to.descriptors[j]);
      if (d < best) {
        second = best;
        best = d;
        at = static_cast<int>(j);
      } else if (d < second) {
        second = d;
      }
    }
    if (at >= 0 && best <= params.max_hamming && best < params.ratio * second) out[i] = at;
  }
  return out;
}

// How much a triangle side of matched points may differ between the frames: depth noise
// of a structured-light or time-of-flight camera grows with the square of the range.
double side_tolerance(double z) { return 0.02 + 0.01 * z * z; }

Eigen::Isometry3d rigid_fit(const std::vector<Eigen::Vector3d>& from, const std::vector<Eigen::Vector3d>& to) {
  Eigen::Matrix3Xd a(3, from.size()), b(3, to.size());
  for (std::size_t i = 0; i < from.size(); ++i) {
    a.col(static_cast<Eigen::Index>(i)) = from[i];
    b.col(static_cast<Eigen::Index>(i)) = to[i];
  }
  Eigen::Isometry3d t = Eigen::Isometry3d::Identity();
  t.matrix() = Eigen::umeyama(a, b, false);
  return t;
}

Eigen::Vector2d project(const Intrinsics& k, const Eigen::Vector3d& p) {
  return {k.fx * p.x() / p.z() + k.cx, k.fy * p.y() / p.z() + k.cy};
}

// Residuals of transform t (current -> reference), Huber-weighted beyond 2 pixels:
// reference points into the current image and current points into the reference image.
// (Adding the matched points' 3D distances, weighted by a depth noise growing with the
// square of the range, made the Kinect frames' registrations worse: 0.8 m off for one
// pair, ATE 25 cm instead of 6.5.)
Eigen::VectorXd reprojection_residuals(const Eigen::Isometry3d& t, const FeatureFrame& reference,
                                       const FeatureFrame& current, const std::vector<int>& set,
                                       const std::vector<std::size_t>& from_index,
                                       const std::vector<std::size_t>& to_index) {
  Eigen::VectorXd r = Eigen::VectorXd::Zero(static_cast<Eigen::Index>(4 * set.size()));
  const Eigen::Isometry3d inverse = t.inverse();
  const auto huber = [](auto&& e) {
    const double norm = e.norm();
    if (norm > 2.0) e *= std::sqrt(2.0 / norm);
  };
  for (std::size_t n = 0; n < set.size(); ++n) {
    const std::size_t c = from_index[static_cast<std::size_t>(set[n])], f = to_index[static_cast<std::size_t>(set[n])];
    const Eigen::Vector3d in_current = inverse * reference.points[f], in_reference = t * current.points[c];
    Eigen::Vector4d e = Eigen::Vector4d::Zero();
    if (in_current.z() > 0.0 && in_reference.z() > 0.0) {
      e.head<2>() = project(current.intrinsics, in_current) - current.pixels[c];
      e.segment<2>(2) = project(reference.intrinsics, in_reference) - reference.pixels[f];
    }
    huber(e.head<2>());
    huber(e.segment<2>(2));
    r.segment<4>(static_cast<Eigen::Index>(4 * n)) = e;
  }
  return r;
}

Eigen::Isometry3d applied(const Eigen::Isometry3d& t, const Eigen::Matrix<double, 6, 1>& d) {
  Eigen::Isometry3d step = Eigen::Isometry3d::Identity();
  const Eigen::Vector3d w = d.head<3>();
  if (w.norm() > 0.0) step.linear() = Eigen::AngleAxisd(w.norm(), w / w.norm()).toRotationMatrix();
  step.translation() = d.tail<3>();
  return step * t;
}

Eigen::Isometry3d refine_reprojection(Eigen::Isometry3d t, const FeatureFrame& reference, const FeatureFrame& current,
                                      const std::vector<int>& set, const std::vector<std::size_t>& from_index,
                                      const std::vector<std::size_t>& to_index) {
  if (set.size() < 6) return t;
  double cost = reprojection_residuals(t, reference, current, set, from_index, to_index).squaredNorm();
  for (int iteration = 0; iteration < 10; ++iteration) {
    const Eigen::VectorXd r = reprojection_residuals(t, reference, current, set, from_index, to_index);
    Eigen::MatrixXd j(r.size(), 6);
    for (int k = 0; k < 6; ++k) {
      Eigen::Matrix<double, 6, 1> d = Eigen::Matrix<double, 6, 1>::Zero();
      d[k] = 1e-6;
      j.col(k) = (reprojection_residuals(applied(t, d), reference, current, set, from_index, to_index) -
                  reprojection_residuals(applied(t, -d), reference, current, set, from_index, to_index)) / 2e-6;
    }
    const Eigen::Matrix<double, 6, 1> delta = (j.transpose() * j).ldlt().solve(-j.transpose() * r);
    if (!delta.allFinite()) break;
    const Eigen::Isometry3d next = applied(t, delta);
    const double next_cost = reprojection_residuals(next, reference, current, set, from_index, to_index).squaredNorm();
    if (!(next_cost < cost)) break;
    t = next;
    const double gain = cost - next_cost;
    cost = next_cost;
    if (gain < 1e-9 * cost) break;
  }
  return t;
}

}  // namespace

std::optional<FeatureRegistration> register_features(const FeatureFrame& reference, const FeatureFrame& current,
                                                     const FeatureParams& params) {
  if (reference.size() < 3 || current.size() < 3) return std::nullopt;
  const std::vector<int> forward = nearest(current, reference, params);
  // A reference feature chosen by several current ones is ambiguous: none of them is kept.
  std::vector<int> chosen(reference.size(), 0);
  for (const int j : forward)
    if (j >= 0) ++chosen[static_cast<std::size_t>(j)];
  std::vector<Eigen::Vector3d> from, to;  // current's points, reference's
  std::vector<std::size_t> from_index, to_index;
  for (std::size_t i = 0; i < forward.size(); ++i)
    if (forward[i] >= 0 && chosen[static_cast<std::size_t>(forward[i])] == 1) {
      from.push_back(current.points[i]);
      to.push_back(reference.points[static_cast<std::size_t>(forward[i])]);
      from_index.push_back(i);
      to_index.push_back(static_cast<std::size_t>(forward[i]));
    }
  const int matches = static_cast<int>(from.size());
  if (matches < std::max(3, params.min_inliers)) return std::nullopt;
  // Inliers by reprojection both ways (each point into the other image within
  // params.max_reprojection pixels): depth noise, which grows with the square of the
  // range, moves a projection only by the parallax it causes, so far points count too.
  const double limit2 = params.max_reprojection * params.max_reprojection;
  auto inliers_of = [&](const Eigen::Isometry3d& t, std::vector<int>* which) {
    const Eigen::Isometry3d inverse = t.inverse();
    int count = 0;
    for (int i = 0; i < matches; ++i) {
      const Eigen::Vector3d in_reference = t * from[i], in_current = inverse * to[i];
      if (!(in_reference.z() > 0.0 && in_current.z() > 0.0)) continue;
      if ((project(reference.intrinsics, in_reference) - reference.pixels[to_index[i]]).squaredNorm() > limit2 ||
          (project(current.intrinsics, in_current) - current.pixels[from_index[i]]).squaredNorm() > limit2)
        continue;
      ++count;
      if (which) which->push_back(i);
    }
    return count;
  };
  std::mt19937_64 rng(params.seed);
  std::uniform_int_distribution<int> pick(0, matches - 1);
  Eigen::Isometry3d best = Eigen::Isometry3d::Identity();
  int best_count = -1;
  double needed = params.ransac_iterations;  // samples, lowered as the consensus grows
  for (int iteration = 0; iteration < params.ransac_iterations && iteration < needed; ++iteration) {
    const int a = pick(rng), b = pick(rng), c = pick(rng);
    if (a == b || b == c || a == c) continue;
    // A rigid motion keeps the triangle's sides; a sample that does not is an outlier.
    bool consistent = true;
    const int idx[3] = {a, b, c};
    for (int p = 0; p < 3 && consistent; ++p) {
      const int i = idx[p], j = idx[(p + 1) % 3];
      const double df = (from[i] - from[j]).norm(), dt = (to[i] - to[j]).norm();
      if (df < 0.05 || std::abs(df - dt) > side_tolerance(std::max(to[i].z(), to[j].z()))) consistent = false;
    }
    if (!consistent) continue;
    // A degenerate (nearly collinear) triangle does not fix the rotation.
    if ((from[b] - from[a]).cross(from[c] - from[a]).norm() < 1e-3) continue;
    const Eigen::Isometry3d t = rigid_fit({from[a], from[b], from[c]}, {to[a], to[b], to[c]});
    const int count = inliers_of(t, nullptr);
    if (count > best_count) {
      best_count = count;
      best = t;
      const double all_three = std::pow(static_cast<double>(count) / matches, 3);
      if (all_three >= 1.0)
        needed = kMinRansacSamples;
      else if (all_three > 0.0)
        needed = std::max<double>(kMinRansacSamples,
                                  std::log(1.0 - params.ransac_confidence) / std::log(1.0 - all_three));
    }
  }
  if (best_count < params.min_inliers) return std::nullopt;
  // Refit on the inliers until the set settles.
  std::vector<int> which;
  for (int round = 0; round < 3; ++round) {
    which.clear();
    inliers_of(best, &which);
    if (static_cast<int>(which.size()) < params.min_inliers) return std::nullopt;
    std::vector<Eigen::Vector3d> f, t;
    for (int i : which) {
      f.push_back(from[i]);
      t.push_back(to[i]);
    }
    best = rigid_fit(f, t);
  }
  // Symmetric reprojection refinement over the inliers.
  {
    std::vector<int> set;
    inliers_of(best, &set);
    best = refine_reprojection(best, reference, current, set, from_index, to_index);
  }
  which.clear();
  const int count = inliers_of(best, &which);
  if (count < params.min_inliers) return std::nullopt;
  double sum = 0.0;
  for (int i : which) sum += (project(reference.intrinsics, best * from[i]) - reference.pixels[to_index[i]]).squaredNorm();
  FeatureRegistration r;
  r.transform = best;
  r.matches = matches;
  r.inliers = count;
  r.rms = std::sqrt(sum / count);
  return r;
}

}  // namespace vola::slam
