#include "vola/mesh/voxelize.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <vector>

#include "vola/builder.hpp"

namespace vola::mesh {

namespace {

// A convex polygon: a triangle clipped by at most four planes has at most 7 vertices.
struct Polygon {
  std::array<Point, 8> points;
  int size = 0;
};

// `out` = the part of `in` on the kept side of the plane p[axis] = bound (p[axis] >=
// bound when keep_above, else <=). Crossing points get p[axis] = bound exactly.
void clip(const Polygon& in, int axis, double bound, bool keep_above, Polygon& out) {
  out.size = 0;
  const auto kept = [&](const Point& p) { return keep_above ? p[axis] >= bound : p[axis] <= bound; };
  for (int i = 0; i < in.size; ++i) {
    const Point& from = in.points[i];
    const Point& to = in.points[i + 1 < in.size ? i + 1 : 0];
    const bool from_kept = kept(from);
    if (from_kept) out.points[out.size++] = from;
    if (from_kept != kept(to)) {
      const double t = (bound - from[axis]) / (to[axis] - from[axis]);
      Point& p = out.points[out.size++];
      for (int a = 0; a < 3; ++a) p[a] = from[a] + t * (to[a] - from[a]);
      p[axis] = bound;
    }
  }
}

// `out` = the part of `in` within [low - slack, high + slack] on `axis` (a negative slack
// shrinks the interval); an infinite bound (a toolkit border voxel) clips nothing.
void clip_slab(const Polygon& in, int axis, double low, double high, double slack, Polygon& out) {
  if (!std::isfinite(low) && !std::isfinite(high)) {
    out = in;
  } else if (!std::isfinite(low)) {
    clip(in, axis, high + slack, false, out);
  } else if (!std::isfinite(high)) {
    clip(in, axis, low - slack, true, out);
  } else {
    Polygon above;
    clip(in, axis, low - slack, true, above);
    clip(above, axis, high + slack, false, out);
  }
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

// Voxelizes one triangle after another into a KeySink.
class TriangleVoxelizer {
 public:
  TriangleVoxelizer(const Quantizer& quantizer, KeySink& sink, VoxelizeReport& report)
      : quantizer_(quantizer), voxel_size_(quantizer.frame().voxel_size), sink_(sink), report_(report) {}

  void add(const TriangleBoxTest& test, const Triangle& triangle) {
    // Clipped polygons carry rounding of the order of an ulp of the coordinates;
    // widening every candidate search by far more than that keeps it a superset of
    // the voxels the exact test accepts. The exact test decides every voxel.
    double magnitude = voxel_size_;
    for (const Point& v : triangle)
      for (double c : v) magnitude = std::max(magnitude, std::abs(c));
    const double slack = 1e-9 * magnitude;

    if (!quantizer_.voxel_range(widened(test.bounds(), slack), first_, last_)) {
      ++report_.outside;
      return;
    }
    load_faces();
    const std::uint64_t candidates =
        std::uint64_t{last_.x - first_.x + 1} * (last_.y - first_.y + 1) * (last_.z - first_.z + 1);
    if (candidates <= kDirectCandidates) {
      for (std::uint32_t z = first_.z; z <= last_.z; ++z)
        for (std::uint32_t y = first_.y; y <= last_.y; ++y)
          for (std::uint32_t x = first_.x; x <= last_.x; ++x) try_voxel(test, {x, y, z});
      return;
    }
    Polygon whole, slab, row, inner_slab, inner_row;
    whole.size = 3;
    for (int i = 0; i < 3; ++i) whole.points[i] = triangle[i];
    for (std::uint32_t z = first_.z; z <= last_.z; ++z) {
      clip_slab(whole, 2, face(2, z), face(2, z + 1), slack, slab);
      if (!slab.size) continue;
      Voxel slab_first, slab_last;
      if (!quantizer_.voxel_range(widened(polygon_bounds(slab), slack), slab_first, slab_last)) continue;
      clip_slab(whole, 2, face(2, z), face(2, z + 1), -slack, inner_slab);
      for (std::uint32_t y = std::max(slab_first.y, first_.y); y <= std::min(slab_last.y, last_.y); ++y) {
        clip_slab(slab, 1, face(1, y), face(1, y + 1), slack, row);
        if (!row.size) continue;
        Voxel row_first, row_last;
        if (!quantizer_.voxel_range(widened(polygon_bounds(row), slack), row_first, row_last)) continue;
        // The triangle's part inside this row of cells shrunk by the rounding (slack) is
        // convex and, rounding and all, inside the row: every x between its lowest and
        // highest is the x of one of its points. A cell whose x range meets that interval
        // by more than the rounding overlaps the triangle; only cells at its ends (and rows
        // the triangle only grazes) need the exact test.
        double sure_low = INFINITY, sure_high = -INFINITY;
        if (inner_slab.size) {
          clip_slab(inner_slab, 1, face(1, y), face(1, y + 1), -slack, inner_row);
          if (inner_row.size) {
            const Box bounds = polygon_bounds(inner_row);
            sure_low = bounds.min[0] + slack, sure_high = bounds.max[0] - slack;
          }
        }
        for (std::uint32_t x = std::max(row_first.x, first_.x); x <= std::min(row_last.x, last_.x); ++x) {
          if (face(0, x) <= sure_high && face(0, x + 1) >= sure_low && sure_low <= sure_high)
            sink_.add({x, y, z});
          else
            try_voxel(test, {x, y, z});
        }
      }
    }
  }

 private:
  // The cell faces of the candidate range, per axis: faces_[a][i] is the lower face of
  // voxel first + i and the upper face of voxel first + i - 1 (Quantizer::cell_box
  // computes shared faces bit for bit, so this is its box, computed once per triangle).
  void load_faces() {
    const std::uint32_t from[3] = {first_.x, first_.y, first_.z}, to[3] = {last_.x, last_.y, last_.z};
    for (int a = 0; a < 3; ++a) {
      faces_[a].clear();
      for (std::uint32_t k = from[a]; k <= to[a]; ++k) faces_[a].push_back(quantizer_.cell_box({k, k, k}).min[a]);
      faces_[a].push_back(quantizer_.cell_box({to[a], to[a], to[a]}).max[a]);
    }
  }
  double face(int axis, std::uint32_t k) const noexcept {
    const std::uint32_t from = axis == 0 ? first_.x : axis == 1 ? first_.y : first_.z;
    return faces_[axis][k - from];
  }
  void try_voxel(const TriangleBoxTest& test, const Voxel& v) {
    const Box cell{{face(0, v.x), face(1, v.y), face(2, v.z)}, {face(0, v.x + 1), face(1, v.y + 1), face(2, v.z + 1)}};
    if (test.overlaps(cell)) sink_.add(v);
  }

  const Quantizer& quantizer_;
  double voxel_size_;
  KeySink& sink_;
  VoxelizeReport& report_;
  Voxel first_, last_;
  std::array<std::vector<double>, 3> faces_;
};

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
  KeySink sink(quantizer.depth());
  TriangleVoxelizer voxelizer(quantizer, sink, r);
  for (const Triangle& t : triangles) {
    const TriangleBoxTest test(t);
    if (!test.usable()) {
      ++r.skipped;
      continue;
    }
    voxelizer.add(test, t);
  }
  std::vector<Key> keys = sink.take();
  r.surface_voxels = keys.size();
  return keys;
}

Tree voxelize(std::span<const Triangle> triangles, const Quantizer& quantizer, const VoxelizeOptions& options,
              VoxelizeReport* report) {
  VoxelizeReport local;
  VoxelizeReport& r = report ? *report : local;
  const std::vector<Key> keys = surface_keys(triangles, quantizer, &r);
  Tree tree = options.solid ? solid_tree(keys, quantizer.depth(), options.max_fill_cells)
                            : build_from_sorted_keys(keys, quantizer.depth());
  if (options.solid) r.enclosed_voxels = tree.voxel_count() - keys.size();
  tree.set_frame(quantizer.frame());
  return tree;
}

}  // namespace vola::mesh
