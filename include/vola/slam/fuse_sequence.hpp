// A whole sequence through the fusion pipeline: frames read in order, tracked (or placed
// at their ground-truth poses) and integrated; the estimated trajectory comes back.
#pragma once

#include <functional>

#include "vola/slam/fusion.hpp"
#include "vola/slam/sequence.hpp"

namespace vola::slam {

struct FuseOptions {
  FusionParams params;
  Intrinsics intrinsics;
  double depth_factor = 5000.0;
  std::size_t max_frames = 0;         // 0 = all
  bool use_colour = true;             // integrate the RGB frames when the sequence has them
  bool groundtruth_poses = false;     // mapping only: every frame at its ground-truth pose
  bool start_at_groundtruth = false;  // the first frame at its ground-truth pose (else identity)
  double max_difference = 0.02;       // seconds, associating frames with ground truth
};

struct FuseResult {
  std::vector<StampedPose> trajectory;  // one pose per processed frame
  std::size_t lost = 0;                 // frames whose tracking failed (kept the previous pose)
  double seconds = 0.0;                 // wall time of reading + fusion
  bool coloured = false;                // colour frames were integrated
  std::uint32_t width = 0, height = 0;
};

// The ground-truth pose associated with each frame (nullopt where none is within
// max_difference).
std::vector<std::optional<Pose>> groundtruth_per_frame(const Sequence& sequence, double max_difference);

// The pose of the first frame under `options` (identity unless it starts at ground truth).
Pose first_pose(const Sequence& sequence, const FuseOptions& options);

// A volume of bricks_per_side bricks whose centre is at `centre`.
VolumeGeometry centred_geometry(const Eigen::Vector3d& centre, double voxel_size, std::uint32_t bricks_per_side);

// progress(frames done, frames total, last frame's result).
template <class Store>
FuseResult fuse_sequence(const Sequence& sequence, const FuseOptions& options, Store& store,
                         const std::function<void(std::size_t, std::size_t, const FrameResult&)>& progress = {});

}  // namespace vola::slam
