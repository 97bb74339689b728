// Synthetic RGB-D sequences with exact poses: depth (and colour) frames of a VOLA scene
// rendered along a trajectory through the ray caster (raycast/ray_caster.hpp), with a
// depth-camera noise and dropout model, written in the TUM layout (sequence.hpp).
#pragma once

#include <cstdint>
#include <functional>
#include <random>
#include <string>
#include <vector>

#include "vola/raycast/ray_caster.hpp"
#include "vola/slam/image.hpp"
#include "vola/slam/sequence.hpp"
#include "vola/tree.hpp"

namespace vola::slam {

// A furnished room (4 m x 5 m x 2.6 m, z up, the floor's corner at the world origin):
// walls, floor, ceiling, a table with legs, a cabinet, boxes, a ball and a column, as
// one-voxel-thick shells with u8 red/green/blue columns (textured floor and walls).
Tree room_scene(double voxel_size = 0.01);

// A hand-held-like loop inside room_scene(): the camera circles the room's centre on an
// ellipse, looking outward and slightly down, bobbing and rolling a little; frame i is
// turned by i * degrees_per_frame around the vertical.
std::vector<Pose> room_trajectory(std::size_t frames, double degrees_per_frame = 1.2);

// Kinect-like depth errors (Nguyen, Izadi, Lovell 2012): axial noise sigma(z) =
// axial_base + axial_quadratic * (z - 0.4)^2, growing towards grazing angles; no
// measurement beyond the range, at angles past dropout_angle_degrees, and at random
// with dropout_probability; depth quantised by the depth factor when written.
struct DepthNoise {
  bool enabled = true;
  double axial_base = 0.0012, axial_quadratic = 0.0019;
  double min_range = 0.4, max_range = 5.0;
  double dropout_angle_degrees = 80.0;
  double dropout_probability = 0.01;
};

struct GeneratorOptions {
  Intrinsics intrinsics{525.0, 525.0, 319.5, 239.5};
  std::uint32_t width = 640, height = 480;
  double depth_factor = 5000.0;
  double frame_rate = 30.0;  // timestamps 1 + i / frame_rate
  DepthNoise noise;
  std::uint64_t seed = 1;
  bool colour = true;  // also write rgb/ and rgb.txt (from the scene's red/green/blue columns, shaded)
  unsigned threads = 0;
};

// One frame: depth in metres along the optical axis (0 = no measurement) and colour.
struct RenderedFrame {
  DepthImage depth;
  RgbImage rgb;
};
RenderedFrame render_frame(const raycast::RayCaster& caster, const Pose& pose, const GeneratorOptions& options,
                           std::mt19937_64& rng);

// Writes depth/NNNNNN.png, depth.txt, groundtruth.txt and, with colour, rgb/NNNNNN.png
// and rgb.txt into `directory` (created). progress(i, n) after each frame.
void generate_sequence(const Tree& scene, const std::vector<Pose>& poses, const GeneratorOptions& options,
                       const std::string& directory,
                       const std::function<void(std::size_t, std::size_t)>& progress = {});

}  // namespace vola::slam
