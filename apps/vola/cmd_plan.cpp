// vola plan: a collision-free path between two points (A* over free voxels), as CSV and PLY;
// with --avoid, the trajectory of a reactive agent that only looks along a fan of rays. On a
// state map (vola map) unknown space is an obstacle unless --unknown free.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <optional>
#include <sstream>
#include <string>
#include <vector>

#include "commands.hpp"
#include "files_read.hpp"
#include "number_checks.hpp"
#include "output_checks.hpp"
#include "vola/error.hpp"
#include "vola/file.hpp"
#include "vola/map/state_map.hpp"
#include "vola/output_file.hpp"
#include "vola/raycast/avoidance.hpp"
#include "vola/raycast/path_planner.hpp"
#include "vola/raycast/world.hpp"
#include "vola/tile/tile_set.hpp"

namespace vola::cli {

namespace {

// A path is a few kilobytes: formatted in memory, then written whole or not at all.
void write_whole(const std::string& path, const std::string& text) {
  OutputFile out(path);
  out.write(text);
  out.commit();
}

struct PlanArgs {
  std::string input, output = "path.csv", ply;
  std::vector<double> from, to;
  double radius = 0.0;
  double margin = 0.0;  // tile sets: around the from-to box; 0 = one tile
  int level = -1;
  bool hierarchical = false, exact = false, no_smooth = false, grid = false, quiet = false, solid_ground = false;
  bool avoid = false;
  double speed = 0.0, look_ahead = 0.0;  // 0: one voxel, 24 voxels
  std::size_t max_steps = 100000;
  std::uint64_t max_expansions = raycast::PlanOptions{}.max_expansions;
  std::string unknown;  // "occupied" or "free"; empty: occupied for a state map
};

// What the search plans in: the obstacles (a state map's occupied voxels) and, when
// unknown space counts as an obstacle, the state map's known voxels.
struct Scene {
  Tree obstacles;
  std::optional<Tree> known;
};

// The agent's positions (grid coordinates) from `from` towards `to`, step by step; throws
// when it does not arrive, after the caller had the chance to write what it flew.
raycast::Flight fly_to(const PlanArgs& a, const Tree& tree, const Point& from, const Point& to, double scale) {
  const raycast::Collider collider(tree);
  raycast::AvoidanceOptions options;
  options.radius = a.radius * scale;
  options.speed = a.speed > 0.0 ? a.speed * scale : 1.0;
  options.look_ahead = a.look_ahead > 0.0 ? a.look_ahead * scale : 24.0;
  if (collider.sphere(from, options.radius))
    throw InvalidArgument("--from: the agent there touches an occupied voxel (or is closer than --radius to one)");
  const raycast::ObstacleAvoider avoider(collider, options);
  return raycast::fly(avoider, from, to, a.max_steps);
}

// A .vol file: a state map's occupied voxels, its known ones too unless --unknown free;
// any other file as it is (empty space free, so --unknown occupied has nothing to mean).
Scene load_file(const PlanArgs& a) {
  Tree file = open_mapped(a.input);
  if (!map::is_state_map(file)) {
    if (a.unknown == "occupied")
      throw InvalidArgument("--unknown occupied: " + a.input + " is not a state map (vola map writes one): its "
                            "empty space is free, it has no unknown space");
    return {std::move(file), std::nullopt};
  }
  Tree occupied = map::occupied_tree(file);
  check_mapped(file);
  if (a.unknown == "free") return {std::move(occupied), std::nullopt};
  if (a.avoid)
    throw InvalidArgument("--avoid sees occupied voxels only, not unknown space: give --unknown free to fly " + a.input +
                          " optimistically");
  return {std::move(occupied), std::move(file)};
}

// The scene to plan in: the file, or for a tile index one grid over the tiles that meet
// the from-to box grown by --margin (only those tiles are opened).
Scene load_scene(const PlanArgs& a) {
  if (!tile::is_tile_index_path(a.input)) return load_file(a);
  if (a.unknown == "occupied") throw InvalidArgument("--unknown occupied: a tile set has no unknown space");
  if (a.grid) throw InvalidArgument("--grid: a tile set has no single voxel grid; give world coordinates");
  const tile::TileSet tiles(a.input);
  const double margin = a.margin > 0.0 ? a.margin : tiles.grid().tile_size;
  Box box;
  for (int i = 0; i < 3; ++i) {
    box.min[i] = std::min(a.from[i], a.to[i]) - margin;
    box.max[i] = std::max(a.from[i], a.to[i]) + margin;
  }
  Tree scene = tiles.mosaic(box);
  if (!a.quiet)
    std::printf("planning over %zu of %zu tiles (the from-to box and %.6g around it)\n", tiles.tiles_opened(),
                tiles.index().tiles.size(), margin);
  return {std::move(scene), std::nullopt};
}

// Start and goal this many voxels apart (or more) on the finest level: the exact search
// would expand millions of cells (a 200 m city at 0.1 m: 76 s and 1 GB), the hierarchical
// one finds a path within about 1% of its cost in a second or two.
constexpr double kAutoHierarchicalVoxels = 1024.0;

// --hierarchical and --exact decide; without either, far-apart points on the finest
// level (grid coordinates) plan hierarchically, with a note saying so. Points outside the
// grid of `side` voxels (or not finite) get no note: the search refuses them, naming them.
bool use_hierarchical(const PlanArgs& a, const Point& from, const Point& to, double side) {
  if (a.hierarchical || a.exact) return a.hierarchical;
  if (a.level >= 0) return false;
  for (int i = 0; i < 3; ++i)
    if (!(from[i] >= 0.0 && from[i] < side && to[i] >= 0.0 && to[i] < side)) return false;
  const double apart = std::max({std::abs(to[0] - from[0]), std::abs(to[1] - from[1]), std::abs(to[2] - from[2])});
  if (apart < kAutoHierarchicalVoxels) return false;
  if (!a.quiet)
    std::printf("searching hierarchically: the points are %.0f voxels apart (--exact for the optimal path, slower)\n",
                apart);
  return true;
}

void run_plan(const PlanArgs& a) {
  refuse_outputs_over_inputs(files_read(a.input), {a.output, a.ply}, "vola plan");
  if (a.avoid && a.solid_ground)
    throw InvalidArgument("--solid-ground: --avoid sees the voxels only, not the ground below them");
  const Scene scene = load_scene(a);
  const Tree& tree = scene.obstacles;
  const Frame frame = tree.frame();
  Point from{a.from[0], a.from[1], a.from[2]}, to{a.to[0], a.to[1], a.to[2]};
  raycast::PlanOptions options;
  options.radius = a.grid ? a.radius : a.radius / frame.voxel_size;
  options.level = a.level;
  options.hierarchical = a.hierarchical;
  options.solid_ground = a.solid_ground;
  options.max_expansions = a.max_expansions;
  options.smooth = !a.no_smooth;
  if (scene.known) options.known = &*scene.known;
  if (!a.grid) {
    options.world = &frame;
    from = raycast::world_to_grid(frame, from);
    to = raycast::world_to_grid(frame, to);
  }
  raycast::PlannedPath path;
  raycast::Flight flight;
  if (a.avoid) {
    flight = fly_to(a, tree, from, to, a.grid ? 1.0 : 1.0 / frame.voxel_size);
    path.points = flight.positions;
  } else {
    options.hierarchical = use_hierarchical(a, from, to, static_cast<double>(tree.side()));
    path = raycast::plan_path(tree, from, to, options);
  }
  std::vector<Point> points;
  for (const Point& p : path.points) points.push_back(a.grid ? p : raycast::grid_to_world(frame, p));
  std::ostringstream csv;
  csv.precision(17);
  csv << "x,y,z\n";
  for (const Point& p : points) csv << p[0] << ',' << p[1] << ',' << p[2] << '\n';
  write_whole(a.output, csv.str());
  if (!a.ply.empty()) {
    std::ostringstream ply;
    ply.precision(17);
    ply << "ply\nformat ascii 1.0\nelement vertex " << points.size() << "\nproperty double x\nproperty double y\n"
        << "property double z\nelement edge " << (points.empty() ? 0 : points.size() - 1)
        << "\nproperty int vertex1\nproperty int vertex2\nend_header\n";
    for (const Point& p : points) ply << p[0] << ' ' << p[1] << ' ' << p[2] << '\n';
    for (std::size_t i = 1; i < points.size(); ++i) ply << i - 1 << ' ' << i << '\n';
    write_whole(a.ply, ply.str());
  }
  if (a.avoid) {
    if (!flight.reached)
      throw InvalidArgument("--avoid: the agent did not reach the goal in " + std::to_string(points.size() - 1) +
                            " steps (" + (flight.held_steps ? "boxed in" : "out of --max-steps") +
                            "); its trajectory is in " + a.output);
    if (!a.quiet)
      std::printf("%zu steps to the goal, never closer than --radius to a voxel\n", points.size() - 1);
    return;
  }
  if (!a.quiet)
    std::printf("%zu waypoints, length %.6g (A* cost %.6g) %s, %llu cells expanded\n", points.size(),
                a.grid ? path.length : path.length * frame.voxel_size,
                a.grid ? path.cost : path.cost * frame.voxel_size, a.grid ? "voxels" : "world units",
                static_cast<unsigned long long>(path.expanded));
}

}  // namespace

void add_plan(CLI::App& app) {
  auto args = std::make_shared<PlanArgs>();
  auto* cmd = app.add_subcommand("plan", "Plan a collision-free path between two points (A* over free voxels)");
  cmd->footer(
      "The robot is a sphere of --radius: a voxel is free when no occupied voxel is within the radius\n"
      "of its centre (decided for bricks of 16^3 voxels at once, from the obstacles dilated by the\n"
      "sphere). A* moves to the 26 neighbours at Euclidean cost, a diagonal move only when every\n"
      "voxel of the box it spans is free (no corner cutting), so the sphere stays clear along every\n"
      "leg, not only at the voxels; the cost is optimal on the planning grid. Smoothing then\n"
      "replaces runs by straight segments the sphere can sweep clear (checked exactly).\n"
      "--hierarchical is the search that scales to a city: a route over coarse cells of 4^3 voxels\n"
      "at least half free first, then the exact search only within one coarse cell of that route\n"
      "(wider, then along wholly free cells, if that holds no path). Its cost is not guaranteed\n"
      "optimal: 0.75% above it on a generated city (docs/BENCHMARKS.md, Planning); a 200 m\n"
      "city at 0.1 m plans in 1-2 s. It is the default when --from and --to are 1024 voxels apart or more\n"
      "on the finest level (a note says so); --exact forces the optimal search.\n"
      "Errors say whether the start or goal is outside the volume, inside an obstacle, or unreachable.\n"
      "On a state map (vola map) unknown space is an obstacle too (--unknown occupied, the default\n"
      "there): a voxel is free only when it is known free and no unknown voxel is within the radius;\n"
      "--unknown free plans optimistically through unknown space. A .vol made from points has no\n"
      "unknown space: what is not a voxel is free.\n"
      "--solid-ground: the ground of a map made from points is a sampled sheet with free space under\n"
      "it, which the shortest path may use where the sheet ends. With it, every voxel below the\n"
      "ground is an obstacle: a column's ground is its lowest voxel, the lowest within 2 columns.\n"
      "The radius may reach at most 24 cells of the planning level: for a larger robot plan on a\n"
      "coarser --level.\n"
      "Coordinates are world coordinates (the file's frame) unless --grid is given. --from and --to\n"
      "are snapped to the centres of the voxels that hold them: the path runs from voxel centre to\n"
      "voxel centre, so its first and last waypoints are those centres (at most half a voxel's\n"
      "diagonal from the points given), as OctoMap-based planners report them.\n"
      "INPUT may be a tile index (index.geojson from vola tile): the search then runs over the tiles\n"
      "that meet the box around --from and --to grown by --margin, and opens no others.\n"
      "--avoid flies a reactive agent instead of planning: each step it casts a fan of rays around\n"
      "the goal direction (--look-ahead long, as thick as the agent), takes the open direction\n"
      "closest to the goal and its current heading, and moves --speed only if the swept sphere is\n"
      "clear, so it never collides; without a map search it can get stuck (then exit status 1). It\n"
      "sees occupied voxels only: on a state map it needs --unknown free.\n"
      "Examples:\n"
      "  vola plan site.vol --from 10 20 5 --to 300 410 8 --radius 0.5 -o path.csv --ply path.ply\n"
      "  vola plan city.vol --from 500001 5000001 100.7 --to 500199 5000199 106.8 --radius 0.3 --solid-ground\n"
      "  vola plan site.vol --from 10 20 5 --to 300 410 8 --radius 0.5 --avoid --speed 0.25\n"
      "  vola plan map.vol --from 0 0 1 --to 20 5 1 --radius 0.3 --unknown free\n"
      "  vola plan tiles/index.geojson --from 500100 5000100 105 --to 501900 5001200 110 --radius 1");
  cmd->add_option("input", args->input, "Input .vol or tile index (.geojson)")->required()->check(CLI::ExistingFile);
  cmd->add_option("--from", args->from, "Start X Y Z")->required()->expected(3);
  cmd->add_option("--to", args->to, "Goal X Y Z")->required()->expected(3);
  cmd->add_option("--radius", args->radius, "Robot radius (obstacle inflation)")->capture_default_str()->check(non_negative_number());
  cmd->add_option("--level", args->level, "Plan on this level (0 = coarsest; default: the voxels)");
  cmd->add_flag("--hierarchical", args->hierarchical,
                "A coarse route over 4^3-voxel cells first, then the voxels near it (scales; not guaranteed optimal, "
                "0.75% above it on a generated city); "
                "the default when the points are 1024 voxels apart or more")
      ->excludes(cmd->add_flag("--exact", args->exact, "The optimal search, however far apart the points"));
  cmd->add_flag("--no-smooth", args->no_smooth, "Keep every cell of the A* path");
  cmd->add_option("--max-expansions", args->max_expansions, "Give up after expanding this many cells")
      ->capture_default_str()
      ->check(positive_number());
  cmd->add_flag("--solid-ground", args->solid_ground, "The space under the ground is an obstacle (maps made from points)");
  cmd->add_option("-o,--output", args->output, "CSV of waypoints (x,y,z)")->capture_default_str();
  cmd->add_option("--ply", args->ply, "Also write the path as a PLY polyline");
  cmd->add_flag("--avoid", args->avoid, "Fly a reactive obstacle-avoiding agent instead of A*");
  cmd->add_option("--speed", args->speed, "--avoid: distance per step (default: one voxel)")
      ->check(positive_number());
  cmd->add_option("--look-ahead", args->look_ahead, "--avoid: length of the fan's rays (default: 24 voxels)")
      ->check(positive_number());
  cmd->add_option("--max-steps", args->max_steps, "--avoid: give up after this many steps")->capture_default_str();
  cmd->add_option("--margin", args->margin, "Tile index: how far around the from-to box to search (default: one tile)")
      ->check(positive_number());
  cmd->add_flag("--grid", args->grid, "Points and radius are in voxel-grid coordinates");
  cmd->add_option("--unknown", args->unknown,
                  "State maps: is unknown space occupied (the default there) or free (optimistic)?")
      ->check(CLI::IsMember({"occupied", "free"}));
  cmd->add_flag("-q,--quiet", args->quiet, "Print nothing on success but warnings (to stderr)");
  cmd->callback([args] { run_plan(*args); });
}

}  // namespace vola::cli
