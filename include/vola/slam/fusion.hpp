// KinectFusion over a brick TSDF store (tsdf_store.hpp): per frame, bilateral filter and
// a 3-level vertex/normal pyramid, projective point-to-plane ICP against the model
// raycast from the map at the previous pose (coarse to fine), TSDF integration of the
// filtered depth at the tracked pose into the bricks the frame's truncation band touches,
// and a new model raycast. Fusion<SparseTsdfStore> and Fusion<DenseTsdfStore> are the
// same code; only where the voxels live differs.
#pragma once

#include <array>
#include <cstdint>
#include <optional>
#include <vector>

#include "vola/slam/image.hpp"
#include "vola/slam/preprocess.hpp"
#include "vola/slam/sequence.hpp"
#include "vola/slam/tsdf_store.hpp"

namespace vola::slam {

inline constexpr int kPyramidLevels = 3;

struct FusionParams {
  double voxel_size = 0.01;        // metres
  double truncation = 0.04;        // metres; the TSDF is clamped to +-1 beyond it
  float max_weight = 64.0f;        // running-average window of the integration
  double min_depth = 0.2, max_depth = 5.0;  // measurements outside are ignored
  int bilateral_radius = 3;
  double bilateral_sigma_space = 4.5;  // pixels
  double bilateral_sigma_depth = 0.03;  // metres
  std::array<int, kPyramidLevels> icp_iterations{10, 5, 4};  // level 0 (full size) .. 2
  double icp_max_distance = 0.1;       // metres between associated points
  double icp_max_angle_degrees = 20;   // between associated normals
  // Constant-velocity motion prior where the depth says (almost) nothing. The prediction
  // is the previous pose moved by the last tracked frame-to-frame motion; in each ICP
  // solve, every eigen-direction of the 6x6 normal matrix whose eigenvalue is below
  // motion_prior times the largest is raised to that floor by a prior pulling towards
  // the prediction. Well-observed directions are left to the data (their eigenvalues are
  // above the floor); where point-to-plane ICP cannot observe a motion (a flat wall and
  // a sofa give no normal along the wall, so sliding along it is free) the prediction
  // decides instead of noise. No prior until a frame-to-frame motion has been tracked
  // (the second frame, the first after a lost one). 0 disables it (KinectFusion's tracker).
  double motion_prior = 1e-3;
  // A frame whose ICP update exceeds these (or has too few associations) is "lost":
  // its pose stays the previous one and it is not integrated.
  double max_step_translation = 0.2, max_step_rotation_degrees = 20;
  unsigned threads = 0;  // 0 = vola::thread_count() (the hardware's count unless set)
  // Throws InvalidArgument for values that make no sense.
  void check() const;
};

// The model surface seen from a pose: world-coordinate vertices and normals per pixel.
struct ModelView {
  std::array<VertexMap, kPyramidLevels> levels;
};

struct FrameResult {
  Pose pose = Pose::Identity();
  bool tracked = true;     // false: ICP failed, the previous pose was kept
  int correspondences = 0;  // at level 0 in the last iteration
};

template <class Store>
class Fusion {
 public:
  // The volume's geometry comes with the store; its voxel size must match params'.
  Fusion(Store& store, const Intrinsics& intrinsics, std::uint32_t width, std::uint32_t height,
         const FusionParams& params);
  // Tracks (from the second frame on) and integrates one frame. `rgb` may be null or
  // must have the depth's size. The first frame is placed at `initial_pose`.
  FrameResult process(const DepthImage& depth, const RgbImage* rgb, const Pose& initial_pose = Pose::Identity());
  // Integrates one frame at a known pose (mapping only, no tracking).
  FrameResult process_at_pose(const DepthImage& depth, const RgbImage* rgb, const Pose& pose);
  const Pose& pose() const noexcept { return pose_; }
  std::size_t frames() const noexcept { return frames_; }
  Store& store() noexcept { return store_; }

 private:
  std::optional<Pose> track(const std::array<VertexMap, kPyramidLevels>& frame, int* correspondences) const;
  DepthImage clipped(const DepthImage& raw, const RgbImage* rgb) const;
  DepthImage filtered(const DepthImage& depth) const;
  void integrate_and_predict(const DepthImage& depth, const RgbImage* rgb);
  void integrate(const DepthImage& depth, const RgbImage* rgb, const Pose& pose);

  Store& store_;
  Intrinsics intrinsics_;
  std::uint32_t width_, height_;
  FusionParams params_;
  Pose pose_ = Pose::Identity();
  std::optional<Pose> motion_;  // the last tracked frame-to-frame motion, previous^-1 * current
  std::size_t frames_ = 0;
  ModelView model_;
};

// Raycasts the TSDF from `pose` through the pinhole camera: world vertices and normals
// of the zero crossing per pixel (NaN where the ray finds none).
template <class Store>
VertexMap raycast(const Store& store, const Intrinsics& k, std::uint32_t width, std::uint32_t height,
                  const Pose& pose, const FusionParams& params);

// A shaded picture of the map from `pose`: the stored colour (grey when none was
// integrated) lit by the surface normal, black where nothing is seen.
template <class Store>
RgbImage render_view(const Store& store, const Intrinsics& k, std::uint32_t width, std::uint32_t height,
                     const Pose& pose, const FusionParams& params, bool use_colour);

// The bricks whose voxels lie within `truncation` of a measured depth along its pixel
// ray, in the order both stores allocate them (sorted).
std::vector<BrickCoord> bricks_in_band(const DepthImage& depth, const Intrinsics& k, const Pose& pose,
                                       const VolumeGeometry& geometry, double truncation);

}  // namespace vola::slam
