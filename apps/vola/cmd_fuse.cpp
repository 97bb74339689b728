// vola fuse: KinectFusion-style dense SLAM over an RGB-D sequence, the map kept in
// VOLA-indexed TSDF bricks; writes the trajectory, the surface as .vol, a mesh, a view.
#include <cmath>
#include <cstdio>
#include <memory>
#include <string>
#include <vector>

#include "commands.hpp"
#include "text_output.hpp"
#include "number_checks.hpp"
#include "progress.hpp"
#include "vola/error.hpp"
#include "vola/file.hpp"
#include "vola/slam/fuse_sequence.hpp"
#include "vola/slam/map_export.hpp"
#include "vola/slam/trajectory_error.hpp"

namespace vola::cli {

namespace {

struct FuseArgs {
  std::string sequence, output, trajectory, mesh, render;
  std::vector<double> intrinsics, render_pose;
  double depth_factor = 5000.0, voxel_size = 0.01, truncation = 0.0, max_depth = 5.0, min_depth = 0.2;
  float max_weight = 64.0f;
  std::vector<int> icp_iterations{10, 5, 4};
  double motion_prior = slam::FusionParams{}.motion_prior;
  double photometric_weight = slam::FusionParams{}.photometric_weight;
  std::size_t frames = 0, render_frame = 1;
  std::uint32_t bricks = 4096;
  unsigned threads = 0;
  bool groundtruth_poses = false, start_at_groundtruth = false, no_colour = false, quiet = false, dense = false,
       no_features = false, no_loop_closure = false, no_refine = false;
};

slam::Pose pose_from(const std::vector<double>& v) {
  Eigen::Quaterniond q(v[6], v[3], v[4], v[5]);
  if (!(std::abs(q.norm() - 1.0) < 1e-3)) throw InvalidArgument("--render-pose: the quaternion must have norm 1");
  slam::Pose p = slam::Pose::Identity();
  p.linear() = q.normalized().toRotationMatrix();
  p.translation() = Eigen::Vector3d(v[0], v[1], v[2]);
  return p;
}

double mebibytes(std::size_t bytes) { return static_cast<double>(bytes) / 1048576.0; }

void print_memory(const slam::SparseTsdfStore& store, double voxel_size) {
  const slam::MapMemory memory = slam::map_memory(store);
  std::printf("map: %zu bricks of 8^3 voxels of %.4g m, %.1f MiB; a dense grid of the same extent (%u x %u x %u) needs %.1f MiB (%.1fx)\n",
              memory.bricks, voxel_size, mebibytes(memory.sparse_bytes), memory.extent_voxels[0], memory.extent_voxels[1],
              memory.extent_voxels[2], mebibytes(memory.dense_bytes),
              memory.sparse_bytes ? mebibytes(memory.dense_bytes) / mebibytes(memory.sparse_bytes) : 0.0);
}

void print_memory(const slam::DenseTsdfStore& store, double voxel_size) {
  std::printf("map: dense grid of %u^3 voxels of %.4g m, %.1f MiB (%zu bricks touched)\n", store.geometry().voxels_per_side(),
              voxel_size, mebibytes(store.memory_bytes()), store.brick_count());
}

template <class Store>
void fuse_into(const FuseArgs& a, const slam::Sequence& sequence, const slam::FuseOptions& options, Store& store) {
  Progress progress("fuse");
  const slam::FuseResult result =
      slam::fuse_sequence(sequence, options, store, [&](std::size_t done, std::size_t total, const slam::FrameResult& r) {
        if (!r.tracked && !a.quiet)
          std::fprintf(stderr, "frame %zu: tracking lost (%d associations, %d feature inliers), pose kept\n", done,
                       r.correspondences, r.feature_inliers);
        if (r.relocalised && !a.quiet)
          std::fprintf(stderr, "frame %zu: relocalised against a keyframe (%d feature inliers)\n", done,
                       r.feature_inliers);
        progress.update(done, total);
      });
  progress.finish();
  for (const auto& warning : result.warnings) std::fprintf(stderr, "vola fuse: warning: %s\n", warning.c_str());
  if (!a.quiet)
    for (const std::size_t frame : result.recovered)
      std::fprintf(stderr, "frame %zu: placed after all, against a later frame (no longer lost)\n", frame);
  if (result.trajectory.empty()) throw InvalidArgument(a.sequence + ": no frame has a ground-truth pose");
  if (!a.trajectory.empty()) slam::write_trajectory(a.trajectory, result.trajectory);
  const auto surface = slam::surface_voxels(store);
  if (surface.empty())  // a map of nothing is a mistake (depth in another unit, empty frames), not a result
    throw InvalidArgument(a.sequence + ": the frames made no surface: no depth was measured within --min-depth.."
                          "--max-depth at --depth-factor " + shortest_text(a.depth_factor) +
                          " stored units per metre (the warnings above say which frames); nothing written");
  slam::VolumeGeometry world = store.geometry();
  world.origin += result.origin;
  const Tree tree = slam::surface_tree(surface, world, result.coloured);
  if (!a.output.empty()) write(tree, a.output);
  std::size_t triangles = 0;
  if (!a.mesh.empty()) {
    const slam::Mesh mesh = slam::marching_cubes(store);
    slam::write_ply(a.mesh, mesh, result.coloured, result.origin);
    triangles = mesh.triangles.size();
  }
  if (!a.render.empty()) {
    slam::Pose view = result.trajectory.at(std::min(a.render_frame, result.trajectory.size()) - 1).pose;
    if (!a.render_pose.empty()) view = pose_from(a.render_pose);
    slam::write_rgb_png(a.render, slam::render_view(store, options.intrinsics, result.width, result.height,
                                                    slam::to_local(view, result.origin), options.params,
                                                    result.coloured));
  }
  if (a.quiet) return;
  const auto frames = result.trajectory.size();
  std::printf("%zu frames (%zu lost) in %.2f s: %.2f frames/s, %u x %u\n", frames, result.lost, result.seconds,
              static_cast<double>(frames) / result.seconds, result.width, result.height);
  std::printf("tracking + fusion: %.2f s, %.2f frames/s (the rest reads the frames)\n", result.fusion_seconds,
              static_cast<double>(frames) / result.fusion_seconds);
  if (result.wide_baseline || result.relocalised)
    std::printf("colour features: %zu frames tracked from a feature pose (large motion), %zu relocalised after a loss\n",
                result.wide_baseline, result.relocalised);
  if (result.loop_corrected)
    std::printf("loop closure: %zu loop edge%s, up to %.3f m / %.2f deg from the tracked trajectory; keyframes moved "
                "by up to %.3f m, map integrated again in %.2f s\n",
                result.loop_edges, result.loop_edges == 1 ? "" : "s", result.loop_disagreement.metres,
                result.loop_disagreement.degrees, result.loop_max_move, result.reintegration_seconds);
  else if (result.loop_edges)
    std::printf("loop closure: %zu loop edge%s, all within %.3f m / %.2f deg of the tracked trajectory: nothing to "
                "correct\n",
                result.loop_edges, result.loop_edges == 1 ? "" : "s", result.loop_disagreement.metres,
                result.loop_disagreement.degrees);
  if (result.refined)
    std::printf("keyframe refinement: %zu keyframes, %zu pairs aligned, keyframes moved by up to %.3f m / %.2f deg "
                "(%.2f s); map integrated again in %.2f s\n",
                result.keyframes, result.refinement_pairs, result.refinement_max_move, result.refinement_max_move_degrees,
                result.refinement_seconds, result.reintegration_seconds);
  else if (result.refinement_pairs)
    std::printf("keyframe refinement: %zu keyframes, %zu pairs aligned, keyframes would move by up to %.3f m / "
                "%.2f deg (%.2f s): trajectory kept\n",
                result.keyframes, result.refinement_pairs, result.refinement_max_move, result.refinement_max_move_degrees,
                result.refinement_seconds);
  print_memory(store, options.params.voxel_size);
  std::printf("surface: %zu voxels in the .vol (depth %d)%s\n", surface.size(), tree.depth(),
              a.mesh.empty() ? "" : (", " + std::to_string(triangles) + " triangles in the mesh").c_str());
  if (!sequence.groundtruth.empty() && !a.groundtruth_poses && frames >= 3) {
    // The outputs are written: ground truth that matches no frame in time is a warning
    // about the figures, not a failure of the run (it exited 1, or 0 with -q).
    slam::AbsoluteError ate;
    try {
      ate = slam::absolute_trajectory_error(sequence.groundtruth, result.trajectory);
    } catch (const InvalidArgument& e) {  // fewer than 3 poses associate
      std::fprintf(stderr,
                   "vola fuse: warning: %s: no ATE or RPE: its timestamps (%.6f .. %.6f s) and the frames' (%.6f .. "
                   "%.6f s) do not match (%s)\n",
                   (a.sequence + "/groundtruth.txt").c_str(), sequence.groundtruth.front().timestamp,
                   sequence.groundtruth.back().timestamp, result.trajectory.front().timestamp,
                   result.trajectory.back().timestamp, e.what());
      return;
    }
    std::printf("ATE: RMSE %.4f m, mean %.4f m, median %.4f m, max %.4f m over %zu poses\n", ate.rmse, ate.mean,
                ate.median, ate.max, ate.pairs);
    const auto rpe = slam::relative_pose_error(sequence.groundtruth, result.trajectory);
    std::printf("RPE (1 frame): translation RMSE %.4f m, rotation RMSE %.4f deg\n", rpe.translation_rmse,
                rpe.rotation_rmse_degrees);
  }
}

void run_fuse(const FuseArgs& a) {
  const slam::Sequence sequence = slam::read_sequence(a.sequence);
  slam::FuseOptions options;
  options.depth_factor = a.depth_factor;
  options.max_frames = a.frames;
  options.use_colour = !a.no_colour;
  options.groundtruth_poses = a.groundtruth_poses;
  options.start_at_groundtruth = a.start_at_groundtruth;
  if (!a.intrinsics.empty())
    options.intrinsics = {a.intrinsics[0], a.intrinsics[1], a.intrinsics[2], a.intrinsics[3]};
  else if (sequence.intrinsics)
    options.intrinsics = *sequence.intrinsics;
  slam::FusionParams& p = options.params;
  p.voxel_size = a.voxel_size;
  p.truncation = a.truncation > 0.0 ? a.truncation : 4 * a.voxel_size;
  p.max_weight = a.max_weight;
  p.min_depth = a.min_depth;
  p.max_depth = a.max_depth;
  for (int l = 0; l < slam::kPyramidLevels; ++l) p.icp_iterations[l] = a.icp_iterations[l];
  p.motion_prior = a.motion_prior;
  p.threads = a.threads;
  p.features = !a.no_features;
  p.loop_closure = !a.no_loop_closure;
  p.refine_keyframes = !a.no_refine;
  p.photometric_weight = a.photometric_weight;
  p.check();
  if ((a.groundtruth_poses || a.start_at_groundtruth) && sequence.groundtruth.empty())
    throw InvalidArgument(a.sequence + ": no ground truth (groundtruth.txt or pose.txt) for --groundtruth-poses / --start-at-groundtruth");

  // In the local frame of slam::fuse_origin (the first frame at its centre); the outputs go back to the world.
  const slam::VolumeGeometry geometry = slam::centred_geometry(Eigen::Vector3d::Zero(), p.voxel_size, a.bricks);
  if (a.dense) {
    const double bytes = std::pow(static_cast<double>(a.bricks), 3) * slam::kBrickVoxels * sizeof(slam::TsdfVoxel);
    if (bytes > 64.0 * (1ull << 30)) throw InvalidArgument("--dense: a grid of --bricks " + std::to_string(a.bricks) + " needs more than 64 GiB");
    slam::DenseTsdfStore store(geometry);
    fuse_into(a, sequence, options, store);
  } else {
    slam::SparseTsdfStore store(geometry);
    fuse_into(a, sequence, options, store);
  }
}

}  // namespace

void add_fuse(CLI::App& app) {
  auto a = std::make_shared<FuseArgs>();
  auto* cmd = app.add_subcommand("fuse", "Dense RGB-D SLAM (KinectFusion): track a depth sequence and fuse it into a VOLA-indexed TSDF map");
  cmd->footer(
      "SEQUENCE_DIR is TUM RGB-D's layout: depth.txt (\"timestamp path\" lines naming 16-bit depth PNGs),\n"
      "optional rgb.txt (associated by nearest timestamp within 20 ms), optional groundtruth.txt and\n"
      "intrinsics.txt (\"fx fy cx cy\"). A folder with depth/1.png|pgm, 2, ..., color/ and pose.txt (slambook's\n"
      "ICL-NUIM and Kinect frames) works too. Depth in metres = stored value / --depth-factor.\n"
      "Each frame is bilateral-filtered, tracked by point-to-plane ICP on a 3-level pyramid against the\n"
      "model raycast from the map, and integrated into 8^3-voxel TSDF bricks allocated only near the\n"
      "observed surfaces and indexed by VOLA occupancy words. With colour frames, ORB features (OpenCV)\n"
      "registered by RANSAC against the last frame restart ICP where the camera moved too far for it, and\n"
      "a frame ICP cannot track is relocalised against keyframes (then refined by ICP); a lost frame is\n"
      "placed later if a following frame registers with it. A photometric term (the previous frame's\n"
      "intensities) joins ICP, so texture holds motions that flat geometry leaves free. A frame that\n"
      "still fails keeps the previous pose and is not integrated. With ground truth, ATE and RPE are printed.\n"
      "The first frame's median depth is checked: a warning names the file when it is implausible\n"
      "(a wrong --depth-factor) or when most of it lies outside --min-depth..--max-depth.\n"
      "Outputs: the trajectory \"timestamp tx ty tz qx qy qz qw\" (camera to world; the first frame at the\n"
      "origin unless --start-at-groundtruth), the surface voxels as .vol (red/green/blue columns when colour\n"
      "frames exist), a marching-cubes mesh (PLY) and a rendered view (PNG). Ground truth in survey\n"
      "coordinates (UTM's millions of metres) is fine: tracking works relative to the first frame, and\n"
      "the mesh's vertices are then written as doubles.\n"
      "Examples:\n"
      "  vola rgbd-generate room --frames 300 && vola fuse room -o map.vol --trajectory est.txt --mesh map.ply --render view.png\n"
      "  vola fuse icl_frames --intrinsics 481.2 -480 319.5 239.5 --groundtruth-poses -o map.vol --render view.png");
  cmd->add_option("sequence", a->sequence, "Sequence folder")->required()->check(CLI::ExistingDirectory);
  cmd->add_option("-o,--output", a->output, "Map of surface voxels (.vol)");
  cmd->add_option("--trajectory", a->trajectory, "Estimated trajectory (TUM format)");
  cmd->add_option("--mesh", a->mesh, "Marching-cubes mesh (.ply)");
  cmd->add_option("--render", a->render, "Rendered view of the map (.png), from --render-frame's pose");
  cmd->add_option("--render-frame", a->render_frame, "Frame (1-based) whose estimated pose --render uses")->check(positive_number());
  cmd->add_option("--render-pose", a->render_pose, "Render from this pose instead: TX TY TZ QX QY QZ QW")->expected(7);
  cmd->add_option("--intrinsics", a->intrinsics, "FX FY CX CY in pixels (default: intrinsics.txt, else 525 525 319.5 239.5)")->expected(4);
  cmd->add_option("--depth-factor", a->depth_factor, "Stored depth units per metre (TUM 5000, Kinect mm 1000)")->check(positive_number());
  cmd->add_option("--voxel-size", a->voxel_size, "TSDF voxel size in metres")->check(positive_number());
  cmd->add_option("--truncation", a->truncation, "TSDF truncation in metres (default 4 voxels)")->check(positive_number());
  cmd->add_option("--max-weight", a->max_weight, "Integration weight cap (running-average window)")->check(positive_number());
  cmd->add_option("--min-depth", a->min_depth, "Ignore depths nearer than this (m)")->check(non_negative_number());
  cmd->add_option("--max-depth", a->max_depth, "Ignore depths farther than this (m)")->check(positive_number());
  cmd->add_option("--icp-iterations", a->icp_iterations, "ICP iterations at pyramid levels 0 (full size), 1, 2")->expected(3);
  cmd->add_option("--motion-prior", a->motion_prior,
                  "Constant-velocity prior in directions the depth barely constrains (ICP eigenvalues below this "
                  "fraction of the largest; 0 = none, as KinectFusion)")
      ->capture_default_str();
  cmd->add_option("--photometric-weight", a->photometric_weight,
                  "Weight of the colour (intensity) residuals next to ICP's, in metres per intensity unit "
                  "squared (0 = geometry only)")
      ->check(non_negative_number())
      ->capture_default_str();
  cmd->add_option("--frames", a->frames, "Process only the first N frames (0 = all)");
  cmd->add_option("--bricks", a->bricks, "Volume extent in bricks per side, centred on the first camera")->check(CLI::Range(1u, 1u << 17));
  cmd->add_flag("--groundtruth-poses", a->groundtruth_poses, "Map only: integrate every frame at its ground-truth pose");
  cmd->add_flag("--start-at-groundtruth", a->start_at_groundtruth, "Place the first frame at its ground-truth pose");
  cmd->add_flag("--no-colour", a->no_colour, "Ignore colour frames (no integration of colour, no features)");
  cmd->add_flag("--no-features", a->no_features,
                "Track by ICP only: no colour features for large motion or relocalisation");
  cmd->add_flag("--no-loop-closure", a->no_loop_closure,
                "No loop closure (by default a keyframe whose colour features register against an older one "
                "closes a loop: a pose graph corrects the trajectory and the map is integrated again)");
  cmd->add_flag("--no-refine", a->no_refine,
                "No keyframe refinement (by default, at the end, every keyframe's depth is aligned with its "
                "overlapping keyframes' at once; when that moves a keyframe by over 2 cm or 1 degree, the "
                "frames move with their keyframes and the map is integrated again)");
  cmd->add_flag("--dense", a->dense, "Keep the TSDF in a dense grid of --bricks^3 bricks instead (the same pipeline, for comparison)");
  cmd->add_option("--threads", a->threads, "Worker threads (0 = all cores)");
  cmd->add_flag("-q,--quiet", a->quiet, "No summary");
  cmd->callback([a] { run_fuse(*a); });
}

}  // namespace vola::cli
