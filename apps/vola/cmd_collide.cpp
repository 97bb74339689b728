// vola collide: is a segment, a sphere or an axis-aligned box free of occupied voxels?
// Prints "free" or what was hit; the exit status answers too (0 free, 3 collision), so
// scripts can write `if vola collide site.vol --segment ...; then`.
#include <cmath>
#include <cstdio>
#include <optional>
#include <string>
#include <vector>

#include "commands.hpp"
#include "open_voxels.hpp"
#include "vola/error.hpp"
#include "vola/file.hpp"
#include "vola/map/unknown_space.hpp"
#include "vola/raycast/collision.hpp"
#include "vola/raycast/world.hpp"

namespace vola::cli {

namespace {

// The exit status of a query that touches an occupied voxel (1 and 2 are errors).
constexpr int kCollisionStatus = 3;

struct CollideArgs {
  std::string input;
  std::vector<double> segment, sphere, box;
  bool grid = false, quiet = false;
};

// One line naming the first voxel a segment enters: the voxel, where and how far along
// the segment it is entered, and the face it is entered through.
void print_segment_hit(const CollideArgs& a, const Point& from, const Point& to,
                       const raycast::RayHit& hit) {
  Point entry{};
  for (int i = 0; i < 3; ++i) entry[i] = from[i] + hit.t * (to[i] - from[i]);
  // hypot: the squares of a segment 1e300 long overflowed, and the distance printed "inf".
  const double distance = hit.t * std::hypot(to[0] - from[0], to[1] - from[1], to[2] - from[2]);
  const char* units = a.grid ? "voxels" : "world units";
  if (hit.t == 0.0)
    std::printf("hit: the segment starts inside voxel %u %u %u\n", hit.voxel.x, hit.voxel.y, hit.voxel.z);
  else
    std::printf("hit: voxel %u %u %u, entered at %.9g %.9g %.9g (%s), %.9g %s from the start through face %d %d %d\n",
                hit.voxel.x, hit.voxel.y, hit.voxel.z, entry[0], entry[1], entry[2], a.grid ? "grid" : "world",
                distance, units, hit.normal[0], hit.normal[1], hit.normal[2]);
}

// "no occupied voxel ...", and on a state map the unknown voxels the query reaches
// (`reaches`: "reaches", "passes through"), or that it reaches too many to count.
std::string free_answer(const char* what, const char* reaches, std::optional<std::uint64_t> unknown) {
  if (!unknown)
    return std::string(what) + ", but it " + reaches + " more than " + std::to_string(map::kMaxUnknownCells) +
           " voxels, too many to count those the map has not seen";
  if (*unknown == 0) return what;
  return std::string(what) + ", but it " + reaches + " " + std::to_string(*unknown) +
         (*unknown == 1 ? " voxel" : " voxels") +
         " the map has not seen (unknown space, which vola plan takes for an obstacle)";
}

int run_collide(const CollideArgs& a) {
  const int queries = !a.segment.empty() + !a.sphere.empty() + !a.box.empty();
  if (queries != 1) throw InvalidArgument("give exactly one of --segment, --sphere or --box");
  const Tree tree = open_voxels(a.input);
  const Frame frame = tree.frame();
  const raycast::Collider collider(tree);
  auto to_grid = [&](double x, double y, double z) {
    const Point p{x, y, z};
    return a.grid ? p : raycast::world_to_grid(frame, p);
  };
  auto report = [&](bool hit, const char* what) {
    if (!a.quiet) std::printf("%s: %s\n", hit ? "hit" : "free", what);
    return hit ? kCollisionStatus : 0;
  };

  if (!a.segment.empty()) {
    const auto& s = a.segment;
    const Point from{s[0], s[1], s[2]}, to{s[3], s[4], s[5]};
    const auto hit = collider.segment(to_grid(s[0], s[1], s[2]), to_grid(s[3], s[4], s[5]));
    if (!hit) {
      // A state map (vola map) knows where it has not seen: say so, as OctoMap's ray
      // casts stop there and vola plan takes it for an obstacle.
      const auto unknown =
          map::unknown_voxels_on_segment(open_mapped(a.input), to_grid(s[0], s[1], s[2]), to_grid(s[3], s[4], s[5]));
      return report(false, free_answer("no occupied voxel on the segment", "passes through", unknown).c_str());
    }
    if (!a.quiet) print_segment_hit(a, from, to, *hit);
    return kCollisionStatus;
  }
  if (!a.sphere.empty()) {
    const auto& s = a.sphere;
    if (!(s[3] >= 0.0) || !std::isfinite(s[3])) throw InvalidArgument("--sphere: the radius must be finite and >= 0");
    const Point centre = to_grid(s[0], s[1], s[2]);
    const double radius = a.grid ? s[3] : s[3] / frame.voxel_size;
    const bool hit = collider.sphere(centre, radius);
    if (hit) return report(true, "an occupied voxel is within the radius");
    const auto unknown = map::unknown_voxels_in_sphere(open_mapped(a.input), centre, radius);
    return report(false, free_answer("no occupied voxel within the radius", "reaches", unknown).c_str());
  }
  const auto& b = a.box;
  for (int i = 0; i < 3; ++i)
    if (!(b[i] <= b[i + 3]))
      throw InvalidArgument("--box: expected XMIN YMIN ZMIN XMAX YMAX ZMAX with each min <= max");
  const Point low = to_grid(b[0], b[1], b[2]), high = to_grid(b[3], b[4], b[5]);
  const bool hit = collider.box(Box{low, high});
  if (hit) return report(true, "an occupied voxel overlaps the box");
  const auto unknown = map::unknown_voxels_in_box(open_mapped(a.input), Box{low, high});
  return report(false, free_answer("no occupied voxel overlaps the box", "reaches", unknown).c_str());
}

}  // namespace

void add_collide(CLI::App& app) {
  auto args = std::make_shared<CollideArgs>();
  auto* cmd = app.add_subcommand("collide", "Collision check: is a segment, sphere or box free of occupied voxels?");
  cmd->footer(
      "Give one query. Coordinates are world coordinates in the file's frame (see 'vola info')\n"
      "unless --grid is given, then voxel-grid coordinates: voxel (i, j, k) is the cube\n"
      "[i, i+1] x [j, j+1] x [k, k+1].\n"
      "  --segment  the first occupied voxel the segment enters, with where, how far and which face;\n"
      "  --sphere   any occupied voxel within the radius of the centre (touching counts);\n"
      "  --box      any occupied voxel overlapping the box's interior (touching faces do not count).\n"
      "Prints 'free: ...' or 'hit: ...'. Exit status: 0 free, 3 collision, 1 error (another status: a usage error).\n"
      "A state map (vola map) is checked against its occupied voxels; a free segment, sphere or box that\n"
      "reaches space the map has not seen says so (unknown space is not free: vola plan takes it for an obstacle).\n"
      "A segment of no length is its point.\n"
      "Examples:\n"
      "  vola collide site.vol --segment 636500 849500 120  636900 849800 90\n"
      "  vola collide site.vol --sphere 636500 849500 120 2.5\n"
      "  vola collide site.vol --grid --box 10 10 0 20 20 5 && echo clear");
  cmd->add_option("input", args->input, "Input .vol")->required()->check(CLI::ExistingFile);
  cmd->add_option("--segment", args->segment, "Segment X0 Y0 Z0 X1 Y1 Z1")->expected(6);
  cmd->add_option("--sphere", args->sphere, "Sphere X Y Z RADIUS")->expected(4);
  cmd->add_option("--box", args->box, "Axis-aligned box XMIN YMIN ZMIN XMAX YMAX ZMAX")->expected(6);
  cmd->add_flag("--grid", args->grid, "Coordinates (and radius) are in voxel-grid coordinates");
  cmd->add_flag("-q,--quiet", args->quiet, "Print nothing; answer by the exit status only");
  cmd->callback([args] {
    const int status = run_collide(*args);
    if (status != 0) throw CLI::RuntimeError(status);
  });
}

}  // namespace vola::cli
