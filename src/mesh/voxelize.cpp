#include "vola/mesh/voxelize.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>

#include "vola/builder.hpp"

namespace vola::mesh {

namespace {

// A convex polygon: a triangle clipped by at most four planes has at most 7 vertices.
struct Polygon {
  std::array<Point, 8> points;
  int size = 0;
};

// The part of `in` on the kept side of the plane p[axis] = bound (p[axis] >= bound when
// keep_above, else <=). Crossing points get p[axis] = bound exactly.
Polygon clip(const Polygon& in, int axis, double bound, bool keep_above) {
  Polygon out;
  const auto kept = [&](const Point& p) { return keep_above ? p[axis] >= bound : p[axis] <= bound; };
  for (int i = 0; i < in.size; ++i) {
    const Point& from = in.points[i];
    const Point& to = in.points[(i + 1) % in.size];
    const bool from_kept = kept(from);
    if (from_kept) out.points[out.size++] = from;
    if (from_kept != kept(to)) {
      const double t = (bound - from[axis]) / (to[axis] - from[axis]);
      Point p;
      for (int a = 0; a < 3; ++a) p[a] = from[a] + t * (to[a] - from[a]);
      p[axis] = bound;
      out.points[out.size++] = p;
    }
  }
  return out;
}

// The part of `in` within [low - slack, high + slack] on `axis`; an infinite bound
// (a toolkit border voxel) clips nothing.
Polygon clip_slab(const Polygon& in, int axis, double low, double high, double slack) {
  Polygon out = in;
  if (std::isfinite(low)) out = clip(out, axis, low - slack, true);
  if (out.size && std::isfinite(high)) out = clip(out, axis, high + slack, false);
  return out;
}

Box polygon_bounds(const Polygon& polygon) {
  Box box{polygon.points[0], polygon.points[0]};
  for (int i = 1; i < polygon.size; ++i)
    for (int a = 0; a < 3; ++a) {
      box.min[a] = std::min(box.min[a], polygon.points[i][a]);
      box.max[a] = std::max(box.max[a], polygon.points[i][a]);
    }
  return box;
}

Box widened(Box box, double slack) {
  for (int a = 0; a < 3; ++a) {
    box.min[a] -= slack;
    box.max[a] += slack;
  }
  return box;
}

// Collects the keys of one triangle after another, sorting out duplicates whenever
// the list has doubled so that memory follows the surface, not the triangle count.
class KeySink {
 public:
  explicit KeySink(int depth) : depth_(depth) {}
  void add(const Voxel& v) {
    keys_.push_back(encode(v));
    if (keys_.size() >= next_compaction_) {
      compact();
      next_compaction_ = std::max(kFirstCompaction, 2 * keys_.size());
    }
  }
  std::vector<Key> take() {
    compact();
    return std::move(keys_);
  }

