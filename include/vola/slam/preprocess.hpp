// Per-frame preprocessing of KinectFusion: edge-preserving bilateral filtering of the
// depth, a pyramid of halved depth images, and vertex/normal maps in camera coordinates.
#pragma once

#include <Eigen/Geometry>
#include <cstdint>
#include <vector>

#include "vola/slam/image.hpp"

namespace vola::slam {

// Points and unit normals per pixel; a pixel without one holds NaN in x.
struct VertexMap {
  std::uint32_t width = 0, height = 0;
  std::vector<Eigen::Vector3f> vertices, normals;
  bool valid(std::size_t i) const noexcept { return vertices[i].x() == vertices[i].x() && normals[i].x() == normals[i].x(); }
};

// Bilateral filter: each valid pixel becomes the average of the valid pixels within
// `radius`, weighted by exp(-dpixel^2 / 2 sigma_space^2 - ddepth^2 / 2 sigma_depth^2);
// rows in parallel on `threads` threads (0 = vola::thread_count()).
DepthImage bilateral_filter(const DepthImage& depth, int radius, double sigma_space, double sigma_depth,
                            unsigned threads);
// Half-size depth: the mean of the 2x2 block's valid samples within 3 sigma_depth of its
// top-left sample (invalid when that one is).
DepthImage halve_depth(const DepthImage& depth, double sigma_depth, unsigned threads = 0);
// Back-projects every valid pixel; the normal is the cross product of the differences
// to the right and lower neighbours, turned to face the camera.
VertexMap vertex_normal_map(const DepthImage& depth, const Intrinsics& k, unsigned threads = 0);
// Half-size vertex map: the mean of a 2x2 block's valid vertices and normals.
VertexMap halve_vertex_map(const VertexMap& map, unsigned threads = 0);
// (Rows in parallel on `threads` threads, 0 = vola::thread_count(); every pixel is
// computed on its own, so the result does not depend on the count.)

}  // namespace vola::slam
