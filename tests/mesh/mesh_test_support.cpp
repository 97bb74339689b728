#include "mesh_test_support.hpp"

#include <array>
#include <cmath>
#include <cstdlib>

namespace vola_mesh_test {

using vola::Box;
using vola::Point;

vola_test::fs::path data_dir() { return vola_test::golden_dir().parent_path() / "data"; }

XyzSet brute_force_voxels(std::span<const Triangle> triangles, const vola::Quantizer& quantizer) {
  XyzSet out;
  const std::uint32_t side = vola::side_of(quantizer.depth());
  for (const Triangle& t : triangles) {
    const vola::mesh::TriangleBoxTest test(t);
    for (std::uint32_t z = 0; z < side; ++z)
      for (std::uint32_t y = 0; y < side; ++y)
        for (std::uint32_t x = 0; x < side; ++x)
          if (test.overlaps(quantizer.cell_box({x, y, z}))) out.insert({x, y, z});
  }
  return out;
}

namespace {

// Sutherland-Hodgman against one plane: keep p[axis] * sign <= bound * sign.
std::vector<Point> clip_plane(const std::vector<Point>& in, int axis, double bound, double sign) {
  std::vector<Point> out;
  for (std::size_t i = 0; i < in.size(); ++i) {
    const Point& a = in[i];
    const Point& b = in[(i + 1) % in.size()];
    const bool a_in = (a[axis] - bound) * sign <= 0.0, b_in = (b[axis] - bound) * sign <= 0.0;
    if (a_in) out.push_back(a);
    if (a_in != b_in) {
      const double t = (bound - a[axis]) / (b[axis] - a[axis]);
      Point p;
      for (int k = 0; k < 3; ++k) p[k] = a[k] + t * (b[k] - a[k]);
      p[axis] = bound;
      out.push_back(p);
    }
  }
  return out;
}

}  // namespace

bool clipped_triangle_meets_box(const Triangle& triangle, const Box& box, double grow) {
  std::vector<Point> polygon(triangle.begin(), triangle.end());
  for (int axis = 0; axis < 3 && !polygon.empty(); ++axis) {
    if (std::isfinite(box.min[axis])) polygon = clip_plane(polygon, axis, box.min[axis] - grow, -1.0);
    if (!polygon.empty() && std::isfinite(box.max[axis])) polygon = clip_plane(polygon, axis, box.max[axis] + grow, 1.0);
  }
  return !polygon.empty();
}

std::vector<Triangle> random_triangles(std::mt19937_64& rng, const Box& box, const vola::Quantizer& quantizer,
                                       int count) {
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  // A flat axis borrows the box's largest extent (1 for a point).
  double largest = 0.0;
  for (int a = 0; a < 3; ++a) largest = std::max(largest, box.max[a] - box.min[a]);
  Point extent;
  for (int a = 0; a < 3; ++a) extent[a] = box.max[a] > box.min[a] ? box.max[a] - box.min[a] : (largest > 0 ? largest : 1.0);
  const auto in_box = [&] {  // a point in the box grown by 20% per side
    Point p;
    for (int a = 0; a < 3; ++a) p[a] = box.min[a] + (unit(rng) * 1.4 - 0.2) * extent[a];
    return p;
  };
  const double step = quantizer.frame().voxel_size;
  const std::uint32_t side = vola::side_of(quantizer.depth());
  // A face between two voxels on `axis` (never a toolkit border, which is infinite).
  const auto face = [&](int axis) {
    std::uniform_int_distribution<std::uint32_t> pick(0, side >= 2 ? side - 2 : 0);
    vola::Voxel v{pick(rng), pick(rng), pick(rng)};
    const double plane = quantizer.cell_box(v).max[axis];
    // A zero-extent toolkit bbox has no faces between voxels: any plane will do.
    return std::isfinite(plane) ? plane : box.min[axis] + unit(rng) * extent[axis];
  };
  std::vector<Triangle> out;
  for (int i = 0; i < count; ++i) {
    Triangle t{in_box(), in_box(), in_box()};
    switch (i % 11) {
      case 0: break;  // general
      case 1: {       // sliver: almost collinear
        const double s = unit(rng);
        for (int a = 0; a < 3; ++a) t[2][a] = t[0][a] + s * (t[1][a] - t[0][a]) + 1e-9 * step * unit(rng);
        break;
      }
      case 2: t[2] = t[0]; break;  // a segment, one vertex repeated
      case 3: t[1] = t[2] = t[0]; break;  // a point
      case 4:  // tiny, a millionth of a voxel
        for (int k = 1; k < 3; ++k)
          for (int a = 0; a < 3; ++a) t[k][a] = t[0][a] + 1e-6 * step * unit(rng);
        break;
      case 5:  // huge: far past the grid on every side
        for (auto& v : t)
          for (int a = 0; a < 3; ++a) v[a] = box.min[a] + (unit(rng) - 0.5) * 1e4 * extent[a];
        break;
      case 6: case 7: case 8: {  // lying exactly in a cell face plane of x, y or z
        const int axis = i % 11 - 6;
        const double plane = face(axis);
        for (auto& v : t) v[axis] = plane;
        break;
      }
      case 9: {  // a vertex exactly on a cell corner, the others anywhere
        std::uniform_int_distribution<std::uint32_t> pick(0, side >= 2 ? side - 2 : 0);
        const Point corner = quantizer.cell_box({pick(rng), pick(rng), pick(rng)}).max;
        if (std::isfinite(corner[0])) t[0] = corner;
        break;
      }
      default: {  // an edge exactly along a cell edge line (two coordinates on faces)
        const double p = face(0), q = face(1);
        t[0][0] = t[1][0] = p;
        t[0][1] = t[1][1] = q;
        break;
      }
    }
    out.push_back(t);
  }
  return out;
}

std::vector<Triangle> box_mesh(const Box& b) {
  const auto corner = [&](int i) {
    return Point{i & 1 ? b.max[0] : b.min[0], i & 2 ? b.max[1] : b.min[1], i & 4 ? b.max[2] : b.min[2]};
  };
  // Two triangles per face, counter-clockwise seen from outside.
  const int faces[6][4] = {{0, 2, 3, 1}, {4, 5, 7, 6}, {0, 1, 5, 4}, {2, 6, 7, 3}, {0, 4, 6, 2}, {1, 3, 7, 5}};
  std::vector<Triangle> out;
  for (const auto& f : faces) {
    out.push_back({corner(f[0]), corner(f[1]), corner(f[2])});
    out.push_back({corner(f[0]), corner(f[2]), corner(f[3])});
  }
  return out;
}

std::vector<Triangle> sphere_mesh(const Point& centre, double radius, int subdivisions) {
  const double g = (1.0 + std::sqrt(5.0)) / 2.0;
  std::vector<Point> v = {{-1, g, 0}, {1, g, 0}, {-1, -g, 0}, {1, -g, 0}, {0, -1, g}, {0, 1, g},
                          {0, -1, -g}, {0, 1, -g}, {g, 0, -1}, {g, 0, 1}, {-g, 0, -1}, {-g, 0, 1}};
  std::vector<std::array<int, 3>> f = {{0, 11, 5}, {0, 5, 1},  {0, 1, 7},   {0, 7, 10}, {0, 10, 11},
                                       {1, 5, 9},  {5, 11, 4}, {11, 10, 2}, {10, 7, 6}, {7, 1, 8},
                                       {3, 9, 4},  {3, 4, 2},  {3, 2, 6},   {3, 6, 8},  {3, 8, 9},
                                       {4, 9, 5},  {2, 4, 11}, {6, 2, 10},  {8, 6, 7},  {9, 8, 1}};
  const auto on_sphere = [](Point p) {
    const double n = std::sqrt(p[0] * p[0] + p[1] * p[1] + p[2] * p[2]);
    return Point{p[0] / n, p[1] / n, p[2] / n};
  };
  for (auto& p : v) p = on_sphere(p);
  for (int s = 0; s < subdivisions; ++s) {
    std::vector<std::array<int, 3>> next;
    const auto middle = [&](int a, int b) {
      v.push_back(on_sphere({(v[a][0] + v[b][0]) / 2, (v[a][1] + v[b][1]) / 2, (v[a][2] + v[b][2]) / 2}));
      return static_cast<int>(v.size() - 1);
    };
    for (const auto& t : f) {
      const int ab = middle(t[0], t[1]), bc = middle(t[1], t[2]), ca = middle(t[2], t[0]);
      next.push_back({t[0], ab, ca});
      next.push_back({t[1], bc, ab});
      next.push_back({t[2], ca, bc});
      next.push_back({ab, bc, ca});
    }
    f = std::move(next);
  }
  std::vector<Triangle> out;
  const auto place = [&](const Point& p) {
    return Point{centre[0] + radius * p[0], centre[1] + radius * p[1], centre[2] + radius * p[2]};
  };
  for (const auto& t : f) out.push_back({place(v[t[0]]), place(v[t[1]]), place(v[t[2]])});
  return out;
}

XyzSet key_set(std::span<const vola::Key> keys) {
  XyzSet out;
  for (vola::Key k : keys) out.insert(vola_test::to_xyz(vola::decode(k)));
  return out;
}

}  // namespace vola_mesh_test
