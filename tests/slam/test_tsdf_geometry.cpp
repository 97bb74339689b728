// Marching cubes, surface voxels and raycasting on an analytic sphere TSDF, the case
// table's invariants, and the vertex/normal maps of a plane.
#include <gtest/gtest.h>

#include <cmath>
#include <map>
#include <random>
#include <set>

#include "vola/slam/fusion.hpp"
#include "vola/slam/map_export.hpp"

namespace {

using namespace vola::slam;

const Eigen::Vector3d kCentre(0.5, 0.45, 0.55);
constexpr double kRadius = 0.3, kVoxel = 0.02, kTruncation = 0.08;

// Bricks within the truncation band of the sphere, filled with the exact distance.
template <class Store>
void fill_sphere(Store& store) {
  const VolumeGeometry& g = store.geometry();
  for (std::uint32_t z = 0; z < g.bricks_per_side; ++z)
    for (std::uint32_t y = 0; y < g.bricks_per_side; ++y)
      for (std::uint32_t x = 0; x < g.bricks_per_side; ++x) {
        const Eigen::Vector3d centre = g.origin + (Eigen::Vector3d(x, y, z) * 8 + Eigen::Vector3d::Constant(4)) * g.voxel_size;
        if (std::abs((centre - kCentre).norm() - kRadius) > kTruncation + 8 * g.voxel_size) continue;
        TsdfVoxel* b = store.allocate({x, y, z});
        for (int i = 0; i < kBrickVoxels; ++i) {
          const Eigen::Vector3d p =
              g.origin + g.voxel_size * Eigen::Vector3d(x * 8 + (i & 7) + 0.5, y * 8 + ((i >> 3) & 7) + 0.5, z * 8 + (i >> 6) + 0.5);
          const double sdf = (p - kCentre).norm() - kRadius;
          b[i].tsdf = static_cast<float>(std::clamp(sdf / kTruncation, -1.0, 1.0));
          b[i].weight = 1.0f;
          b[i].r = 200;
        }
      }
}

VolumeGeometry sphere_geometry() {
  VolumeGeometry g;
  g.voxel_size = kVoxel;
  g.bricks_per_side = 7;  // 1.12 m
  return g;
}

TEST(SlamGeometry, CaseTableTrianglesUseCrossingEdgesOnly) {
  const auto& table = marching_cubes_table();
  ASSERT_EQ(table.size(), 256u);
  EXPECT_TRUE(table[0].empty());
  EXPECT_TRUE(table[255].empty());
  for (int mask = 1; mask < 255; ++mask) {
    std::set<int> used;
    for (const auto& t : table[mask])
      for (int e : t) {
        const int a = kEdgeCorners[e][0], b = kEdgeCorners[e][1];
        EXPECT_NE((mask >> a) & 1, (mask >> b) & 1) << "mask " << mask << " edge " << e;
        used.insert(e);
      }
    int crossing = 0;
    for (int e = 0; e < 12; ++e) crossing += ((mask >> kEdgeCorners[e][0]) & 1) != ((mask >> kEdgeCorners[e][1]) & 1);
    EXPECT_EQ(static_cast<int>(used.size()), crossing) << "mask " << mask;
    EXPECT_FALSE(table[mask].empty());  // every mixed cube has surface in it
  }
}

TEST(SlamGeometry, SphereMeshIsClosedOrientedAndOnTheSphere) {
  SparseTsdfStore store(sphere_geometry());
  fill_sphere(store);
  const Mesh mesh = marching_cubes(store);
  ASSERT_GT(mesh.triangles.size(), 1000u);
  std::map<std::pair<std::uint32_t, std::uint32_t>, int> directed;
  for (const auto& t : mesh.triangles)
    for (int i = 0; i < 3; ++i) ++directed[{t[i], t[(i + 1) % 3]}];
  for (const auto& [edge, count] : directed) {
    EXPECT_EQ(count, 1) << "directed edge used twice: orientation flips";
    EXPECT_EQ(directed.count({edge.second, edge.first}), 1u) << "an open edge: the mesh has a hole";
  }
  for (const auto& v : mesh.vertices)
    EXPECT_NEAR((Eigen::Vector3d(v[0], v[1], v[2]) - kCentre).norm(), kRadius, 0.1 * kVoxel);
  for (const auto& t : mesh.triangles) {
    const Eigen::Vector3d a(mesh.vertices[t[0]][0], mesh.vertices[t[0]][1], mesh.vertices[t[0]][2]);
    const Eigen::Vector3d b(mesh.vertices[t[1]][0], mesh.vertices[t[1]][1], mesh.vertices[t[1]][2]);
    const Eigen::Vector3d c(mesh.vertices[t[2]][0], mesh.vertices[t[2]][1], mesh.vertices[t[2]][2]);
    EXPECT_GT((b - a).cross(c - a).dot(a - kCentre), 0.0) << "faces point out of the sphere (to positive TSDF)";
  }
}

TEST(SlamGeometry, SurfaceVoxelsHugTheSphereAndDenseAgrees) {
  SparseTsdfStore sparse(sphere_geometry());
  DenseTsdfStore dense(sphere_geometry());
  fill_sphere(sparse);
  fill_sphere(dense);
  const auto s = surface_voxels(sparse);
  const auto d = surface_voxels(dense);
  ASSERT_EQ(s.size(), d.size());
  for (std::size_t i = 0; i < s.size(); ++i) ASSERT_TRUE(s[i].x == d[i].x && s[i].y == d[i].y && s[i].z == d[i].z);
  for (const auto& v : s) {
    const Eigen::Vector3d p = sphere_geometry().origin + kVoxel * Eigen::Vector3d(v.x + 0.5, v.y + 0.5, v.z + 0.5);
    EXPECT_LE(std::abs((p - kCentre).norm() - kRadius), 0.5 * std::sqrt(3.0) * kVoxel + 1e-9);
  }
  // One thin layer: a plane of normal n takes about area * max|n_i| / voxel^2 voxels,
  // about 0.8 of the area over a sphere (a shell on both sides would be 2-3 times that).
  const double area = 4 * M_PI * kRadius * kRadius / (kVoxel * kVoxel);
  EXPECT_GT(static_cast<double>(s.size()), 0.7 * area);
  EXPECT_LT(static_cast<double>(s.size()), 1.2 * area);
  const vola::Tree tree = surface_tree(s, sparse.geometry(), true);
  EXPECT_EQ(tree.voxel_count(), s.size());
  ASSERT_NE(tree.attributes().find("red"), nullptr);
  EXPECT_EQ(tree.attributes().find("red")->get(0), 200.0);
}

TEST(SlamGeometry, RaycastFindsTheSphereSurface) {
  SparseTsdfStore store(sphere_geometry());
  fill_sphere(store);
  FusionParams params;
  params.voxel_size = kVoxel;
  params.truncation = kTruncation;
  params.min_depth = 0.05;
  const Intrinsics k{100, 100, 31.5, 23.5};
  Pose pose = Pose::Identity();  // looking along +z from in front of the sphere
  pose.translation() = kCentre - Eigen::Vector3d(0, 0, 0.45);
  const VertexMap map = raycast(store, k, 64, 48, pose, params);
  int hits = 0;
  for (std::size_t i = 0; i < map.vertices.size(); ++i) {
    if (!map.valid(i)) continue;
    ++hits;
    const Eigen::Vector3d p = map.vertices[i].cast<double>();
    EXPECT_NEAR((p - kCentre).norm(), kRadius, 0.1 * kVoxel);
    EXPECT_GT(map.normals[i].cast<double>().dot((p - kCentre).normalized()), 0.99);
    EXPECT_LT(p.z(), kCentre.z());  // the near side
  }
  EXPECT_GT(hits, 64 * 48 / 3);
  // The centre pixel looks straight at the sphere: its depth is 0.45 - r.
  const std::size_t centre = 24 * 64 + 32;
  ASSERT_TRUE(map.valid(centre));
  EXPECT_NEAR(map.vertices[centre].z() - pose.translation().z(), 0.45 - kRadius, 0.1 * kVoxel + 0.01);
}

TEST(SlamGeometry, PlaneNormalsFaceTheCameraWhateverTheSignOfFy) {
  for (double fy : {480.0, -480.0}) {
    const Intrinsics k{481.2, fy, 15.5, 11.5};
    DepthImage d{32, 24, std::vector<float>(32 * 24, 2.0f)};
    const VertexMap map = vertex_normal_map(d, k);
    for (std::uint32_t y = 0; y + 1 < 24; ++y)
      for (std::uint32_t x = 0; x + 1 < 32; ++x) {
        const std::size_t i = y * 32 + x;
        ASSERT_TRUE(map.valid(i));
        EXPECT_NEAR(map.normals[i].z(), -1.0f, 1e-5f);
        EXPECT_FLOAT_EQ(map.vertices[i].z(), 2.0f);
      }
    const DepthImage f = bilateral_filter(d, 3, 4.5, 0.03, 2);
    for (float v : f.metres) EXPECT_FLOAT_EQ(v, 2.0f);
  }
}

TEST(SlamGeometry, BilateralFilterKeepsDepthEdges) {
  DepthImage d{20, 10, std::vector<float>(200)};
  for (std::uint32_t y = 0; y < 10; ++y)
    for (std::uint32_t x = 0; x < 20; ++x) d.metres[y * 20 + x] = x < 10 ? 1.0f : 3.0f;
  d.metres[5 * 20 + 3] = 0.0f;  // a hole stays a hole
  const DepthImage f = bilateral_filter(d, 3, 4.5, 0.03, 1);
  EXPECT_EQ(f.metres[5 * 20 + 3], 0.0f);
  EXPECT_NEAR(f.metres[5 * 20 + 9], 1.0f, 1e-6);
  EXPECT_NEAR(f.metres[5 * 20 + 10], 3.0f, 1e-6);
}

// The filter's vectorised rows against the definition, in double precision pixel by
// pixel: noisy depth with steps and holes, every pixel within a micrometre.
TEST(SlamGeometry, BilateralFilterMatchesTheDirectSum) {
  const int w = 45, h = 31, r = 3;
  const double sigma_space = 4.5, sigma_depth = 0.03;
  DepthImage d{w, h, std::vector<float>(w * h)};
  std::mt19937 random(7);
  std::normal_distribution<float> noise(0.0f, 0.01f);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x)
      d.metres[y * w + x] = (x + y) % 13 == 0 ? 0.0f : (x < 20 ? 1.2f : 2.5f) + 0.01f * static_cast<float>(y) + noise(random);
  const DepthImage fast = bilateral_filter(d, r, sigma_space, sigma_depth, 2);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      const double centre = d.metres[y * w + x];
      if (centre <= 0.0) {
        EXPECT_EQ(fast.metres[y * w + x], 0.0f);
        continue;
      }
      double sum = 0.0, weights = 0.0;
      for (int dy = -r; dy <= r; ++dy)
        for (int dx = -r; dx <= r; ++dx) {
          if (x + dx < 0 || y + dy < 0 || x + dx >= w || y + dy >= h) continue;
          const double v = d.metres[(y + dy) * w + x + dx];
          if (v <= 0.0) continue;
          const double weight = std::exp(-(dx * dx + dy * dy) / (2 * sigma_space * sigma_space)) *
                                std::exp(-(v - centre) * (v - centre) / (2 * sigma_depth * sigma_depth));
          sum += weight * v;
          weights += weight;
        }
      EXPECT_NEAR(fast.metres[y * w + x], sum / weights, 1e-6) << x << ", " << y;
    }
}

}  // namespace
