// Sparse colour features for wide-baseline registration: ORB keypoints (OpenCV) with
// their 3D points from the depth frame, matched by Hamming distance (Lowe's ratio test)
// and registered by RANSAC over 3-point rigid fits (3D-3D, Umeyama) whose inliers
// reproject within a few pixels both ways. The tracker (fusion.hpp) uses them where frame-to-model
// ICP cannot hold: large motion between frames, and relocalising a lost frame against
// keyframes. Where ORB finds too few matches (a view turned far from every other one),
// SIFT features, slower but matching across wider changes of viewpoint, are registered
// the same way. Only detection needs OpenCV; a build without it has features_available()
// false and extracts none.
#pragma once

#include <Eigen/Geometry>
#include <array>
#include <cstdint>
#include <optional>
#include <vector>

#include "vola/slam/image.hpp"

namespace vola::slam {

using Descriptor = std::array<std::uint64_t, 4>;  // 256-bit ORB
using SiftDescriptor = std::array<std::uint8_t, 128>;

// Keypoints that have a valid depth: camera-frame points (metres) and descriptors, ORB
// (`descriptors`) or SIFT (`sift_descriptors`); only frames of the same kind match.
struct FeatureFrame {
  std::vector<Eigen::Vector3d> points;
  std::vector<Eigen::Vector2d> pixels;  // where each was detected
  std::vector<Descriptor> descriptors;
  std::vector<SiftDescriptor> sift_descriptors;
  Intrinsics intrinsics;
  std::size_t size() const noexcept { return points.size(); }
  bool sift() const noexcept { return !sift_descriptors.empty(); }
};

struct FeatureParams {
  int max_features = 2000;
  int fast_threshold = 7;      // grey levels; low, so that weakly textured views still have features
  double ratio = 0.9;          // Lowe's ratio: best / second best Hamming distance
  int max_hamming = 80;        // of 256 bits
  int ransac_iterations = 3000;  // samples at most; most fail the cheap side-length test
  // Sampling stops once a sample of three inliers would have been drawn with this
  // probability at the best consensus's inlier ratio (the usual adaptive bound): a few
  // dozen samples when most matches agree, ransac_iterations when few do.
  double ransac_confidence = 0.9999;
  int min_inliers = 12;        // a registration with fewer is refused
  double max_reprojection = 4.0;  // pixels, an inlier's error in both images
  std::uint64_t seed = 1;      // RANSAC sampling (deterministic)
  // SIFT, where ORB fails: at most sift_max_features (the strongest); the contrast
  // threshold is a quarter of OpenCV's default (0.04), for the same reason as the low
  // FAST threshold (weakly textured views); Lowe's ratio 0.8 on Euclidean distances.
  int sift_max_features = 1500;
  double sift_contrast_threshold = 0.01;
  double sift_ratio = 0.8;
};

// True when vola was built with OpenCV (features can be extracted).
bool features_available() noexcept;

// ORB on the grey image of `rgb`; keypoints kept where depth (metres, 0 = none) is
// valid and not at a depth edge (the 3x3 neighbourhood within 5% of the centre).
FeatureFrame extract_features(const RgbImage& rgb, const DepthImage& depth, const Intrinsics& k,
                              const FeatureParams& params);

// The same with SIFT keypoints (100-300 ms a 640 x 480 frame, ORB's tenfold and more).
FeatureFrame extract_sift_features(const RgbImage& rgb, const DepthImage& depth, const Intrinsics& k,
                                   const FeatureParams& params);

struct FeatureRegistration {
  // Maps points of `current` onto `reference`: reference ~ transform * current (so with
  // reference's camera-to-world pose P, the current camera's pose is P * transform).
  Eigen::Isometry3d transform = Eigen::Isometry3d::Identity();
  int matches = 0, inliers = 0;
  double rms = 0.0;  // pixels over the inliers (reference points in the reference image)
};

// Matches (each current feature's nearest reference descriptor passing the ratio test:
// Hamming distances for ORB, Euclidean for SIFT;
// each reference feature used once), samples rigid fits of 3 matches (RANSAC; inliers
// reproject within max_reprojection pixels into both images), refits on the inliers,
// then refines the pose by Gauss-Newton on the symmetric reprojection error of the
// inliers (pixels, Huber), which is less sensitive to depth noise than 3D distances. Nothing when fewer than
// params.min_inliers agree.
std::optional<FeatureRegistration> register_features(const FeatureFrame& reference, const FeatureFrame& current,
                                                     const FeatureParams& params);

}  // namespace vola::slam
