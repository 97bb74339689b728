// Joint refinement of keyframe poses by dense multi-view alignment (what Open3D's
// reconstruction system calls multiway registration, done on the depth itself): every
// keyframe's depth is aligned at once with each of its overlapping keyframes', point to
// plane, and all poses move together (on SE(3), the first keyframe held).
//
// Why: frame-to-model tracking and feature registration place each frame against what
// came before it, so errors of frames far apart (0.5 m and more, as in real sequences
// with large motion) add up along the chain. Aligning every pair that sees the same
// surface lets later frames correct earlier ones. Levenberg-Marquardt, coarse to fine in
// the association distance (4, 2, then 1 x max_distance). On the real Kinect frames of the shared
// data this takes the trajectory from 4.6 cm to under 3 cm of the reference
// (docs/BENCHMARKS.md).
#pragma once

#include <cstddef>
#include <vector>

#include "vola/slam/fusion.hpp"
#include "vola/slam/image.hpp"
#include "vola/slam/preprocess.hpp"
#include "vola/slam/sequence.hpp"

namespace vola::slam {

struct KeyframeRefinementParams {
  int sample_step = 4;             // every sample_step-th pixel in x and y of a keyframe is a source point
  int iterations = 15;             // Levenberg-Marquardt steps at most, at each of 3 association distances
  double max_distance = 0.07;      // metres: a point further from the other view's surface is not associated
  double max_angle_degrees = 30;   // between associated normals
  double min_overlap = 0.1;        // a pair takes part when this fraction of the source's samples associate at the start
  std::size_t max_neighbours = 8;  // per keyframe, the nearest overlapping ones (translation + 1 m per radian)
  double min_depth = 0.2, max_depth = 5.0;  // metres; measurements outside are ignored
  unsigned threads = 0;            // 0 = vola::thread_count()
  // Throws InvalidArgument for values that make no sense.
  void check() const;
};

struct KeyframeRefinementResult {
  std::vector<Pose> poses;            // refined, one per keyframe (the input poses when nothing improved)
  std::size_t pairs = 0;              // ordered keyframe pairs aligned
  int iterations = 0;
  double initial_cost = 0.0, final_cost = 0.0;  // mean weighted squared residual over the pairs' associations
  bool improved = false;              // final_cost < initial_cost: `poses` are the refined ones
  double max_move_metres = 0.0, max_move_degrees = 0.0;  // the largest change of a keyframe's pose
};

// A keyframe's depth as the refinement aligns it: clipped to the depth range,
// bilateral-filtered as tracking does (normals of raw Kinect depth scatter by tens of
// degrees), halved `level` times, as camera-coordinate vertices and normals.
VertexMap keyframe_view(DepthImage depth, const Intrinsics& k, const FusionParams& params, int level);
// The intrinsics of those views, and the bytes one of them holds for a width x height frame.
Intrinsics keyframe_view_intrinsics(const Intrinsics& k, int level);
std::size_t keyframe_view_bytes(std::uint32_t width, std::uint32_t height, int level);

// `views` are the keyframes' vertex/normal maps in camera coordinates (keyframe_view),
// `poses` their camera-to-world poses, `k` the intrinsics of the views.
// Residual of a source point p of keyframe i associated (by projection) with the point q
// and normal n of keyframe j: n_w . (T_i p - T_j q), weighted by 1 / sigma(z)^2 with
// Kinect's axial noise sigma(z) = 0.0012 + 0.0019 (z - 0.4)^2 metres (Nguyen et al. 2012)
// and Huber beyond 2 sigma. Deterministic for any thread count (per-pair sums added in
// pair order). Throws InvalidArgument when views and poses differ in number or a view's
// size differs from the first's.
KeyframeRefinementResult refine_keyframes(const std::vector<VertexMap>& views, const std::vector<Pose>& poses,
                                          const Intrinsics& k, const KeyframeRefinementParams& params = {});

}  // namespace vola::slam
