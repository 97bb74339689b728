// A whole sequence through the fusion pipeline: frames read in order, tracked (or placed
// at their ground-truth poses) and integrated; the estimated trajectory comes back.
#pragma once

#include <functional>
#include <optional>
#include <string>

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
  std::vector<StampedPose> trajectory;  // one pose per processed frame, in world coordinates
  Eigen::Vector3d origin = Eigen::Vector3d::Zero();  // fuse_origin(): where the store's frame lies in the world
  std::size_t lost = 0;                 // frames whose tracking failed (kept the previous pose)
  std::size_t wide_baseline = 0;        // frames tracked by ICP from a colour-feature pose (large motion)
  std::size_t relocalised = 0;          // frames placed after a loss (the next frame, or the lost one later)
  std::vector<std::size_t> recovered;   // 1-based numbers of lost frames placed later (no longer lost)
  double seconds = 0.0;                 // wall time of reading + fusion
  double fusion_seconds = 0.0;          // of which tracking + fusion (the frames' processing alone)
  bool coloured = false;                // colour frames were integrated
  // Loop closure (FusionParams::loop_closure): loop edges found, how far they disagree
  // with the tracked trajectory, whether it was corrected (the disagreement exceeds
  // FusionParams::loop_min_correction), the largest keyframe move the pose graph made,
  // and the time spent integrating the map again at the corrected poses (not part of
  // `seconds`).
  std::size_t loop_edges = 0;
  LoopDisagreement loop_disagreement;
  bool loop_corrected = false;
  double loop_max_move = 0.0;
  // Keyframe refinement (FusionParams::refine_keyframes): keyframe pairs aligned, the
  // largest move it made (metres, degrees; 0 when it did not improve the alignment) and
  // whether the trajectory took it (a move above FusionParams::refine_min_move), and the
  // time it took (not part of `seconds`; integrating the map again is in
  // reintegration_seconds).
  std::size_t keyframes = 0;
  std::size_t refinement_pairs = 0;
  double refinement_max_move = 0.0, refinement_max_move_degrees = 0.0;
  bool refined = false;
  int refinement_level = -1;  // the pyramid level of the views aligned; -1: not run (too many keyframes for refine_memory, or off)
  double refinement_seconds = 0.0;
  double reintegration_seconds = 0.0;  // integrating the map again after loop closure or refinement
  std::uint32_t width = 0, height = 0;
  // Implausible input that did not stop the run (depth in the wrong unit, most of the
  // depth outside the depth range), each naming the file.
  std::vector<std::string> warnings;
};

// A warning when the frame's median measured depth is implausible for an RGB-D camera
// (under 0.1 m or over 12 m: the depth factor is likely wrong), or when most of its
// measurements lie outside [min_depth, max_depth]; nothing otherwise.
std::optional<std::string> depth_unit_warning(const DepthImage& depth, const std::string& path, double depth_factor,
                                              const FusionParams& params);

// The ground-truth pose associated with each frame (nullopt where none is within
// max_difference).
std::vector<std::optional<Pose>> groundtruth_per_frame(const Sequence& sequence, double max_difference);

// The pose of the first frame under `options` (identity unless it starts at ground truth).
Pose first_pose(const Sequence& sequence, const FuseOptions& options);

// The world point the fusion's frame is placed at: the first frame's ground-truth position
// when ground truth places the frames (start_at_groundtruth, groundtruth_poses), else 0.
// Tracking and fusion compute in single precision, which keeps about half a metre at
// survey coordinates such as UTM's millions of metres (a sequence placed there tracked
// 170 times worse), so they work relative to this point: the store's geometry is in that
// local frame (centred_geometry(zero, ...) puts the first frame at its centre), and
// FuseResult::trajectory comes back in world coordinates.
Eigen::Vector3d fuse_origin(const Sequence& sequence, const FuseOptions& options);

// A world pose in the frame whose origin is `origin` (to_local), and back (to_world).
Pose to_local(Pose pose, const Eigen::Vector3d& origin);
Pose to_world(Pose pose, const Eigen::Vector3d& origin);

// A volume of bricks_per_side bricks whose centre is at `centre`.
VolumeGeometry centred_geometry(const Eigen::Vector3d& centre, double voxel_size, std::uint32_t bricks_per_side);

// The store's geometry is in the local frame of fuse_origin() (see there).
// progress(frames done, frames total, last frame's result).
template <class Store>
FuseResult fuse_sequence(const Sequence& sequence, const FuseOptions& options, Store& store,
                         const std::function<void(std::size_t, std::size_t, const FrameResult&)>& progress = {});

}  // namespace vola::slam
