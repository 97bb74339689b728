// Image sources over surface patches: a breadth-first search of mirrored sources, each
// checked by tracing its path back from the listener (room_response.hpp).
#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>

#include "vola/audio/room_response.hpp"
#include "vola/parallel.hpp"
#include "vola/raycast/world.hpp"

namespace vola::audio {

namespace {

double length(const Point& a, const Point& b) noexcept {
  const double dx = a[0] - b[0], dy = a[1] - b[1], dz = a[2] - b[2];
  return std::sqrt(dx * dx + dy * dy + dz * dz);
}

// A node of the search: the image after reflecting in `patch`, child of `parent`.
struct Node {
  std::uint32_t parent = UINT32_MAX;  // in the previous order's nodes; none at order 1
  std::uint32_t patch = 0;
  Point image{};
};

// Reflection points within this many voxels of a leg's end are the patch's own voxels:
// a fitted plane runs up to half a voxel inside a staircase of faces, and a ray leaving
// it must not count its own surface as an obstacle.
constexpr double kSurfaceSkip = 1.5;

// The fraction of a segment left out at its far end.
constexpr double kShortOfEnd = 1e-9;

// Is the segment from a to b free of occupied voxels? Ends on a patch skip kSurfaceSkip
// voxels next to them.
bool clear(const raycast::RayCaster& caster, const Point& a, bool a_on_surface, const Point& b, bool b_on_surface) {
  const double len = length(a, b);
  const double skip_a = a_on_surface ? kSurfaceSkip : 0.0, skip_b = b_on_surface ? kSurfaceSkip : 0.0;
  if (len <= skip_a + skip_b) return true;
  const Point u{(b[0] - a[0]) / len, (b[1] - a[1]) / len, (b[2] - a[2]) / len};
  const Point from{a[0] + skip_a * u[0], a[1] + skip_a * u[1], a[2] + skip_a * u[2]};
  // Up to just short of b: a listener standing on a face (a table top, the floor) is not
  // hidden by the voxel it stands on.
  return !caster.cast(raycast::Ray{from, u, (len - skip_a - skip_b) * (1.0 - kShortOfEnd)}).has_value();
}

// Does point q of patch p's plane lie on the patch: is the voxel just behind it (or a
// 6-neighbour, for points on a staircase's riser) one of the patch's?
bool on_patch(const SurfacePatches& patches, std::uint32_t p, const Point& q, std::uint32_t side) {
  const SurfacePatch& patch = patches.patches()[p];
  const double behind[3] = {q[0] - 0.5 * patch.normal[0], q[1] - 0.5 * patch.normal[1], q[2] - 0.5 * patch.normal[2]};
  std::int64_t v[3];
  for (int a = 0; a < 3; ++a) {
    if (!(behind[a] >= 0.0 && behind[a] < side)) return false;
    v[a] = static_cast<std::int64_t>(behind[a]);
  }
  auto in = [&](std::int64_t x, std::int64_t y, std::int64_t z) {
    return x >= 0 && y >= 0 && z >= 0 && x < side && y < side && z < side &&
           patches.voxel_in_patch(Voxel{static_cast<std::uint32_t>(x), static_cast<std::uint32_t>(y), static_cast<std::uint32_t>(z)}, p);
  };
  if (in(v[0], v[1], v[2])) return true;
  static constexpr int kStep[6][3] = {{-1, 0, 0}, {1, 0, 0}, {0, -1, 0}, {0, 1, 0}, {0, 0, -1}, {0, 0, 1}};
  for (const auto& s : kStep)
    if (in(v[0] + s[0], v[1] + s[1], v[2] + s[2])) return true;
  return false;
}

// Can no point of the patch's box be in front of plane `of`? Then no path goes from `of`
// to the patch.
bool wholly_behind(const SurfacePatch& patch, const SurfacePatch& of) {
  for (int corner = 0; corner < 8; ++corner) {
    const Point c{(corner & 1) ? patch.hi[0] : patch.lo[0], (corner & 2) ? patch.hi[1] : patch.lo[1],
                  (corner & 4) ? patch.hi[2] : patch.lo[2]};
    if (plane_distance(of, c) > 1e-9) return false;
  }
  return true;
}

// One image's reflections, last first: the patches and the images after each.
struct Trace {
  std::vector<std::uint32_t> sequence;
  std::vector<Point> images;
  std::vector<Point> points;  // where each reflects, last first
};

// Is q within `margin` voxels of the patch's box of face centres? Cheaper than on_patch,
// and most candidate images of a cluttered scene fail it.
bool near_box(const SurfacePatch& patch, const Point& q, double margin) {
  for (int a = 0; a < 3; ++a)
    if (q[a] < patch.lo[a] - margin || q[a] > patch.hi[a] + margin) return false;
  return true;
}

// Can a path from image i through (a point of) patch `through` go on to patch `to`: does
// the beam from i through the box of `through` (grown by kBoxMargin) meet the box of `to`
// (grown too)? A path's reflection point on a patch is within kBoxMargin of its box
// (path_of checks near_box), and the next one lies on the ray from i through it, past
// it: i + t (y - i), t >= 1, y in the box. At a fixed t that is a box too, so per axis
// the t for which it overlaps `to` is an interval: the beam meets `to` when the intervals
// and [1, inf) have a point in common. Only a box is tested, so it may say yes for a patch
// the path cannot reach, never no for one it can.
constexpr double kBoxMargin = 1.5;
bool beam_meets(const Point& i, const SurfacePatch& through, const SurfacePatch& to) {
  double t_lo = 1.0, t_hi = std::numeric_limits<double>::infinity();
  // c t <= r
  auto at_most = [&](double c, double r) {
    if (c > 0.0) t_hi = std::min(t_hi, r / c);
    else if (c < 0.0) t_lo = std::max(t_lo, r / c);
    else if (r < 0.0) t_hi = -1.0;
  };
  for (int a = 0; a < 3; ++a) {
    const double lo = through.lo[a] - kBoxMargin - i[a], hi = through.hi[a] + kBoxMargin - i[a];
    // The beam's lower end at t is i + t lo, at most the far side of `to`; its upper end
    // i + t hi at least the near side.
    at_most(lo, to.hi[a] + kBoxMargin - i[a] + 1e-9);
    at_most(-hi, -(to.lo[a] - kBoxMargin - i[a]) + 1e-9);
  }
  return t_lo <= t_hi * (1.0 + 1e-12) + 1e-12;
}

// Does the line from the listener l to image i cross the patch's plane, in front of it,
// within kBoxMargin of its box? (The first test of path_of, for the last reflection.)
bool last_leg_meets(const SurfacePatch& patch, const Point& i, const Point& l) {
  const double dt = plane_distance(patch, l), di = plane_distance(patch, i);
  if (!(dt > 0.0 && di < 0.0)) return false;
  const double u = dt / (dt - di);
  return near_box(patch, Point{l[0] + u * (i[0] - l[0]), l[1] + u * (i[1] - l[1]), l[2] + u * (i[2] - l[2])}, kBoxMargin);
}

// The path an image stands for, traced back from the listener l to the source s (grid
// coordinates), or false when it does not exist (room_response.hpp).
bool path_of(const Room& room, const Point& s, const Point& l, const RoomOptions& o, Trace& t, ImageSource& out) {
  const AcousticScene& scene = room.scene();
  const Frame& frame = scene.frame();
  const double voxel = frame.voxel_size;
  const std::uint32_t side = scene.tree().side();
  const auto& patches = room.patches().patches();
  t.points.clear();
  Point target = l;
  for (std::size_t k = 0; k < t.sequence.size(); ++k) {
    const SurfacePatch& patch = patches[t.sequence[k]];
    const double dt = plane_distance(patch, target), di = plane_distance(patch, t.images[k]);
    if (!(dt > 0.0 && di < 0.0)) return false;
    const double u = dt / (dt - di);
    const Point q{target[0] + u * (t.images[k][0] - target[0]), target[1] + u * (t.images[k][1] - target[1]),
                  target[2] + u * (t.images[k][2] - target[2])};
    if (!near_box(patch, q, kBoxMargin) || !on_patch(room.patches(), t.sequence[k], q, side)) return false;
    if (o.occlusion && !clear(scene.caster(), q, true, target, k > 0)) return false;
    t.points.push_back(q);
    target = q;
  }
  if (o.occlusion && !clear(scene.caster(), s, false, target, true)) return false;
  const double path = length(t.images[0], l) * voxel;
  out.path = path;
  out.delay = path / o.speed_of_sound;
  out.image = raycast::grid_to_world(frame, t.images[0]);
  out.patches.clear();
  out.points.clear();
  const double wavelength = o.speed_of_sound / 1000.0;  // m, at 1 kHz (Fresnel zone)
  const double scatter = std::sqrt(1.0 - o.scattering);
  double gain = 1.0;
  Bands band_gain;
  band_gain.fill(1.0);
  // Source side first: r_in runs from the source to the reflection point along the path.
  double r_in = 0.0;
  Point previous = s;
  for (std::size_t k = t.sequence.size(); k-- > 0;) {
    const std::uint32_t p = t.sequence[k];
    r_in += length(previous, t.points[k]) * voxel;
    previous = t.points[k];
    const double r_out = path - r_in;
    const double fresnel = std::numbers::pi * wavelength * r_in * r_out / path;
    const double area = patches[p].area * voxel * voxel;
    const double geometric = scatter * std::sqrt(std::min(1.0, area / fresnel));
    gain *= room.reflection()[p] * geometric;
    for (std::size_t b = 0; b < band_gain.size(); ++b) band_gain[b] *= room.band_reflection()[p][b] * geometric;
    out.patches.push_back(p);
    out.points.push_back(raycast::grid_to_world(frame, t.points[k]));
  }
  const Bands air = air_attenuation(o);
  double mean_square = 0.0;
  for (std::size_t b = 0; b < band_gain.size(); ++b) {
    out.bands[b] = band_gain[b] * std::pow(10.0, -air[b] * path / 20.0) / path;
    mean_square += out.bands[b] * out.bands[b];
  }
  // Broadband materials without air: the bands are equal, and the amplitude is exactly theirs.
  out.amplitude = room.per_band() || o.air ? std::sqrt(mean_square / static_cast<double>(band_gain.size())) : gain / path;
  return out.amplitude > 0.0;
}

}  // namespace

ImageSearch image_sources(const Room& room, const Point& source, const Point& listener, const RoomOptions& o) {
  o.check();
  const Frame& frame = room.scene().frame();
  const auto& patches = room.patches().patches();
  const Point s = raycast::world_to_grid(frame, source), l = raycast::world_to_grid(frame, listener);

  ImageSearch search;
  std::vector<std::vector<Node>> levels;  // levels[k - 1]: the images of order k
  for (int order = 1; order <= o.order; ++order) {
    std::vector<Node> next;
    bool over_budget = false;
    const std::size_t parents = order == 1 ? 1 : levels.back().size();
    for (std::size_t i = 0; i < parents && !over_budget; ++i) {
      const Node* parent = order == 1 ? nullptr : &levels.back()[i];
      const Point from = parent ? parent->image : s;
      for (std::uint32_t p = 0; p < patches.size(); ++p) {
        if (parent && (p == parent->patch || !beam_meets(from, patches[parent->patch], patches[p]) ||
                       wholly_behind(patches[p], patches[parent->patch])))
          continue;
        if (!(plane_distance(patches[p], from) > 1e-9)) continue;  // behind the mirror: no image
        // At the last order an image is only traced, not reflected again: one whose last leg
        // (from the listener) misses its patch is no path (path_of's first test, made here
        // before the image is kept).
        if (order == o.order && !last_leg_meets(patches[p], mirror(patches[p], from), l)) continue;
        if (next.size() >= o.max_image_nodes) {
          over_budget = true;
          break;
        }
        next.push_back(Node{parent ? static_cast<std::uint32_t>(i) : UINT32_MAX, p, mirror(patches[p], from)});
      }
    }
    if (over_budget) break;
    search.candidates += next.size();
    levels.push_back(std::move(next));
    search.order = order;

    // Each image of this order: its path traced back from the listener, in chunks on the
    // threads; the chunks' results are joined in order, so the thread count changes nothing.
    const std::vector<Node>& nodes = levels.back();
    const std::size_t chunks = std::min<std::size_t>(nodes.size() / 256 + 1, 64);
    std::vector<std::vector<ImageSource>> found(chunks);
    ParallelOptions parallel;
    parallel.threads = o.threads;
    parallel.chunks = chunks;
    parallel.name = "audio.image_sources";
    const auto trace_chunk = [&](const Chunk& chunk) {
      Trace trace;
      for (std::size_t i = chunk.begin; i < chunk.end; ++i) {
        trace.sequence.clear();
        trace.images.clear();
        for (const Node* n = &nodes[i];;) {
          trace.sequence.push_back(n->patch);
          trace.images.push_back(n->image);
          if (n->parent == UINT32_MAX) break;
          n = &levels[static_cast<std::size_t>(order) - trace.sequence.size() - 1][n->parent];
        }
        ImageSource is;
        if (path_of(room, s, l, o, trace, is)) found[chunk.index].push_back(std::move(is));
      }
    };
    // A few hundred images are traced on the calling thread: no threads to start.
    if (chunks == 1) trace_chunk(Chunk{0, 0, nodes.size(), 0});
    else parallel_for(nodes.size(), trace_chunk, parallel);
    for (auto& f : found)
      for (auto& is : f) search.images.push_back(std::move(is));
  }
  std::stable_sort(search.images.begin(), search.images.end(),
                   [](const ImageSource& a, const ImageSource& b) { return a.delay < b.delay; });
  return search;
}

}  // namespace vola::audio