 private:
  static constexpr std::size_t kFirstCompaction = std::size_t{1} << 24;
  void compact() {
    radix_sort(keys_, nullptr, 6 * depth_);
    keys_.erase(std::unique(keys_.begin(), keys_.end()), keys_.end());
  }
  int depth_;
  std::vector<Key> keys_;
  std::size_t next_compaction_ = kFirstCompaction;
};

// Candidates up to this many are tested directly; larger triangles go slab by slab.
constexpr std::uint64_t kDirectCandidates = 64;

void voxelize_triangle(const TriangleBoxTest& test, const Triangle& triangle, const Quantizer& quantizer,
                       double voxel_size, KeySink& sink, VoxelizeReport& report) {
  // Clipped polygons carry rounding of the order of an ulp of the coordinates; widening
  // every candidate search by far more than that keeps it a superset of the voxels the
  // exact test accepts. The exact test decides every voxel.
  double magnitude = voxel_size;
  for (const Point& v : triangle)
    for (double c : v) magnitude = std::max(magnitude, std::abs(c));
  const double slack = 1e-9 * magnitude;

  Voxel first, last;
  if (!quantizer.voxel_range(widened(test.bounds(), slack), first, last)) {
    ++report.outside;
    return;
  }
  const auto try_voxel = [&](const Voxel& v) {
    if (test.overlaps(quantizer.cell_box(v))) sink.add(v);
  };
  const std::uint64_t candidates = std::uint64_t{last.x - first.x + 1} * (last.y - first.y + 1) * (last.z - first.z + 1);
  if (candidates <= kDirectCandidates) {
    for (std::uint32_t z = first.z; z <= last.z; ++z)
      for (std::uint32_t y = first.y; y <= last.y; ++y)
        for (std::uint32_t x = first.x; x <= last.x; ++x) try_voxel({x, y, z});
    return;
  }
  Polygon whole;
  whole.size = 3;
  for (int i = 0; i < 3; ++i) whole.points[i] = triangle[i];
  for (std::uint32_t z = first.z; z <= last.z; ++z) {
    const Box slab_cell = quantizer.cell_box({first.x, first.y, z});
    const Polygon slab = clip_slab(whole, 2, slab_cell.min[2], slab_cell.max[2], slack);
    if (!slab.size) continue;
    Voxel slab_first, slab_last;
    if (!quantizer.voxel_range(widened(polygon_bounds(slab), slack), slab_first, slab_last)) continue;
    for (std::uint32_t y = std::max(slab_first.y, first.y); y <= std::min(slab_last.y, last.y); ++y) {
      const Box row_cell = quantizer.cell_box({first.x, y, z});
      const Polygon row = clip_slab(slab, 1, row_cell.min[1], row_cell.max[1], slack);
      if (!row.size) continue;
      Voxel row_first, row_last;
      if (!quantizer.voxel_range(widened(polygon_bounds(row), slack), row_first, row_last)) continue;
      for (std::uint32_t x = std::max(row_first.x, first.x); x <= std::min(row_last.x, last.x); ++x)
        try_voxel({x, y, z});
    }
  }
}

}  // namespace

Box triangle_bounds(std::span<const Triangle> triangles) noexcept {
  const double inf = std::numeric_limits<double>::infinity();
  Box box{{inf, inf, inf}, {-inf, -inf, -inf}};
  bool any = false;
  for (const Triangle& t : triangles) {
    const TriangleBoxTest test(t);
    if (!test.usable()) continue;
    any = true;
    for (int a = 0; a < 3; ++a) {
      box.min[a] = std::min(box.min[a], test.bounds().min[a]);
      box.max[a] = std::max(box.max[a], test.bounds().max[a]);
    }
  }
  return any ? box : Box{};
}

std::vector<Key> surface_keys(std::span<const Triangle> triangles, const Quantizer& quantizer,
                              VoxelizeReport* report) {
  VoxelizeReport local;
  VoxelizeReport& r = report ? *report : local;
  r.triangles += triangles.size();
  const double voxel_size = quantizer.frame().voxel_size;
  KeySink sink(quantizer.depth());
  for (const Triangle& t : triangles) {
    const TriangleBoxTest test(t);
    if (!test.usable()) {
      ++r.skipped;
      continue;
    }
    voxelize_triangle(test, t, quantizer, voxel_size, sink, r);
  }
  std::vector<Key> keys = sink.take();
  r.surface_voxels = keys.size();
  return keys;
}

Tree voxelize(std::span<const Triangle> triangles, const Quantizer& quantizer, const VoxelizeOptions& options,
              VoxelizeReport* report) {
  VoxelizeReport local;
  VoxelizeReport& r = report ? *report : local;
  std::vector<Key> keys = surface_keys(triangles, quantizer, &r);
  Tree tree;
  if (options.solid) {
    std::vector<Key> inside = enclosed_keys(keys, options.max_fill_cells);
    r.enclosed_voxels = inside.size();
    keys.insert(keys.end(), inside.begin(), inside.end());
    tree = build_from_keys(std::move(keys), quantizer.depth());
  } else {
    tree = build_from_sorted_keys(keys, quantizer.depth());
  }
  tree.set_frame(quantizer.frame());
  return tree;
}

}  // namespace vola::mesh
