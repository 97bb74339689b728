// vola get: one voxel's occupancy, rank, payload and attributes.
#include <cstdio>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "commands.hpp"
#include "vola/error.hpp"
#include "vola/file.hpp"
#include "vola/tile/tile_set.hpp"

namespace vola::cli {

namespace {

struct GetArgs {
  std::string file;
  std::vector<double> position;
  bool world = false;
};

// Reads everything first and checks the mapping (a file cut meanwhile reads as zeros),
// then prints: no line comes from a lost mapping.
void print_voxel(const Tree& tree, const Voxel& v) {
  const auto rank = tree.rank(v);
  const auto payload = rank ? tree.voxel_payload(v) : std::nullopt;
  std::vector<std::pair<std::string, double>> values;
  if (rank)
    for (const auto& c : tree.attributes().columns()) values.emplace_back(c.name(), c.get(*rank));
  check_mapped(tree);
  std::printf("voxel %u %u %u: %s\n", v.x, v.y, v.z, rank ? "occupied" : "empty");
  if (!rank) return;
  std::printf("rank %llu\n", static_cast<unsigned long long>(*rank));
  if (payload) std::printf("payload 0x%016llx\n", static_cast<unsigned long long>(*payload));
  for (const auto& [name, value] : values) std::printf("%s %.17g\n", name.c_str(), value);
}

// A tile set: the point is in world coordinates; only its tile is opened.
void get_from_tiles(const GetArgs& a) {
  const tile::TileSet tiles(a.file);
  const Point p{a.position[0], a.position[1], a.position[2]};
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
  if (tile::is_tile_index_path(a.file)) return get_from_tiles(a);
  const Tree tree = open_mapped(a.file);
  Voxel v;
  if (a.world) {
    if (!tree.quantizer().to_voxel({a.position[0], a.position[1], a.position[2]}, v))
      throw InvalidArgument("world point (" + std::to_string(a.position[0]) + ", " + std::to_string(a.position[1]) +
                            ", " + std::to_string(a.position[2]) + ") is outside the grid");
  } else {
    std::uint32_t c[3];
    for (int i = 0; i < 3; ++i) {
      const double p = a.position[i];
      if (!(p >= 0 && p < tree.side()) || p != static_cast<double>(static_cast<std::uint64_t>(p)))
        throw InvalidArgument("voxel coordinate " + std::to_string(p) + " is not an integer in 0.." +
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
      "         vola get tiles/index.geojson 315420.5 234010.2 42.0");
  cmd->add_option("file", args->file, ".vol file or tile index (.geojson)")->required()->check(CLI::ExistingFile);
  cmd->add_option("position", args->position, "X Y Z: voxel coordinates (or world coordinates with --world)")
      ->required()->expected(3)->allow_extra_args(false);
  cmd->add_flag("--world", args->world, "X Y Z are in the file's CRS units, not voxel indices");
  cmd->callback([args] { run_get(*args); });
}

}  // namespace vola::cli
