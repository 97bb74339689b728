// Rays through the shared benchmark camera (../shared/data/bench/README.md), vola against
// OpenVDB and OctoMap in this one process: a 256x256 pinhole at (120.5, 80.5, 450.5)
// looking at (560, 600, 260), up +z, 60 degree vertical field of view, one ray per pixel
// centre, each ray ending where it leaves the 1024^3 cube.
//
// For the surface and uniform sets, on the same voxels:
//   vola     : RayCaster (hierarchical DDA), 1 and 2 threads
//   OpenVDB  : MaskGrid, VolumeHDDA over the tree's nodes to the first leaf span, then a
//              voxel DDA through it testing isValueOn (and on to the next span), 1 thread
//   OctoMap  : OcTree (resolution 1) castRay, ignoring unknown cells, 1 thread
// Each figure is the median of --reps runs; every answer is checked against the
// voxel-by-voxel reference DDA (vola: voxel, distance and face; the peers: the voxel).
//
// Usage: vola_raycast_peers [--data DIR] [--reps N] [--sets surface,uniform]
// Exit status 0 when every vola hit is identical to the reference's (targets may be missed).
#include <openvdb/openvdb.h>
#include <openvdb/math/DDA.h>
#include <openvdb/math/Ray.h>
#include <octomap/OcTree.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "bench_data.hpp"
#include "vola/builder.hpp"
#include "vola/raycast/camera.hpp"
#include "vola/raycast/ray_caster.hpp"
#include "vola/raycast/reference_dda.hpp"

namespace {

namespace fs = std::filesystem;
using vola::Voxel;
using vola::raycast::Ray;
using vola::raycast::RayHit;
constexpr double kSide = 1024.0;

// The camera's rays, each ending where it leaves the cube [0, 1024]^3.
std::vector<Ray> camera_rays() {
  vola::raycast::PinholeCamera camera;
  camera.eye = {120.5, 80.5, 450.5};
  camera.look_at = {560, 600, 260};
  camera.up = {0, 0, 1};
  camera.vertical_fov_degrees = 60;
  camera.width = camera.height = 256;
  std::vector<Ray> rays;
  for (std::uint32_t row = 0; row < camera.height; ++row)
    for (std::uint32_t col = 0; col < camera.width; ++col) {
      Ray r = camera.ray(col, row);
      double leave = INFINITY;
      for (int a = 0; a < 3; ++a)
        if (r.direction[a] != 0.0)
          leave = std::min(leave, ((r.direction[a] > 0 ? kSide : 0.0) - r.origin[a]) / r.direction[a]);
      r.t_max = leave;
      rays.push_back(r);
    }
  return rays;
}

// Median seconds of `reps` runs of f.
double median_seconds(int reps, const std::function<void()>& f) {
  std::vector<double> s;
  for (int i = 0; i < reps; ++i) {
    const auto t0 = std::chrono::steady_clock::now();
    f();
    s.push_back(std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count());
  }
  std::sort(s.begin(), s.end());
  return s[s.size() / 2];
}

// --- OpenVDB ----------------------------------------------------------------------------
class VdbRays {
 public:
  explicit VdbRays(const std::vector<Voxel>& voxels) : grid_(openvdb::MaskGrid::create(false)) {
    auto acc = grid_->getAccessor();
    for (const Voxel& v : voxels) acc.setValueOn(openvdb::Coord(int(v.x), int(v.y), int(v.z)));
  }
  // The first active voxel along the ray, by VolumeHDDA spans of leaves and a voxel DDA.
  std::optional<Voxel> cast(const Ray& r) const {
    using RayT = openvdb::math::Ray<double>;
    using TreeT = openvdb::MaskGrid::TreeType;
    constexpr int kTop = TreeT::RootNodeType::ChildNodeType::LEVEL;
    openvdb::math::VolumeHDDA<TreeT, RayT, kTop> hdda;
    auto acc = grid_->getConstAccessor();
    const RayT::Vec3T eye(r.origin[0], r.origin[1], r.origin[2]), dir(r.direction[0], r.direction[1], r.direction[2]);
    double t0 = 0.0;
    while (t0 < r.t_max) {
      RayT ray(eye, dir, t0, r.t_max);
      const RayT::TimeSpan span = hdda.march(ray, acc);
      if (!span.valid()) return std::nullopt;
      RayT segment(eye, dir, span.t0, span.t1);
      openvdb::math::DDA<RayT, 0> dda(segment);
      do {
        if (acc.isValueOn(dda.voxel())) {
          const openvdb::Coord c = dda.voxel();
          return Voxel{std::uint32_t(c.x()), std::uint32_t(c.y()), std::uint32_t(c.z())};
        }
      } while (dda.step());
      t0 = span.t1;
    }
    return std::nullopt;
  }

 private:
  openvdb::MaskGrid::Ptr grid_;
};

// --- OctoMap ----------------------------------------------------------------------------
class OctoRays {
 public:
  explicit OctoRays(const std::vector<Voxel>& voxels) : tree_(1.0) {
    for (const Voxel& v : voxels) tree_.updateNode(octomap::point3d(v.x + 0.5f, v.y + 0.5f, v.z + 0.5f), true);
  }
  std::optional<Voxel> cast(const Ray& r) {
    octomap::point3d end;
    const octomap::point3d origin(float(r.origin[0]), float(r.origin[1]), float(r.origin[2]));
    const octomap::point3d dir(float(r.direction[0]), float(r.direction[1]), float(r.direction[2]));
    if (!tree_.castRay(origin, dir, end, true, r.t_max)) return std::nullopt;
    // end is the hit cell's centre.
    return Voxel{std::uint32_t(std::floor(end.x())), std::uint32_t(std::floor(end.y())),
                 std::uint32_t(std::floor(end.z()))};
  }

