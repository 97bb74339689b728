#include "vola/slam/fuse_sequence.hpp"

#include <chrono>
#include <memory>

#include "vola/error.hpp"

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

VolumeGeometry centred_geometry(const Eigen::Vector3d& centre, double voxel_size, std::uint32_t bricks_per_side) {
  VolumeGeometry g;
  g.voxel_size = voxel_size;
  g.bricks_per_side = bricks_per_side;
  g.origin = centre - Eigen::Vector3d::Constant(0.5 * bricks_per_side * kBrickSide * voxel_size);
  g.check();
  return g;
}

template <class Store>
FuseResult fuse_sequence(const Sequence& sequence, const FuseOptions& options, Store& store,
                         const std::function<void(std::size_t, std::size_t, const FrameResult&)>& progress) {
  const auto start = std::chrono::steady_clock::now();
  const std::size_t total =
      options.max_frames ? std::min(options.max_frames, sequence.frames.size()) : sequence.frames.size();
  if (total == 0) throw InvalidArgument("the sequence has no frames");
  std::vector<std::optional<Pose>> truth;
  if (options.groundtruth_poses) truth = groundtruth_per_frame(sequence, options.max_difference);
  const Pose initial = first_pose(sequence, options);
  FuseResult result;
  std::unique_ptr<Fusion<Store>> fusion;
  for (std::size_t i = 0; i < total; ++i) {
    const SequenceFrame& frame = sequence.frames[i];
    if (options.groundtruth_poses && !truth[i]) continue;  // no pose to place it at
    const DepthImage depth = read_depth(frame.depth_path, options.depth_factor);
    std::optional<RgbImage> rgb;
    if (options.use_colour && !frame.rgb_path.empty()) {
      rgb = read_rgb_png(frame.rgb_path);
      if (rgb->width != depth.width || rgb->height != depth.height)
        throw FormatError(frame.rgb_path, std::nullopt, "colour frame is " + std::to_string(rgb->width) + " x " +
                                                            std::to_string(rgb->height) + ", its depth frame " +
                                                            std::to_string(depth.width) + " x " + std::to_string(depth.height));
      result.coloured = true;
    }
    if (!fusion) {
      fusion = std::make_unique<Fusion<Store>>(store, options.intrinsics, depth.width, depth.height, options.params);
      result.width = depth.width;
      result.height = depth.height;
    }
    const FrameResult r = options.groundtruth_poses ? fusion->process_at_pose(depth, rgb ? &*rgb : nullptr, *truth[i])
                                                    : fusion->process(depth, rgb ? &*rgb : nullptr, initial);
    if (!r.tracked) ++result.lost;
    result.trajectory.push_back({frame.timestamp, r.pose});
    if (progress) progress(i + 1, total, r);
  }
  result.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return result;
}

template FuseResult fuse_sequence(const Sequence&, const FuseOptions&, SparseTsdfStore&,
                                  const std::function<void(std::size_t, std::size_t, const FrameResult&)>&);
template FuseResult fuse_sequence(const Sequence&, const FuseOptions&, DenseTsdfStore&,
                                  const std::function<void(std::size_t, std::size_t, const FrameResult&)>&);

}  // namespace vola::slam
