// vola.tile: `vola tile` from Python, through tile::open_inputs and tile::make_tiles as
// the CLI calls them (in this one process; mpirun is the CLI's).
#include "python_support.hpp"

#include <cstdint>
#include <filesystem>
#include <optional>

#include "vola/tile/communicator.hpp"
#include "vola/tile/tile_inputs.hpp"
#include "vola/tile/tiler.hpp"

namespace vola::python {

namespace {

py::dict make_tiles(const std::vector<std::filesystem::path>& paths, const std::filesystem::path& output, double tile_size,
                    int depth, std::optional<std::array<double, 3>> origin, const std::string& assign_crs,
                    const std::string& target_crs, bool allow_geographic, std::uint64_t memory_budget,
                    const std::optional<std::filesystem::path>& spill_dir, unsigned threads, bool overviews,
                    bool attributes, std::uint64_t generate_survey, double survey_density, std::uint64_t seed,
                    std::size_t chunk_points, const std::vector<std::string>& filters) {
  vola::tile::TileOptions options;
  options.grid.tile_size = tile_size;
  options.grid.depth = depth;
  if (origin) options.grid.origin = to_point(*origin);
  options.output_dir = output.string();
  if (spill_dir) options.spill_dir = spill_dir->string();
  options.memory_budget = memory_budget;
  options.threads = threads;
  options.progress = [check = interruptible()](const std::string&, std::uint64_t done, std::uint64_t total) {
    check(done, total);
  };
  options.overviews = overviews;
  options.attributes = attributes;
  vola::tile::TileInputs inputs;
  for (const auto& p : paths) inputs.inputs.push_back(p.string());
  inputs.generate_survey = generate_survey;
  inputs.survey.density = survey_density;
  inputs.survey.seed = seed;
  inputs.assign_crs = assign_crs;
  inputs.target_crs = target_crs;
  inputs.allow_geographic = allow_geographic;
  inputs.chunk_points = chunk_points;
  inputs.filters = filters;
  std::vector<std::string> warnings;
  vola::tile::TileSummary s;
  std::uint64_t points = 0;
  {
    py::gil_scoped_release release;
    s = with_python_names([&] {
      const vola::tile::OpenedInputs opened = vola::tile::open_inputs(inputs, options);
      warnings = opened.warnings;
      points = opened.points;
      const auto comm = vola::tile::single_process();
      return vola::tile::make_tiles(opened.views(), options, *comm);
    });
  }
  for (const auto& w : s.warnings) warnings.push_back(w);
  for (auto& w : warnings) w = python_words(w);
  py::dict out;
  out["index"] = s.index_path;
  out["points"] = points;
  out["points_in"] = s.points_in;
  out["points_outside"] = s.points_outside;
  out["tiles"] = s.tiles;
  out["voxels"] = s.voxels;
  out["tile_bytes"] = s.tile_bytes;
  out["overview_files"] = s.overview_files;
  out["spill_runs"] = s.spill_runs;
  out["spill_bytes"] = s.spill_bytes;
  out["attributes"] = s.attributes;
  out["epsg"] = options.epsg ? py::object(py::int_(*options.epsg)) : py::object(py::none());
  out["crs_wkt"] = options.crs_wkt;
  out["voxel_size"] = options.grid.voxel_size();
  out["warnings"] = warnings;
  return out;
}

}  // namespace

void bind_tiling(py::module_& m) {
  m.def("tile", &make_tiles, py::arg("inputs"), py::arg("output"), py::arg("tile_size"), py::arg("depth"),
        py::arg("origin") = py::none(), py::arg("assign_crs") = "", py::arg("target_crs") = "",
        py::arg("allow_geographic") = false, py::arg("memory_budget") = std::uint64_t{2} << 30,
        py::arg("spill_dir") = py::none(), py::arg("threads") = 0u, py::arg("overviews") = true,
        py::arg("attributes") = true, py::arg("generate_survey") = std::uint64_t{0}, py::arg("survey_density") = 10.0,
        py::arg("seed") = std::uint64_t{1}, py::arg("chunk_points") = std::size_t{0},
        py::arg("filters") = std::vector<std::string>{},
        "Point files into a grid of georeferenced .vol tiles (`vola tile INPUTS -o OUTPUT --tile-size S --depth D`):\n"
        "tile (i, j, k) covers origin + [i, i+1) * tile_size per axis with 4**depth voxels per edge; output gets\n"
        "index.geojson (open it with vola.open_tiles) and, in .generation-N/, tile_I_J_K.vol files and overviews/\n"
        "(overviews=False: none).\n"
        "inputs: LAS/LAZ/COPC (streamed) or any point file vola.convert reads; assign_crs relabels, target_crs\n"
        "reprojects, allow_geographic tiles in degrees; memory_budget in bytes (the CLI's --memory); spill_dir\n"
        "(default output/.spill); attributes=False: occupancy only; generate_survey=N adds a generated survey\n"
        "(survey_density points per square metre, seed); filters=['where:Classification == 2', 'crop:...']: the\n"
        "per-point stages, chunk by chunk (as --where/--crop). The files are the CLI's, byte for byte.\n"
        "Returns {index, points, points_in, points_outside, tiles, voxels, tile_bytes, overview_files, spill_runs,\n"
        "spill_bytes, attributes, epsg, crs_wkt, voxel_size, warnings}.");
}

}  // namespace vola::python
