#include "vola/slam/map_export.hpp"

#include <algorithm>
#include <bit>
#include <tuple>
#include <cmath>
#include <cstring>
#include <fstream>
#include <unordered_map>

#include "tsdf_reader.hpp"
#include "vola/builder.hpp"
#include "vola/error.hpp"
#include "vola/output_stream.hpp"

namespace vola::slam {

// Corner c of a cube sits at offset (c & 1, (c >> 1) & 1, c >> 2).
const std::array<std::array<int, 2>, 12> kEdgeCorners = {{
    {0, 1}, {2, 3}, {4, 5}, {6, 7},  // along x
    {0, 2}, {1, 3}, {4, 6}, {5, 7},  // along y
    {0, 4}, {1, 5}, {2, 6}, {3, 7},  // along z
}};

namespace {

int edge_between(int a, int b) {
  for (int e = 0; e < 12; ++e)
    if ((kEdgeCorners[e][0] == a && kEdgeCorners[e][1] == b) || (kEdgeCorners[e][0] == b && kEdgeCorners[e][1] == a))
      return e;
  return -1;
}

std::vector<std::vector<std::array<int, 3>>> derive_table() {
  // The six faces, corners in cyclic order.
  std::vector<std::array<int, 4>> faces;
  for (int axis = 0; axis < 3; ++axis)
    for (int side = 0; side < 2; ++side) {
      const int b = (axis + 1) % 3, c = (axis + 2) % 3;
      auto corner = [&](int ub, int uc) { return side << axis | ub << b | uc << c; };
      faces.push_back({corner(0, 0), corner(1, 0), corner(1, 1), corner(0, 1)});
    }
  std::vector<std::vector<std::array<int, 3>>> table(256);
  for (int mask = 0; mask < 256; ++mask) {
    auto inside = [&](int corner) { return ((mask >> corner) & 1) != 0; };
    std::array<std::vector<int>, 12> links;  // each crossing edge links to two others
    for (const auto& q : faces) {
      std::array<int, 4> e{};
      for (int i = 0; i < 4; ++i) e[i] = edge_between(q[i], q[(i + 1) % 4]);
      std::vector<int> crossing;
      for (int i = 0; i < 4; ++i)
        if (inside(q[i]) != inside(q[(i + 1) % 4])) crossing.push_back(i);
      auto link = [&](int a, int b) {
        links[e[a]].push_back(e[b]);
        links[e[b]].push_back(e[a]);
      };
      if (crossing.size() == 2) {
        link(crossing[0], crossing[1]);
      } else if (crossing.size() == 4) {
        for (int i = 0; i < 4; ++i)  // cut off each inside corner q[i]: edges i-1 and i
          if (inside(q[i])) link((i + 3) % 4, i);
      }
    }
    std::array<bool, 12> used{};
    for (int start = 0; start < 12; ++start) {
      if (used[start] || links[start].empty()) continue;
      std::vector<int> loop{start};
      used[start] = true;
      int previous = -1, current = start;
      for (;;) {
        const int next = links[current][0] != previous ? links[current][0] : links[current][1];
        if (next == start) break;
        loop.push_back(next);
        used[next] = true;
        previous = current;
        current = next;
      }
      for (std::size_t i = 1; i + 1 < loop.size(); ++i) table[mask].push_back({loop[0], loop[i], loop[i + 1]});
    }
  }
  return table;
}

}  // namespace

const std::vector<std::vector<std::array<int, 3>>>& marching_cubes_table() {
  static const auto table = derive_table();
  return table;
}

template <class Store>
std::vector<SurfaceVoxel> surface_voxels(const Store& store) {
  std::vector<SurfaceVoxel> out;
  TsdfReader<Store> reader(store);
  store.for_each_brick([&](const BrickCoord& c, const TsdfVoxel* voxels) {
    for (int i = 0; i < kBrickVoxels; ++i) {
      const TsdfVoxel& v = voxels[i];
      if (!(v.weight > 0.0f)) continue;
      const std::int64_t x = c.x * 8 + (i & 7), y = c.y * 8 + ((i >> 3) & 7), z = c.z * 8 + (i >> 6);
      bool surface = false;
      for (int n = 0; n < 6 && !surface; ++n) {
        const int axis = n >> 1, sign = (n & 1) ? 1 : -1;
        const TsdfVoxel* w = reader.voxel(x + (axis == 0) * sign, y + (axis == 1) * sign, z + (axis == 2) * sign);
        surface = w && ((v.tsdf < 0.0f) != (w->tsdf < 0.0f)) && std::abs(v.tsdf) <= std::abs(w->tsdf) &&
                  std::abs(v.tsdf) < 1.0f;
      }
      if (surface)
        out.push_back({static_cast<std::uint32_t>(x), static_cast<std::uint32_t>(y), static_cast<std::uint32_t>(z), v.r, v.g,
                       v.b});
    }
  });
  std::sort(out.begin(), out.end(), [](const SurfaceVoxel& a, const SurfaceVoxel& b) {
    return std::tie(a.z, a.y, a.x) < std::tie(b.z, b.y, b.x);
  });
  return out;
}

Tree surface_tree(const std::vector<SurfaceVoxel>& voxels, const VolumeGeometry& geometry, bool with_colour) {
  std::uint32_t lo[3] = {~0u, ~0u, ~0u}, hi[3] = {0, 0, 0};
  for (const auto& v : voxels) {
    const std::uint32_t p[3] = {v.x, v.y, v.z};
    for (int a = 0; a < 3; ++a) {
      lo[a] = std::min(lo[a], p[a]);
      hi[a] = std::max(hi[a], p[a]);
    }
  }
  if (voxels.empty()) lo[0] = lo[1] = lo[2] = 0;
  const double vs = geometry.voxel_size;
  PointCloud cloud;
  cloud.xyz.reserve(voxels.size() * 3);
  PointAttribute red{"red", ValueType::u8, Reduction::mean, {}}, green{"green", ValueType::u8, Reduction::mean, {}},
      blue{"blue", ValueType::u8, Reduction::mean, {}};
  for (const auto& v : voxels) {
    const std::uint32_t p[3] = {v.x, v.y, v.z};
    for (int a = 0; a < 3; ++a) cloud.xyz.push_back(geometry.origin[a] + (p[a] + 0.5) * vs);
    if (with_colour) {
      red.values.push_back(v.r);
      green.values.push_back(v.g);
      blue.values.push_back(v.b);
    }
  }
  if (with_colour) cloud.attributes = {red, green, blue};
  BuildOptions options;
  options.quantization = Quantization::grid;
  options.voxel_size = vs;
  options.origin = Point{geometry.origin.x() + lo[0] * vs, geometry.origin.y() + lo[1] * vs, geometry.origin.z() + lo[2] * vs};
  const std::uint32_t extent = std::max({hi[0] - lo[0], hi[1] - lo[1], hi[2] - lo[2]}) + 1;
  options.depth = voxels.empty() ? 1 : depth_for_extent(extent * vs, vs);
  return build(cloud, options);
}

template <class Store>
Mesh marching_cubes(const Store& store) {
  const auto& table = marching_cubes_table();
  const VolumeGeometry& geometry = store.geometry();
  const double vs = geometry.voxel_size;
  const std::uint64_t side = geometry.voxels_per_side();
  Mesh mesh;
  std::unordered_map<std::uint64_t, std::uint32_t> shared;  // (lower corner, axis) -> vertex
  TsdfReader<Store> reader(store);
  store.for_each_brick([&](const BrickCoord& c, const TsdfVoxel*) {
    for (int i = 0; i < kBrickVoxels; ++i) {
      const std::int64_t x = c.x * 8 + (i & 7), y = c.y * 8 + ((i >> 3) & 7), z = c.z * 8 + (i >> 6);
      const TsdfVoxel* corner[8];
      int mask = 0;
      bool usable = true;
      for (int k = 0; k < 8 && usable; ++k) {
        corner[k] = reader.voxel(x + (k & 1), y + ((k >> 1) & 1), z + (k >> 2));
        usable = corner[k] && std::abs(corner[k]->tsdf) < 1.0f;
        if (usable && corner[k]->tsdf < 0.0f) mask |= 1 << k;
      }
      if (!usable || mask == 0 || mask == 255) continue;
      auto vertex_on = [&](int e) -> std::uint32_t {
        const int a = kEdgeCorners[e][0], b = kEdgeCorners[e][1];
        const int axis = e / 4;
        const std::uint64_t key =
            (((x + (a & 1)) * side + (y + ((a >> 1) & 1))) * side + static_cast<std::uint64_t>(z + (a >> 2))) * 3 + axis;
        const auto found = shared.find(key);
        if (found != shared.end()) return found->second;
        const double fa = corner[a]->tsdf, fb = corner[b]->tsdf;
        const double t = fa / (fa - fb);
        std::array<float, 3> p{};
        for (int d = 0; d < 3; ++d) {
          const double ca = static_cast<double>((d == 0 ? x : d == 1 ? y : z) + ((a >> d) & 1)) + 0.5;
          p[d] = static_cast<float>(geometry.origin[d] + (ca + (d == axis ? t : 0.0)) * vs);
        }
        const TsdfVoxel* near = t < 0.5 ? corner[a] : corner[b];
        const auto index = static_cast<std::uint32_t>(mesh.vertices.size());
        mesh.vertices.push_back(p);
        mesh.colours.push_back({near->r, near->g, near->b});
        shared.emplace(key, index);
        return index;
      };
      for (const auto& tri : table[mask]) {
        std::array<std::uint32_t, 3> t{vertex_on(tri[0]), vertex_on(tri[1]), vertex_on(tri[2])};
        // Outward (towards positive TSDF) = from each crossed edge's inside corner to
        // its outside one; wind the triangle to face that way.
        Eigen::Vector3d outward = Eigen::Vector3d::Zero();
        for (int e : tri) outward[e / 4] += ((mask >> kEdgeCorners[e][0]) & 1) ? 1.0 : -1.0;  // corner 0 inside: towards corner 1
        const auto& p0 = mesh.vertices[t[0]];
        const auto& p1 = mesh.vertices[t[1]];
        const auto& p2 = mesh.vertices[t[2]];
        const Eigen::Vector3d e1(p1[0] - p0[0], p1[1] - p0[1], p1[2] - p0[2]);
        const Eigen::Vector3d e2(p2[0] - p0[0], p2[1] - p0[1], p2[2] - p0[2]);
        if (e1.cross(e2).dot(outward) < 0.0) std::swap(t[1], t[2]);
        mesh.triangles.push_back(t);
      }
    }
  });
  return mesh;
}

void write_ply(const std::string& path, const Mesh& mesh, bool with_colour, const Eigen::Vector3d& origin) {
  const bool shifted = origin != Eigen::Vector3d::Zero();
  const char* type = shifted ? "double" : "float";
  OutputStream out(path);
  out << "ply\nformat binary_little_endian 1.0\ncomment vola fuse: marching cubes of the TSDF\nelement vertex "
      << mesh.vertices.size() << "\nproperty " << type << " x\nproperty " << type << " y\nproperty " << type << " z\n";
  if (with_colour) out << "property uchar red\nproperty uchar green\nproperty uchar blue\n";
  out << "element face " << mesh.triangles.size() << "\nproperty list uchar uint vertex_indices\nend_header\n";
  static_assert(std::endian::native == std::endian::little, "PLY writer assumes a little-endian host");
  for (std::size_t i = 0; i < mesh.vertices.size(); ++i) {
    if (shifted) {
      const std::array<double, 3> world{origin[0] + mesh.vertices[i][0], origin[1] + mesh.vertices[i][1],
                                        origin[2] + mesh.vertices[i][2]};
      out.write(reinterpret_cast<const char*>(world.data()), 24);
    } else {
      out.write(reinterpret_cast<const char*>(mesh.vertices[i].data()), 12);
    }
    if (with_colour) out.write(reinterpret_cast<const char*>(mesh.colours[i].data()), 3);
  }
  for (const auto& t : mesh.triangles) {
    const char three = 3;
    out.write(&three, 1);
    out.write(reinterpret_cast<const char*>(t.data()), 12);
  }
  out.commit();
}

MapMemory map_memory(const SparseTsdfStore& store) {
  MapMemory m;
  m.sparse_bytes = store.memory_bytes();
  m.bricks = store.brick_count();
  std::uint32_t lo[3] = {~0u, ~0u, ~0u}, hi[3] = {0, 0, 0};
  store.for_each_brick([&](const BrickCoord& c, const TsdfVoxel*) {
    const std::uint32_t p[3] = {c.x, c.y, c.z};
    for (int a = 0; a < 3; ++a) {
      lo[a] = std::min(lo[a], p[a]);
      hi[a] = std::max(hi[a], p[a]);
    }
  });
  if (m.bricks == 0) return m;
  std::size_t voxels = 1;
  for (int a = 0; a < 3; ++a) {
    m.extent_voxels[a] = (hi[a] - lo[a] + 1) * kBrickSide;
    voxels *= m.extent_voxels[a];
  }
  m.dense_bytes = voxels * sizeof(TsdfVoxel);
  return m;
}

template std::vector<SurfaceVoxel> surface_voxels(const SparseTsdfStore&);
template std::vector<SurfaceVoxel> surface_voxels(const DenseTsdfStore&);
template Mesh marching_cubes(const SparseTsdfStore&);
template Mesh marching_cubes(const DenseTsdfStore&);

}  // namespace vola::slam