 private:
  octomap::OcTree tree_;
};

struct Row {
  std::string name;
  double rays_per_second = 0;
  std::size_t differ = 0;
};

}  // namespace

int main(int argc, char** argv) {
  fs::path data = vola_bench::default_data_dir();
  int reps = 5;
  std::vector<std::string> sets{"surface", "uniform"};
  for (int i = 1; i < argc; ++i) {
    const std::string arg = argv[i];
    if (arg == "--data" && i + 1 < argc) {
      data = argv[++i];
    } else if (arg == "--reps" && i + 1 < argc) {
      reps = std::max(1, std::atoi(argv[++i]));
    } else if (arg == "--sets" && i + 1 < argc) {
      sets.clear();
      std::string list = argv[++i];
      for (std::size_t at = 0; at <= list.size();) {
        const std::size_t comma = std::min(list.find(',', at), list.size());
        sets.push_back(list.substr(at, comma - at));
        at = comma + 1;
      }
    } else {
      std::fprintf(stderr, "usage: vola_raycast_peers [--data DIR] [--reps N] [--sets surface,uniform]\n");
      return 2;
    }
  }
  openvdb::initialize();
  const std::vector<Ray> rays = camera_rays();
  int status = 0;
  std::printf("## Rays: the shared benchmark camera (%zu rays, median of %d runs, one process)\n\n", rays.size(), reps);
  for (const std::string& set : sets) {
    const std::vector<Voxel> voxels = vola_bench::read_points(data / (set + "_points_1e6.npy")).voxels();
    const vola::Tree tree = vola::build_from_voxels(voxels, 5);
    const vola::raycast::RayCaster caster(tree);
    const VdbRays vdb(voxels);
    OctoRays octo(voxels);

    std::vector<std::optional<RayHit>> reference(rays.size());
    std::size_t hits = 0;
    for (std::size_t i = 0; i < rays.size(); ++i) hits += (reference[i] = vola::raycast::reference_cast(tree, rays[i])).has_value();

    std::vector<Row> rows;
    std::vector<std::optional<RayHit>> got(rays.size());
    for (unsigned threads : {1u, 2u}) {
      Row row{"vola RayCaster, " + std::to_string(threads) + (threads == 1 ? " thread" : " threads")};
      row.rays_per_second = rays.size() / median_seconds(reps, [&] { caster.cast(rays, got, threads); });
      for (std::size_t i = 0; i < rays.size(); ++i) row.differ += got[i] != reference[i];
      rows.push_back(row);
    }
    auto voxel_differs = [&](std::size_t i, const std::optional<Voxel>& v) {
      return v.has_value() != reference[i].has_value() || (v && !(*v == reference[i]->voxel));
    };
    std::vector<std::optional<Voxel>> voxel_hits(rays.size());
    Row vdb_row{"OpenVDB MaskGrid, VolumeHDDA + voxel DDA, 1 thread"};
    vdb_row.rays_per_second = rays.size() / median_seconds(reps, [&] {
      for (std::size_t i = 0; i < rays.size(); ++i) voxel_hits[i] = vdb.cast(rays[i]);
    });
    for (std::size_t i = 0; i < rays.size(); ++i) vdb_row.differ += voxel_differs(i, voxel_hits[i]);
    Row octo_row{"OctoMap OcTree castRay, 1 thread"};
    octo_row.rays_per_second = rays.size() / median_seconds(reps, [&] {
      for (std::size_t i = 0; i < rays.size(); ++i) voxel_hits[i] = octo.cast(rays[i]);
    });
    for (std::size_t i = 0; i < rays.size(); ++i) octo_row.differ += voxel_differs(i, voxel_hits[i]);
    rows.push_back(vdb_row);
    rows.push_back(octo_row);

    std::printf("### %s set (%llu voxels): %zu of %zu rays hit\n\n", set.c_str(),
                static_cast<unsigned long long>(tree.voxel_count()), hits, rays.size());
    std::printf("| caster | M rays/s | differ from the reference DDA |\n|---|---|---|\n");
    for (const Row& r : rows) std::printf("| %s | %.3f | %zu |\n", r.name.c_str(), r.rays_per_second / 1e6, r.differ);
    const double one = rows[0].rays_per_second, two = rows[1].rays_per_second;
    const double vs_vdb = one / vdb_row.rays_per_second, vs_octo = one / octo_row.rays_per_second;
    std::printf("\nvola single-threaded: %.2fx OpenVDB, %.1fx OctoMap; 2 threads scale %.2fx\n\n", vs_vdb, vs_octo,
                two / one);
    if (set == "surface") {
      std::printf("TARGET rays surface: vola 1 thread >= 3x OpenVDB HDDA: %.2fx %s\n", vs_vdb, vs_vdb >= 3 ? "PASS" : "MISS");
      std::printf("TARGET rays surface: vola 1 thread >= 30x OctoMap castRay: %.1fx %s\n", vs_octo,
                  vs_octo >= 30 ? "PASS" : "MISS");
      std::printf("TARGET rays surface: 2 threads near-linear (>= 1.8x): %.2fx %s\n", two / one,
                  two / one >= 1.8 ? "PASS" : "MISS");
    }
    std::printf("TARGET rays %s: every vola hit identical to the reference DDA: %s\n\n", set.c_str(),
                rows[0].differ + rows[1].differ == 0 ? "PASS" : "MISS");
    if (rows[0].differ + rows[1].differ) status = 1;
  }
  return status;
}
