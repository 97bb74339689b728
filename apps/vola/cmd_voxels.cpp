// vola voxels / vola coords: one line per occupied voxel, in key (file) order.
#include <bit>
#include <cstdio>
#include <optional>
#include <string>

#include "commands.hpp"
#include "open_voxels.hpp"
#include "text_output.hpp"
#include "vola/error.hpp"
#include "vola/file.hpp"
#include "vola/geo/crs.hpp"

namespace vola::cli {

namespace {

struct VoxelsArgs {
  std::string file;
  bool payload = false;
  bool attributes = false;
  bool header = false;
  bool wgs84 = false;                // coords: longitude latitude instead of the file's CRS
  std::optional<std::uint32_t> crs;  // coords: EPSG code overriding the file's
};

// Calls f(voxel, rank, leaf block) for every voxel.
template <class F>
void each_voxel(const Tree& tree, F&& f) {
  std::uint64_t rank = 0;
  tree.for_each_block(tree.depth() - 1, [&](std::size_t block, std::uint64_t word, std::uint32_t ox, std::uint32_t oy,
                                            std::uint32_t oz) {
    while (word) {
      const unsigned b = static_cast<unsigned>(std::countr_zero(word));
      word &= word - 1;
      f(Voxel{ox + (b & 3u), oy + ((b >> 2) & 3u), oz + (b >> 4)}, rank++, block);
    }
  });
}

void print_header(TextOutput& out, const Tree& tree, const VoxelsArgs& a, const char* columns = "x y z") {
  if (!a.header) return;
  out.text(columns);
  if (a.payload) out.text(" payload");
  if (a.attributes)
    for (const auto& c : tree.attributes().columns()) out.ch(' ').text(c.name());
  out.ch('\n');
}

void print_tail(TextOutput& out, const Tree& tree, const VoxelsArgs& a, std::uint64_t rank, std::size_t block) {
  if (a.payload) out.ch(' ').hex64(tree.voxel_payload_at_rank(rank, block));
  if (a.attributes)
    for (const auto& c : tree.attributes().columns()) out.ch(' ').number(c.get(rank));
  out.ch('\n');
}

void run_voxels(const VoxelsArgs& a) {
  const Tree tree = open_voxels(a.file);
  TextOutput out;
  print_header(out, tree, a);
  each_voxel(tree, [&](const Voxel& v, std::uint64_t rank, std::size_t block) {
    out.number(std::uint64_t{v.x}).ch(' ').number(std::uint64_t{v.y}).ch(' ').number(std::uint64_t{v.z});
    print_tail(out, tree, a, rank, block);
  });
  out.finish();
}

// The CRS to transform from: --crs, else what the file says; a file without one is an
// error rather than coordinates in a guessed CRS.
std::string source_crs(const Tree& tree, const VoxelsArgs& a) {
  if (a.crs) return "EPSG:" + std::to_string(*a.crs);
  if (auto crs = geo::crs_definition(tree.georef())) return *crs;
  throw InvalidArgument(a.file + " has no CRS (header EPSG " + std::to_string(geo::kUnsetEpsg) +
                        ", the reference's unset default, and no WKT): its coordinates cannot be placed on the "
                        "globe; give --crs EPSG if you know what they are");
}

void run_coords(const VoxelsArgs& a) {
  const Tree tree = open_voxels(a.file);
  const Quantizer q = tree.quantizer();
  std::optional<geo::ToWgs84> to_wgs84;
  if (a.wgs84) to_wgs84.emplace(source_crs(tree, a));
  else if (!geo::crs_definition(tree.georef()))
    std::fprintf(stderr, "vola: note: %s has no CRS; coordinates are in the units of the original input\n",
                 a.file.c_str());
  TextOutput out;
  print_header(out, tree, a, a.wgs84 ? "lon lat z" : "x y z");
  each_voxel(tree, [&](const Voxel& v, std::uint64_t rank, std::size_t block) {
    const Point p = to_wgs84 ? to_wgs84->transform(q.center(v)) : q.center(v);
    out.number(p[0]).ch(' ').number(p[1]).ch(' ').number(p[2]);
    print_tail(out, tree, a, rank, block);
  });
  out.finish();
}

void add_common(CLI::App* cmd, VoxelsArgs& args) {
  cmd->add_option("file", args.file, ".vol file")->required()->check(CLI::ExistingFile);
  cmd->add_flag("--payload", args.payload, "Add each voxel's 64-bit payload word (hex; 0 when the file has none)");
  cmd->add_flag("--attributes", args.attributes, "Add each voxel's attribute values, in column order");
  cmd->add_flag("--header", args.header, "Print a first line naming the columns");
}

}  // namespace

void add_voxels(CLI::App& app) {
  auto args = std::make_shared<VoxelsArgs>();
  auto* voxels = app.add_subcommand("voxels", "Print every occupied voxel as integer grid coordinates \"x y z\"");
  voxels->footer("Example: vola voxels part.vol --header > part.txt   (vola coords for world coordinates)");
  add_common(voxels, *args);
  voxels->callback([args] { run_voxels(*args); });

  auto coord_args = std::make_shared<VoxelsArgs>();
  auto* coords = app.add_subcommand("coords", "Print every occupied voxel's centre in world (CRS) coordinates \"x y z\"");
  coords->footer(
      "Toolkit-mode files map voxel v back to min + v * Lmax / (4^depth - 1), the inverse of the\n"
      "reference writer's rounding (the reference reader's -c uses Lmax / 4^depth, which is not).\n"
      "With --wgs84 the centres go from the file's CRS (its WKT, else its EPSG code) to WGS84;\n"
      "a file without a CRS is an error unless --crs says what it is.\n"
      "Example: vola coords dublin.vol --wgs84 --header");
  add_common(coords, *coord_args);
  auto* wgs84 = coords->add_flag("--wgs84", coord_args->wgs84,
                                 "Print \"lon lat z\": WGS84 longitude and latitude through PROJ, z unchanged");
  coords->add_option("--crs", coord_args->crs, "--wgs84: EPSG code of the file's coordinates, overriding the file's")
      ->needs(wgs84);
  coords->callback([coord_args] { run_coords(*coord_args); });
}

}  // namespace vola::cli
