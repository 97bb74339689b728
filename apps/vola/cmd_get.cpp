// vola get: one voxel's occupancy, rank, payload and attributes; or, with --points, the
// state of many points, one line each.
#include <charconv>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <optional>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

#include "commands.hpp"
#include "text_output.hpp"
#include "vola/error.hpp"
#include "vola/file.hpp"
#include "vola/map/state_map.hpp"
#include "vola/tile/tile_set.hpp"

namespace vola::cli {

namespace {

struct GetArgs {
  std::string file;
  std::vector<double> position;
  bool world = false;
  std::string points;
};

// The points of a --points file: one "x y z" per line (blank lines and lines starting
// with # skipped). A bad line is an error naming it.
std::vector<Point> read_points(const std::string& path) {
  std::ifstream in(path);
  if (!in) throw IoError(path + ": cannot open the --points file");
  std::vector<Point> points;
  std::string line;
  for (std::size_t number = 1; std::getline(in, line); ++number) {
    std::istringstream fields(line);
    std::vector<std::string> words;
    for (std::string w; fields >> w;) words.push_back(w);
    if (words.empty() || words[0][0] == '#') continue;
    Point p{};
    bool good = words.size() == 3;
    for (std::size_t i = 0; good && i < 3; ++i) {
      const char* end = words[i].data() + words[i].size();
      const auto [at, error] = std::from_chars(words[i].data(), end, p[i]);
      good = error == std::errc() && at == end && std::isfinite(p[i]);
    }
    if (!good)
      throw InvalidArgument(path + ": line " + std::to_string(number) + ": expected three finite numbers x y z, got '" +
                            line + "'");
    points.push_back(p);
  }
  if (in.bad()) throw IoError(path + ": read error");
  return points;
}

// --points: one line per point, "occupied P", "free P" or "unknown" for a state map (P the
// occupancy probability from the voxel's log-odds), "occupied" or "free" for any other
// tree (space outside its voxels is free there). Voxel coordinates without --world are the
// voxel's corner, so a point's voxel is its integer part; one outside the grid is an error.
void print_states(const GetArgs& a) {
  if (tile::is_tile_index_path(a.file)) throw InvalidArgument("--points takes a .vol file, not a tile index");
  const std::vector<Point> points = read_points(a.points);
  const Tree tree = open_mapped(a.file);
  const bool states = map::is_state_map(tree);
  std::vector<map::WorldState> found;
  found.reserve(points.size());
  if (a.world) {
    const map::StateLookup lookup(tree);
    for (const Point& p : points) found.push_back(lookup.at(p));
  } else {
    // A voxel coordinate outside the grid names no voxel: most often world coordinates
    // given without --world, which were all answered "free".
    const AttributeColumn* log_odds = tree.attributes().find("log_odds");
    for (std::size_t i = 0; i < points.size(); ++i) {
      const Point& p = points[i];
      if (!(p[0] >= 0 && p[1] >= 0 && p[2] >= 0 && p[0] < tree.side() && p[1] < tree.side() && p[2] < tree.side()))
        throw InvalidArgument(a.points + ": point " + std::to_string(i + 1) + " (" + shortest_text(p[0]) + ", " +
                              shortest_text(p[1]) + ", " + shortest_text(p[2]) + ") is not a voxel coordinate in 0.." +
                              std::to_string(tree.side() - 1) + " (use --world for CRS coordinates)");
      map::WorldState s{states ? map::VoxelState::unknown : map::VoxelState::free, {}};
      const Voxel v{static_cast<std::uint32_t>(p[0]), static_cast<std::uint32_t>(p[1]),
                    static_cast<std::uint32_t>(p[2])};
      s.state = map::state_at(tree, v);
      if (log_odds && s.state != map::VoxelState::unknown)
        if (const auto rank = tree.rank(v)) s.log_odds = static_cast<float>(log_odds->get(*rank));
      found.push_back(s);
    }
  }
  check_mapped(tree);
  std::string out;
  char line[64];
  for (const map::WorldState& s : found) {
    if (states && s.log_odds)
      std::snprintf(line, sizeof line, "%s %.4f\n", map::name_of(s.state), map::occupancy_probability(*s.log_odds));
    else
      std::snprintf(line, sizeof line, "%s\n", map::name_of(s.state));
    out += line;
  }
  std::fwrite(out.data(), 1, out.size(), stdout);
}

// Reads everything first and checks the mapping (a file cut meanwhile reads as zeros),
// then prints: no line comes from a lost mapping.
void print_voxel(const Tree& tree, const Voxel& v) {
  const auto rank = tree.rank(v);
  const auto payload = rank ? tree.voxel_payload(v) : std::nullopt;
  std::vector<std::pair<std::string, double>> values;
  if (rank)
    for (const auto& c : tree.attributes().columns()) values.emplace_back(c.name(), c.get(*rank));
  // A state map's voxels are known ones: the state word says which are occupied.
  const char* what = map::is_state_map(tree) ? map::name_of(map::state_at(tree, v)) : rank ? "occupied" : "empty";
  check_mapped(tree);
  std::printf("voxel %u %u %u: %s\n", v.x, v.y, v.z, what);
  if (!rank) return;
  std::printf("rank %llu\n", static_cast<unsigned long long>(*rank));
  if (payload) std::printf("payload 0x%016llx\n", static_cast<unsigned long long>(*payload));
  for (const auto& [name, value] : values) std::printf("%s %.17g\n", name.c_str(), value);
}

// A tile set: the point is in world coordinates; only its tile is opened.
void get_from_tiles(const GetArgs& a) {
  const tile::TileSet tiles(a.file);
  const Point p{a.position[0], a.position[1], a.position[2]};
  Key key;
  tile::TileIndex tile;
  if (!tiles.index().grid.locate(p, tile, key))  // a .vol refuses such a point too
    throw InvalidArgument("world point (" + shortest_text(p[0]) + ", " + shortest_text(p[1]) + ", " +
                          shortest_text(p[2]) + ") is not finite or lies beyond the 2^31 tiles the grid of " + a.file +
                          " indexes");
  const tile::TileLookup found = tiles.locate(p);
  std::string file = "not in the set (no points there)";
  for (const tile::TileEntry& e : tiles.index().tiles)
    if (found.in_tile && e.tile == found.tile) file = e.file;  // as the index names it: inside its generation
  std::printf("tile %d %d %d: %s\n", found.tile.i, found.tile.j, found.tile.k, file.c_str());
  if (!found.in_tile) {
    std::printf("voxel %u %u %u: empty\n", found.voxel.x, found.voxel.y, found.voxel.z);
    return;
  }
  print_voxel(*tiles.tree(found.tile), found.voxel);
}

void run_get(const GetArgs& a) {
  if (!a.points.empty()) {
    if (!a.position.empty()) throw InvalidArgument("give X Y Z or --points, not both");
    return print_states(a);
  }
  if (a.position.size() != 3) throw InvalidArgument("give X Y Z (or --points FILE)");
  if (tile::is_tile_index_path(a.file)) return get_from_tiles(a);
  const Tree tree = open_mapped(a.file);
  Voxel v;
  if (a.world) {
    if (!tree.quantizer().to_voxel({a.position[0], a.position[1], a.position[2]}, v))
      throw InvalidArgument("world point (" + shortest_text(a.position[0]) + ", " + shortest_text(a.position[1]) + ", " +
                            shortest_text(a.position[2]) + ") is outside the grid");
  } else {
    std::uint32_t c[3];
    for (int i = 0; i < 3; ++i) {
      const double p = a.position[i];
      if (!(p >= 0 && p < tree.side()) || p != static_cast<double>(static_cast<std::uint64_t>(p)))
        throw InvalidArgument("voxel coordinate " + shortest_text(p) + " is not an integer in 0.." +
                              std::to_string(tree.side() - 1) + " (use --world for CRS coordinates)");
      c[i] = static_cast<std::uint32_t>(p);
    }
    v = Voxel{c[0], c[1], c[2]};
  }
  print_voxel(tree, v);
}

}  // namespace

void add_get(CLI::App& app) {
  auto args = std::make_shared<GetArgs>();
  auto* cmd = app.add_subcommand("get", "Is voxel X Y Z occupied? Prints its rank, payload and attributes");
  cmd->footer(
      "FILE may be a tile index (index.geojson from vola tile): X Y Z are then world coordinates and\n"
      "only the tile holding them is opened.\n"
      "Example: vola get scan.vol 120 455 31      vola get scan.vol 315420.5 234010.2 42.0 --world\n"
      "         vola get tiles/index.geojson 315420.5 234010.2 42.0\n"
      "--points FILE: one \"x y z\" per line, one line out per point: for a state map (vola map)\n"
      "\"occupied P\", \"free P\" or \"unknown\", P the occupancy probability 1/(1+exp(-log_odds)) to 4\n"
      "decimals; for any other .vol \"occupied\" or \"free\" (space outside its voxels is free).\n"
      "         vola get map.vol --world --points queries.txt");
  cmd->add_option("file", args->file, ".vol file or tile index (.geojson)")->required()->check(CLI::ExistingFile);
  cmd->add_option("position", args->position, "X Y Z: voxel coordinates (or world coordinates with --world)")
      ->expected(3)->allow_extra_args(false);
  cmd->add_flag("--world", args->world, "X Y Z are in the file's CRS units, not voxel indices");
  cmd->add_option("--points", args->points, "Text file of x y z lines: print each point's state")
      ->check(CLI::ExistingFile);
  cmd->callback([args] { run_get(*args); });
}

}  // namespace vola::cli
