// Rays through the shared benchmark camera (../shared/data/bench/README.md): a 256x256
// pinhole at (120.5, 80.5, 450.5) looking at (560, 600, 260), up +z, 60 degree vertical
// field of view, one ray per pixel centre, each ray ending where it leaves the 1024^3 cube.
// For the surface and uniform sets: vola's hierarchical DDA single- and two-threaded
// (median of 5 runs), and every hit checked against the voxel-by-voxel reference DDA.
// The peers' published figures (same camera, same voxels) are printed for the ratios.
//
// Usage: vola_raycast_peers [DATA_DIR]   (default: ../shared/data/bench)
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <stdexcept>
#include <string>
#include <vector>

#include "vola/builder.hpp"
#include "vola/raycast/camera.hpp"
#include "vola/raycast/ray_caster.hpp"
#include "vola/raycast/reference_dda.hpp"

namespace {

namespace fs = std::filesystem;
using vola::raycast::Ray;
using vola::raycast::RayHit;

// NPY int16 (N, 3), C order, little-endian -> voxels.
std::vector<vola::Voxel> read_voxels(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  const std::vector<char> bytes((std::istreambuf_iterator<char>(in)), {});
  if (bytes.size() < 10 || std::memcmp(bytes.data(), "\x93NUMPY", 6) != 0)
    throw std::runtime_error(path.string() + ": not an .npy file");
  const std::size_t header_len = static_cast<unsigned char>(bytes[8]) | (static_cast<unsigned char>(bytes[9]) << 8);
  const std::string header(bytes.data() + 10, std::min(header_len, bytes.size() - 10));
  if (header.find("'<i2'") == std::string::npos || header.find("'fortran_order': False") == std::string::npos)
    throw std::runtime_error(path.string() + ": expected little-endian int16 in C order");
  const std::size_t at = 10 + header_len, rows = (bytes.size() - at) / 6;
  std::vector<vola::Voxel> voxels(rows);
  for (std::size_t i = 0; i < rows; ++i) {
    std::int16_t xyz[3];
    std::memcpy(xyz, bytes.data() + at + 6 * i, 6);
    voxels[i] = {static_cast<std::uint32_t>(xyz[0]), static_cast<std::uint32_t>(xyz[1]),
                 static_cast<std::uint32_t>(xyz[2])};
  }
  return voxels;
}

std::vector<Ray> camera_rays() {
  vola::raycast::PinholeCamera camera;
  camera.eye = {120.5, 80.5, 450.5};
  camera.look_at = {560, 600, 260};
  camera.up = {0, 0, 1};
  camera.vertical_fov_degrees = 60;
  camera.width = camera.height = 256;
  std::vector<Ray> rays;
  for (std::uint32_t row = 0; row < 256; ++row)
    for (std::uint32_t col = 0; col < 256; ++col) rays.push_back(camera.ray(col, row));
  return rays;
}

// Median rays/s of 5 batches on `threads` threads.
double rays_per_second(const vola::raycast::RayCaster& caster, const std::vector<Ray>& rays, unsigned threads,
                       std::vector<std::optional<RayHit>>& hits) {
  std::vector<double> rates;
  for (int run = 0; run < 5; ++run) {
    const auto start = std::chrono::steady_clock::now();
    caster.cast(rays, hits, threads);
    const double s = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    rates.push_back(static_cast<double>(rays.size()) / s);
  }
  std::sort(rates.begin(), rates.end());
  return rates[2];
}

}  // namespace

int main(int argc, char** argv) {
  const fs::path data = argc > 1 ? fs::path(argv[1]) : fs::path("../shared/data/bench");
  const std::vector<Ray> rays = camera_rays();
  struct Peer {
    const char* set;
    double openvdb, octomap;  // M rays/s, data README
  };
  constexpr Peer kPeers[] = {{"surface", 0.689, 0.0586}, {"uniform", 0.131, 0.0323}};
  int status = 0;
  for (const Peer& peer : kPeers) {
    const vola::Tree tree = vola::build_from_voxels(read_voxels(data / (std::string(peer.set) + "_points_1e6.npy")), 5);
    const vola::raycast::RayCaster caster(tree);
    std::vector<std::optional<RayHit>> one(rays.size()), two(rays.size());
    const double single = rays_per_second(caster, rays, 1, one);
    const double dual = rays_per_second(caster, rays, 2, two);
    std::size_t hit_count = 0, mismatches = 0;
    for (std::size_t i = 0; i < rays.size(); ++i) {
      const auto reference = vola::raycast::reference_cast(tree, rays[i]);
      hit_count += reference.has_value();
      mismatches += (reference != one[i]) + (reference != two[i]);
    }
    std::printf("%s set (%llu voxels): %zu of %zu rays hit, %zu differ from the reference DDA\n", peer.set,
                static_cast<unsigned long long>(tree.voxel_count()), hit_count, rays.size(), mismatches);
    std::printf("  vola 1 thread : %.3f M rays/s = %.2fx OpenVDB HDDA (%.3f), %.1fx OctoMap castRay (%.4f)\n",
                single / 1e6, single / 1e6 / peer.openvdb, peer.openvdb, single / 1e6 / peer.octomap, peer.octomap);
    std::printf("  vola 2 threads: %.3f M rays/s (scaling %.2fx)\n", dual / 1e6, dual / single);
    if (mismatches) status = 1;
  }
  return status;
}
