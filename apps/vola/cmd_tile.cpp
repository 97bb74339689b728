// vola tile: many point files (or one huge one, or a generated survey) into a grid of
// georeferenced .vol tiles with a GeoJSON index and an overview pyramid, in a memory
// budget, on all cores, and on many processes under mpirun.
#include <chrono>
#include <cmath>
#include <cstdio>
#include <memory>
#include <string>
#include <vector>

#include "commands.hpp"
#include "crs_flags.hpp"
#include "filter_flags.hpp"
#include "number_checks.hpp"
#include "option_flags.hpp"
#include "progress.hpp"
#include "vola/error.hpp"
#include "vola/tile/tile_inputs.hpp"
#include "vola/tile/tiler.hpp"

namespace vola::cli {

namespace {

struct TileArgs {
  std::vector<std::string> inputs;
  std::string output, memory = "2G", spill_dir;
  double tile_size = 0.0;
  int depth = 0;
  std::vector<double> origin;
  std::string assign_crs, target_crs;
  bool allow_geographic = false;
  std::vector<std::string> filters;  // per-point stages (vola/filters/stages.hpp)
  unsigned threads = 0;
  bool no_overviews = false, no_attributes = false, quiet = false;
  std::uint64_t generate = 0;
  double density = 10.0;
  std::uint64_t seed = 1;
  std::size_t chunk_points = 0;  // 0: tile::chunk_points_for the options
  std::uint64_t max_tiles = tile::TileOptions{}.max_tiles;
};

// "2G", "512M", "1.5G", "300000000" -> bytes.
std::uint64_t parse_bytes(const std::string& text) {
  std::size_t used = 0;
  double value = 0.0;
  try {
    value = std::stod(text, &used);
  } catch (const std::exception&) {
    used = 0;
  }
  const std::string unit = text.substr(used);
  double scale = 0.0;
  if (unit.empty() || unit == "B") scale = 1.0;
  else if (unit == "K" || unit == "KiB") scale = 1024.0;
  else if (unit == "M" || unit == "MiB") scale = 1024.0 * 1024.0;
  else if (unit == "G" || unit == "GiB") scale = 1024.0 * 1024.0 * 1024.0;
  if (used == 0 || scale == 0.0 || !(value > 0.0) || !std::isfinite(value))
    throw InvalidArgument("--memory '" + text + "': expected a size such as 2G, 512M or 1073741824");
  return static_cast<std::uint64_t>(value * scale);
}

void run_tile(const TileArgs& a) {
  const auto start = std::chrono::steady_clock::now();
  std::unique_ptr<tile::Communicator> comm = tile::world();
  // Warnings are printed under --quiet too (rank 0 only); the rest only without it.
  const bool warn = comm->rank() == 0;
  const bool talk = warn && !a.quiet;
  try {
    tile::TileOptions options;
    options.memory_budget = parse_bytes(a.memory);
    options.threads = a.threads;
    options.attributes = !a.no_attributes;
    options.grid.tile_size = a.tile_size;
    options.grid.depth = a.depth;
    if (!a.origin.empty()) options.grid.origin = {a.origin[0], a.origin[1], a.origin[2]};
    options.output_dir = a.output;
    options.spill_dir = a.spill_dir;
    options.overviews = !a.no_overviews;
    options.max_tiles = a.max_tiles;
    tile::TileInputs inputs;
    inputs.inputs = a.inputs;
    inputs.generate_survey = a.generate;
    inputs.survey.density = a.density;
    inputs.survey.seed = a.seed;
    inputs.assign_crs = a.assign_crs;
    inputs.target_crs = a.target_crs;
    inputs.allow_geographic = a.allow_geographic;
    inputs.chunk_points = a.chunk_points;
    inputs.filters = a.filters;
    const tile::OpenedInputs opened = tile::open_inputs(inputs, options);
    if (warn)
      for (const std::string& w : opened.warnings) std::fprintf(stderr, "vola: warning: %s\n", with_flags(w).c_str());
    std::unique_ptr<Progress> progress;
    std::string stage;
    if (talk)
      options.progress = [&](const std::string& s, std::uint64_t done, std::uint64_t total) {
        if (s != stage) {
          if (progress) progress->finish();
          stage = s;
          progress = std::make_unique<Progress>(s);
        }
        progress->update(done, total);
      };
    const tile::TileSummary summary = tile::make_tiles(opened.views(), options, *comm);
    if (progress) progress->finish();
    if (warn)
      for (const std::string& w : summary.warnings) std::fprintf(stderr, "vola: warning: %s\n", with_flags(w).c_str());
    if (!talk) return;
    const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    std::printf("inputs:         %zu (%llu points)\n", opened.sources.size(), static_cast<unsigned long long>(opened.points));
    const std::string crs = crs_summary_line(options.epsg, options.crs_wkt);
    std::printf("crs:            %s\n", !crs.empty()              ? crs.c_str()
                                        : options.epsg            ? ("EPSG:" + std::to_string(*options.epsg)).c_str()
                                        : options.crs_wkt.empty() ? "none known"
                                                                  : "WKT from the input");
    std::printf("grid:           tiles of %.6g at depth %d (%u^3 voxels of %.6g), origin %.6g %.6g %.6g\n",
                options.grid.tile_size, options.grid.depth, side_of(options.grid.depth), options.grid.voxel_size(),
                options.grid.origin[0], options.grid.origin[1], options.grid.origin[2]);
    std::printf("points in:      %llu", static_cast<unsigned long long>(summary.points_in));
    if (summary.points_outside)
      std::printf(" (%llu not finite or beyond the tile range, dropped)", static_cast<unsigned long long>(summary.points_outside));
    std::printf("\ntiles:          %llu, %llu voxels, %llu bytes (%.2f bits per voxel)\n",
                static_cast<unsigned long long>(summary.tiles), static_cast<unsigned long long>(summary.voxels),
                static_cast<unsigned long long>(summary.tile_bytes),
                summary.voxels ? 8.0 * static_cast<double>(summary.tile_bytes) / static_cast<double>(summary.voxels) : 0.0);
    std::string columns;
    for (const std::string& name : summary.attributes) columns += (columns.empty() ? "" : ", ") + name;
    std::printf("attributes:     %s\n", columns.empty() ? "none (occupancy only)" : columns.c_str());
    std::printf("overviews:      %llu files\n", static_cast<unsigned long long>(summary.overview_files));
    std::printf("spilled:        %llu runs, %llu bytes (rank 0 of %d)\n", static_cast<unsigned long long>(summary.spill_runs),
                static_cast<unsigned long long>(summary.spill_bytes), comm->size());
    std::printf("index:          %s\n", summary.index_path.c_str());
    std::printf("time:           %.2f s, %.2f M points/s (rank 0: bucketing %.2f s, exchange %.2f s, tiles %.2f s, "
                "overviews %.2f s)\n",
                seconds, seconds > 0 ? static_cast<double>(summary.points_in) / seconds / 1e6 : 0.0,
                summary.seconds_bucket, summary.seconds_exchange, summary.seconds_build, summary.seconds_overviews);
  } catch (const std::exception& e) {
    if (comm->size() == 1) throw;
    std::fprintf(stderr, "vola: rank %d: %s\n", comm->rank(), e.what());
    comm->abort(1);
  }
}

}  // namespace

void add_tile(CLI::App& app) {
  auto args = std::make_shared<TileArgs>();
  auto* cmd = app.add_subcommand("tile", "Point clouds of any size into a grid of georeferenced .vol tiles");
  cmd->footer(
      "Tile (i, j, k) covers ORIGIN + [i, i+1) * TILE-SIZE on each axis and holds 4^DEPTH voxels per\n"
      "axis (voxel = TILE-SIZE / 4^DEPTH), so tiles of one tile size and depth line up voxel for\n"
      "voxel, across runs too. OUTDIR gets index.geojson (RFC 7946 footprints in WGS84 with files\n"
      "and counts, plus the grid and CRS: pass it to vola get / render / plan / view), index.gpkg (the\n"
      "footprints in the survey's own CRS, for a GIS) and the files they name, in one folder per run,\n"
      ".generation-N/: tile_I_J_K.vol and overviews/L1, L2, ... (each level 4x coarser, covering\n"
      "4x4x4 tiles of the level below; none when --depth is 1). A run replaces the previous run's\n"
      "folder only once its index is in place; files vola did not write are left alone.\n"
      "Filters: --where, --crop and --crop-polygon (as in vola convert) drop points chunk by chunk, in\n"
      "the inputs' own CRS, before any reprojection; filters that need neighbours (smrf, hag, outlier,\n"
      "decimation) are refused: run them with vola translate first.\n"
      "Memory: voxel keys are bucketed per tile and spilled to disk as sorted runs whenever the\n"
      "--memory budget is reached, so inputs far larger than memory tile within it; a single tile's\n"
      "voxel keys (8 bytes each) must fit the budget; with attributes every point's values are spilled\n"
      "too and reduced into its voxel in input order. The files are byte-identical whatever\n"
      "--threads, and under mpirun whatever the number of ranks (each rank reads a share of the\n"
      "chunks; keys travel to each tile's owner by message; OUTDIR must be visible to every rank).\n"
      "Examples:\n"
      "  vola tile flight1.las flight2.las --tile-size 512 --depth 6 -o tiles/    (voxels of 512/4^6 = 0.125 m)\n"
      "  vola tile survey.las --tile-size 1024 --depth 7 -o tiles/ --memory 1G      (voxels of 6.25 cm)\n"
      "  vola tile --generate-survey 1000000000 --tile-size 2000 --depth 6 --assign-crs 32633 -o big/ --memory 2G\n"
      "  mpirun -np 3 vola tile *.las --tile-size 1000 --depth 6 -o tiles/\n"
      "  vola get tiles/index.geojson 636250 849217 435       vola render tiles/index.geojson -o view.png");
  cmd->add_option("inputs", args->inputs, "Point files: LAS/LAZ/COPC (streamed in chunks), or any point format vola convert reads");
  cmd->add_option("-o,--output", args->output, "Output folder")->required();
  cmd->add_option("--tile-size", args->tile_size, "Tile edge in the CRS's units (metres, feet, ...)")->required()
      ->check(positive_number());
  cmd->add_option("--depth", args->depth, "Levels per tile: 4^DEPTH voxels per tile edge (1..10)")->required()
      ->check(CLI::Range(1, 10));
  cmd->add_option("--origin", args->origin, "World position of tile (0,0,0)'s corner")->expected(3);
  add_crs_options(*cmd, args->assign_crs, args->target_crs, args->allow_geographic, "--tile-size and --origin");
  add_filter_options(*cmd, args->filters, false);
  cmd->add_option("--memory", args->memory,
                  "Memory budget per process, at least 1M: key buffers, sorting and merging stay within it; a tile "
                  "being built holds its own voxels beyond it (a warning says when the largest tile may need more)")
      ->capture_default_str();
  cmd->add_option("--tmp", args->spill_dir, "Folder for spill files (default: OUTDIR/.spill; removed at the end)");
  cmd->add_option("--threads", args->threads, "Threads per process (0 = all cores)")->capture_default_str();
  cmd->add_flag("--no-overviews", args->no_overviews, "Write no overview pyramid");
  cmd->add_option("--max-tiles", args->max_tiles,
                  "Refuse, before writing any, more tiles than this (a tile size far below the point spacing; "
                  "0: no limit)")
      ->capture_default_str();
  cmd->add_flag("--no-attributes", args->no_attributes,
                "Occupancy only: drop the attribute columns (by default every tile keeps the columns vola convert "
                "keeps from the inputs, e.g. colour, intensity, classification; overviews reduce them further)");
  cmd->add_option("--generate-survey", args->generate,
                  "Also tile a generated survey of N points (city blocks of 200 m, streamed, never stored)");
  cmd->add_option("--survey-density", args->density, "Generated survey: points per square metre")->capture_default_str()
      ->check(positive_number());
  cmd->add_option("--seed", args->seed, "Generated survey: seed")->capture_default_str();
  cmd->add_option("--chunk-points", args->chunk_points,
                  "LAS points per work unit (default: 2^20, or fewer with attributes when --memory is small)")
      ->check(positive_number());
  cmd->add_flag("-q,--quiet", args->quiet, "Print nothing on success but warnings (to stderr)");
  cmd->callback([args] { run_tile(*args); });
}

}  // namespace vola::cli
