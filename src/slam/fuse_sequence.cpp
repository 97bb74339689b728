#include "vola/slam/fuse_sequence.hpp"

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <memory>

#include "vola/error.hpp"
#include "vola/slam/keyframe_refinement.hpp"

namespace vola::slam {

std::vector<std::optional<Pose>> groundtruth_per_frame(const Sequence& sequence, double max_difference) {
  std::vector<double> frames, truth;
  for (const auto& f : sequence.frames) frames.push_back(f.timestamp);
  for (const auto& g : sequence.groundtruth) truth.push_back(g.timestamp);
  std::vector<std::optional<Pose>> out(sequence.frames.size());
  for (const auto& [i, j] : associate(frames, truth, max_difference)) out[i] = sequence.groundtruth[j].pose;
  return out;
}

Pose first_pose(const Sequence& sequence, const FuseOptions& options) {
  if (!options.start_at_groundtruth && !options.groundtruth_poses) return Pose::Identity();
  for (const auto& pose : groundtruth_per_frame(sequence, options.max_difference))
    if (pose) return *pose;
  throw InvalidArgument("the sequence has no ground-truth pose for any frame");
}

Eigen::Vector3d fuse_origin(const Sequence& sequence, const FuseOptions& options) {
  return first_pose(sequence, options).translation();
}

Pose to_local(Pose pose, const Eigen::Vector3d& origin) {
  pose.translation() -= origin;
  return pose;
}

Pose to_world(Pose pose, const Eigen::Vector3d& origin) {
  pose.translation() += origin;
  return pose;
}

VolumeGeometry centred_geometry(const Eigen::Vector3d& centre, double voxel_size, std::uint32_t bricks_per_side) {
  VolumeGeometry g;
  g.voxel_size = voxel_size;
  g.bricks_per_side = bricks_per_side;
  g.origin = centre - Eigen::Vector3d::Constant(0.5 * bricks_per_side * kBrickSide * voxel_size);
  g.check();
  return g;
}

std::optional<std::string> depth_unit_warning(const DepthImage& depth, const std::string& path, double depth_factor,
                                              const FusionParams& params) {
  std::vector<float> measured;
  std::size_t outside = 0;
  for (const float d : depth.metres)
    if (d > 0.0f) {
      measured.push_back(d);
      if (d < params.min_depth || d > params.max_depth) ++outside;
    }
  if (measured.empty()) return path + ": no depth measured in the first frame";
  auto middle = measured.begin() + static_cast<std::ptrdiff_t>(measured.size() / 2);
  std::nth_element(measured.begin(), middle, measured.end());
  const double median = *middle;
  char text[400];
  if (median < 0.1 || median > 12.0) {
    std::snprintf(text, sizeof text,
                  ": median depth %.3g m at depth factor %g is implausible for an RGB-D camera; is the depth factor "
                  "right (TUM PNG 5000, millimetres 1000)?",
                  median, depth_factor);
    return path + text;
  }
  if (outside * 2 > measured.size()) {
    std::snprintf(text, sizeof text, ": %.0f%% of the measured depth lies outside %g..%g m (median %.3g m)",
                  100.0 * static_cast<double>(outside) / static_cast<double>(measured.size()), params.min_depth,
                  params.max_depth, median);
    return path + text;
  }
  return std::nullopt;
}

namespace {

// fuse_sequence in the local frame of result.origin: every pose here, the trajectory's
// included, is local.
template <class Store>
FuseResult fuse_locally(const Sequence& sequence, const FuseOptions& options, Store& store,
                        const std::function<void(std::size_t, std::size_t, const FrameResult&)>& progress) {
  const auto start = std::chrono::steady_clock::now();
  const std::size_t total =
      options.max_frames ? std::min(options.max_frames, sequence.frames.size()) : sequence.frames.size();
  if (total == 0) throw InvalidArgument("the sequence has no frames");
  std::vector<std::optional<Pose>> truth;
  FuseResult result;
  result.origin = fuse_origin(sequence, options);
  if (options.groundtruth_poses) {
    truth = groundtruth_per_frame(sequence, options.max_difference);
    for (auto& pose : truth)
      if (pose) pose = to_local(*pose, result.origin);
  }
  const Pose initial = to_local(first_pose(sequence, options), result.origin);
  const auto read_colour = [&](const SequenceFrame& frame, const DepthImage& depth) -> std::optional<RgbImage> {
    if (!options.use_colour || frame.rgb_path.empty()) return std::nullopt;
    RgbImage rgb = read_rgb_png(frame.rgb_path);
    if (rgb.width != depth.width || rgb.height != depth.height)
      throw FormatError(frame.rgb_path, std::nullopt, "colour frame is " + std::to_string(rgb.width) + " x " +
                                                          std::to_string(rgb.height) + ", its depth frame " +
                                                          std::to_string(depth.width) + " x " + std::to_string(depth.height));
    result.coloured = true;
    return rgb;
  };
  std::unique_ptr<Fusion<Store>> fusion;
  std::vector<std::size_t> sequence_index;  // of each processed frame
  std::vector<bool> integrated;             // per processed frame: in the map (tracked or placed later)
  for (std::size_t i = 0; i < total; ++i) {
    const SequenceFrame& frame = sequence.frames[i];
    if (options.groundtruth_poses && !truth[i]) continue;  // no pose to place it at
    const DepthImage depth = read_depth(frame.depth_path, options.depth_factor);
    const std::optional<RgbImage> rgb = read_colour(frame, depth);
    if (!fusion) {
      if (auto warning = depth_unit_warning(depth, frame.depth_path, options.depth_factor, options.params))
        result.warnings.push_back(std::move(*warning));
      fusion = std::make_unique<Fusion<Store>>(store, options.intrinsics, depth.width, depth.height, options.params);
      result.width = depth.width;
      result.height = depth.height;
    }
    const auto fusion_start = std::chrono::steady_clock::now();
    const FrameResult r = options.groundtruth_poses ? fusion->process_at_pose(depth, rgb ? &*rgb : nullptr, *truth[i])
                                                    : fusion->process(depth, rgb ? &*rgb : nullptr, initial);
    result.fusion_seconds += std::chrono::duration<double>(std::chrono::steady_clock::now() - fusion_start).count();
    sequence_index.push_back(i);
    integrated.push_back(r.tracked);
    if (!r.tracked) ++result.lost;
    if (r.wide_baseline) ++result.wide_baseline;
    if (r.relocalised) ++result.relocalised;
    result.trajectory.push_back({frame.timestamp, r.pose});
    // Lost frames placed later, against a frame tracked after them.
    if (!options.groundtruth_poses)
      for (const auto& recovered : fusion->take_recovered()) {
        result.trajectory.at(recovered.frame).pose = recovered.pose;
        integrated.at(recovered.frame) = true;
        --result.lost;
        ++result.relocalised;
        result.recovered.push_back(recovered.frame + 1);
      }
    if (progress) progress(i + 1, total, r);
  }
  result.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  if (fusion && !options.groundtruth_poses && options.params.loop_closure && !fusion->loops().empty()) {
    result.loop_edges = fusion->loops().size();
    result.loop_disagreement = loop_disagreement(fusion->keyframe_poses(), fusion->loops());
    result.loop_corrected = result.loop_disagreement.metres > options.params.loop_min_correction ||
                            result.loop_disagreement.degrees > options.params.loop_min_correction_degrees;
  }
  if (!fusion || options.groundtruth_poses) return result;
  std::vector<Pose> poses;
  for (const auto& p : result.trajectory) poses.push_back(p.pose);
  std::vector<KeyframePose> keyframes = fusion->keyframe_poses();
  result.keyframes = keyframes.size();
  if (result.loop_corrected) {
    const LoopCorrection correction = correct_trajectory(poses, keyframes, fusion->loops());
    result.loop_max_move = correction.max_keyframe_move;
    poses = correction.poses;
    for (KeyframePose& k : keyframes) k.pose = poses[k.frame];
  }
  bool refined = false;
  int level = options.params.refine_level;  // the finest whose views fit refine_memory
  const auto views_fit = [&] {
    return keyframes.size() * keyframe_view_bytes(result.width, result.height, level) <= options.params.refine_memory;
  };
  while (level + 1 < kPyramidLevels && !views_fit()) ++level;
  const bool refine = options.params.refine_keyframes && keyframes.size() >= 2;
  if (refine && !views_fit())
    result.warnings.push_back("keyframe refinement skipped: the views of " + std::to_string(keyframes.size()) +
                              " keyframes need more than FusionParams::refine_memory (" +
                              std::to_string(options.params.refine_memory >> 20) + " MiB) even at a quarter size");
  if (refine && views_fit()) {
    const auto refine_start = std::chrono::steady_clock::now();
    result.refinement_level = level;
    std::vector<VertexMap> views;
    std::vector<Pose> keyframe_poses;
    for (const KeyframePose& k : keyframes) {
      const SequenceFrame& frame = sequence.frames[sequence_index.at(k.frame)];
      views.push_back(keyframe_view(read_depth(frame.depth_path, options.depth_factor), options.intrinsics,
                                    options.params, level));
      keyframe_poses.push_back(k.pose);
    }
    KeyframeRefinementParams settings;
    settings.min_depth = options.params.min_depth;
    settings.max_depth = options.params.max_depth;
    settings.threads = options.params.threads;
    settings.sample_step = std::max(1, settings.sample_step >> level);  // the same pixels at any level
    const KeyframeRefinementResult refinement = refine_keyframes(
        views, keyframe_poses, keyframe_view_intrinsics(options.intrinsics, level), settings);
    result.refinement_pairs = refinement.pairs;
    result.refinement_max_move = refinement.max_move_metres;
    result.refinement_max_move_degrees = refinement.max_move_degrees;
    refined = refinement.improved && (refinement.max_move_metres > options.params.refine_min_move ||
                                      refinement.max_move_degrees > options.params.refine_min_move_degrees);
    if (refined) poses = move_with_keyframes(poses, keyframes, refinement.poses);
    result.refined = refined;
    result.refinement_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - refine_start).count();
  }
  if (result.loop_corrected || refined) {
    // The map again, every integrated frame at its corrected pose.
    const auto again_start = std::chrono::steady_clock::now();
    for (std::size_t f = 0; f < poses.size(); ++f) result.trajectory[f].pose = poses[f];
    fusion.reset();
    store.clear();
    Fusion<Store> again(store, options.intrinsics, result.width, result.height, options.params);
    for (std::size_t f = 0; f < poses.size(); ++f) {
      if (!integrated[f]) continue;
      const SequenceFrame& frame = sequence.frames[sequence_index[f]];
      const DepthImage depth = read_depth(frame.depth_path, options.depth_factor);
      const std::optional<RgbImage> rgb = read_colour(frame, depth);
      again.integrate_at_pose(depth, rgb ? &*rgb : nullptr, poses[f]);
    }
    result.reintegration_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - again_start).count();
  }
  return result;
}

}  // namespace

template <class Store>
FuseResult fuse_sequence(const Sequence& sequence, const FuseOptions& options, Store& store,
                         const std::function<void(std::size_t, std::size_t, const FrameResult&)>& progress) {
  FuseResult result = fuse_locally(sequence, options, store, progress);
  for (StampedPose& p : result.trajectory) p.pose = to_world(p.pose, result.origin);
  return result;
}

template FuseResult fuse_sequence(const Sequence&, const FuseOptions&, SparseTsdfStore&,
                                  const std::function<void(std::size_t, std::size_t, const FrameResult&)>&);
template FuseResult fuse_sequence(const Sequence&, const FuseOptions&, DenseTsdfStore&,
                                  const std::function<void(std::size_t, std::size_t, const FrameResult&)>&);

}  // namespace vola::slam
