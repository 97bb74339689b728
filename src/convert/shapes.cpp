#include "shapes.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>

#include "vola/error.hpp"
#include "vola/io/dem.hpp"
#include "vola/map/state_map.hpp"
#include "vola/mesh/terrain.hpp"
#include "vola/mesh/voxelize.hpp"

namespace vola::convert_detail {

Tree tree_from_grid_cells(const io::VoxelGrid& grid, int requested_depth, BuildReport& report) {
  const std::uint32_t largest = std::max({grid.dims[0], grid.dims[1], grid.dims[2], 1u});
  int depth = requested_depth;
  if (depth == 0)
    for (depth = 1; depth < kMaxDepth && side_of(depth) < largest; ++depth) {
    }
  if (side_of(depth) < largest) {
    const std::string cause = "a " + std::to_string(largest) + "-cell grid does not fit depth " + std::to_string(depth) +
                              " (" + std::to_string(side_of(depth)) + " voxels per axis)";
    if (requested_depth != 0) throw OptionError("depth", cause);
    throw InvalidArgument(cause + ", the deepest a tree has");
  }
  Tree tree;
  if (!grid.free.empty()) {
    // A map's free cells too (an OctoMap's): a state map of both states, as `vola map`
    // writes one, the occupied cells' log-odds from the grid's column when it has one.
    std::vector<float> occupied_log_odds;
    for (const PointAttribute& column : grid.attributes)
      if (column.name == "log_odds") occupied_log_odds.assign(column.values.begin(), column.values.end());
    tree = map::state_map_from_voxels(grid.voxels, occupied_log_odds, grid.free, grid.free_log_odds, depth,
                                      Frame{Quantization::grid, grid.origin, grid.voxel_size});
  } else if (grid.attributes.empty()) {
    tree = build_from_voxels(grid.voxels, depth);
    tree.set_frame(Frame{Quantization::grid, grid.origin, grid.voxel_size});
  } else {
    // Columns ride with the cell centres through the builder's grid quantization, which
    // puts each centre back into its own cell (half a cell from every face).
    BuildOptions options;
    options.quantization = Quantization::grid;
    options.depth = depth;
    options.voxel_size = grid.voxel_size;
    options.origin = grid.origin;
    tree = build(grid_cell_centres(grid), options);
  }
  Box box{grid.origin, grid.origin};
  for (int i = 0; i < 3; ++i) box.max[i] += grid.voxel_size * grid.dims[i];
  tree.georef().bbox = box;
  report.points_in = grid.voxels.size() + grid.free.size();
  report.voxels = tree.voxel_count();
  return tree;
}

PointCloud grid_cell_centres(const io::VoxelGrid& grid) {
  PointCloud cloud;
  cloud.xyz.reserve(3 * grid.voxels.size());
  for (const Voxel& v : grid.voxels) {
    cloud.xyz.push_back(grid.origin[0] + (v.x + 0.5) * grid.voxel_size);
    cloud.xyz.push_back(grid.origin[1] + (v.y + 0.5) * grid.voxel_size);
    cloud.xyz.push_back(grid.origin[2] + (v.z + 0.5) * grid.voxel_size);
  }
  cloud.attributes = grid.attributes;
  return cloud;
}

namespace {

std::string shortest(double v) {
  char text[32];
  std::snprintf(text, sizeof text, "%.6g", v);
  return text;
}

}  // namespace

PointCloud grid_cell_points(const io::VoxelGrid& grid, const BuildOptions& options) {
  PointCloud centres = grid_cell_centres(grid);
  if (centres.size() == 0) return centres;
  // The voxel the build will make: the given size, or the one the centres' extent gives
  // (the points filling the cells reach further, so the build's voxel is no smaller).
  double voxel = options.voxel_size;
  if (options.quantization != Quantization::grid || !(voxel > 0.0)) {
    Box box{{centres.xyz[0], centres.xyz[1], centres.xyz[2]}, {centres.xyz[0], centres.xyz[1], centres.xyz[2]}};
    for (std::size_t i = 0; i < centres.size(); ++i)
      for (int a = 0; a < 3; ++a) {
        box.min[a] = std::min(box.min[a], centres.xyz[3 * i + a]);
        box.max[a] = std::max(box.max[a], centres.xyz[3 * i + a]);
      }
    voxel = resolve_quantizer(options.bbox ? *options.bbox : box, options).frame().voxel_size;
  }
  if (!(voxel > 0.0) || voxel >= grid.voxel_size) return centres;
  const double per_axis = std::ceil(grid.voxel_size / voxel);
  // 2^25 points: 800 MB of coordinates. A toolkit depth of 5 over a small grid asks for
  // hundreds of voxels a cell side (a 2 x 3 x 4 grid: 81 million points).
  constexpr double kMaxPoints = 33554432.0;
  const double points = per_axis * per_axis * per_axis * static_cast<double>(centres.size());
  if (points > kMaxPoints)
    throw InvalidArgument("cells of " + shortest(grid.voxel_size) + " at voxels of " + shortest(voxel) +
                          ": filling each of the " + std::to_string(centres.size()) +
                          " occupied cells would set up to " + shortest(points) + " voxels (" + shortest(per_axis) +
                          "^3 a cell), more than 2^25; give a larger voxel size or a smaller depth (the grid's own "
                          "cell size, " +
                          shortest(grid.voxel_size) + ", gives one voxel a cell)");
  const auto k = static_cast<std::size_t>(per_axis);
  const double step = grid.voxel_size / per_axis;
  PointCloud filled;
  filled.xyz.reserve(3 * centres.size() * k * k * k);
  filled.attributes = centres.attributes;
  for (auto& a : filled.attributes) {
    a.values.clear();
    a.values.reserve(centres.size() * k * k * k);
  }
  for (std::size_t i = 0; i < centres.size(); ++i) {
    const double corner[3] = {centres.xyz[3 * i] - 0.5 * grid.voxel_size,
                              centres.xyz[3 * i + 1] - 0.5 * grid.voxel_size,
                              centres.xyz[3 * i + 2] - 0.5 * grid.voxel_size};
    for (std::size_t z = 0; z < k; ++z)
      for (std::size_t y = 0; y < k; ++y)
        for (std::size_t x = 0; x < k; ++x) {
          filled.xyz.push_back(corner[0] + (static_cast<double>(x) + 0.5) * step);
          filled.xyz.push_back(corner[1] + (static_cast<double>(y) + 0.5) * step);
          filled.xyz.push_back(corner[2] + (static_cast<double>(z) + 0.5) * step);
          for (std::size_t c = 0; c < filled.attributes.size(); ++c)
            filled.attributes[c].values.push_back(centres.attributes[c].values[i]);
        }
  }
  return filled;
}

Tree tree_from_mesh(const io::Input& input, const BuildOptions& options, bool solid, BuildReport& report) {
  if (options.payload) throw OptionError("nbits", "mesh input carries no payload");
  const Box bbox = options.bbox ? *options.bbox : mesh::triangle_bounds(input.triangles);
  const Quantizer quantizer = resolve_quantizer(bbox, options);
  mesh::VoxelizeOptions voxelize;
  voxelize.solid = solid;
  mesh::VoxelizeReport voxels;
  Tree tree = mesh::voxelize(input.triangles, quantizer, voxelize, &voxels);
  tree.georef().bbox = bbox;
  report.points_in = voxels.triangles;
  report.points_outside = voxels.skipped + voxels.outside;
  report.voxels = tree.voxel_count();
  return tree;
}

namespace {

// A DEM's voxel columns stand on its cells: with a voxel size and no origin, the default
// origin is the box's minimum snapped to the raster's own lattice (its corner plus whole
// voxels) in x and y, not to multiples of the voxel size, which moved a 60 m raster 20 m
// west. z snaps as for points.
BuildOptions on_the_cells(const io::Input& input, const Box& bbox, BuildOptions options) {
  if (options.origin || !input.terrain_lattice || options.quantization != Quantization::grid ||
      !(options.voxel_size > 0.0))
    return options;
  const auto& [x, y] = *input.terrain_lattice;
  options.origin = Point{grid_line_below(bbox.min[0], options.voxel_size, x),
                         grid_line_below(bbox.min[1], options.voxel_size, y),
                         grid_line_below(bbox.min[2], options.voxel_size)};
  return options;
}

// A cell wider than a voxel covers every voxel column whose centre lies on it, not only
// the one under its own centre (a 60 m raster at 30 m voxels left three columns in four
// empty): its point becomes a point per such column, each at the cell's height (the
// raster's value, as GDAL's nearest resampling gives it, not interpolated). Empty when
// each cell already is at most a voxel. Grid mode only (toolkit files follow the reference).
PointCloud cells_on_voxels(const io::Input& input, const BuildOptions& options, double voxel) {
  if (!input.terrain_cell || options.quantization != Quantization::grid || !(voxel > 0.0)) return {};
  const auto [width, height] = *input.terrain_cell;
  // Points no farther apart than a voxel reach every column the cell touches.
  const auto split = [voxel](double side) { return std::max(1.0, std::ceil(side / voxel - 1e-9)); };
  const double nx = split(width), ny = split(height);
  if (nx * ny <= 1.0) return {};
  const double cells = static_cast<double>(input.cloud.size());
  if (cells * nx * ny > static_cast<double>(io::kMaxDemCells)) {
    char what[192];
    std::snprintf(what, sizeof what,
                  "the DEM's %.0f cells of %g x %g at voxels of %g make %.0f voxel columns, more than %llu", cells,
                  width, height, voxel, cells * nx * ny, static_cast<unsigned long long>(io::kMaxDemCells));
    throw InvalidArgument(std::string(what) + "; give a larger voxel size, or crop the raster first");
  }
  PointCloud out;
  out.xyz.reserve(static_cast<std::size_t>(cells * nx * ny) * 3);
  const std::size_t ix = static_cast<std::size_t>(nx), iy = static_cast<std::size_t>(ny);
  for (std::size_t c = 0; c < input.cloud.size(); ++c) {
    const double* p = &input.cloud.xyz[3 * c];
    for (std::size_t j = 0; j < iy; ++j)
      for (std::size_t i = 0; i < ix; ++i) {
        out.xyz.push_back(p[0] - width / 2 + (static_cast<double>(i) + 0.5) * width / nx);
        out.xyz.push_back(p[1] - height / 2 + (static_cast<double>(j) + 0.5) * height / ny);
        out.xyz.push_back(p[2]);
      }
  }
  return out;
}

}  // namespace

Tree tree_from_terrain(const io::Input& input, const BuildOptions& options, BuildReport& report) {
  if (options.payload) throw OptionError("nbits", "DEM input carries no payload");
  const PointCloud spread = cells_on_voxels(input, options, options.voxel_size);
  const PointCloud& cells = spread.xyz.empty() ? input.cloud : spread;
  Box bbox = cells.bounds();
  if (!input.terrain_surface_only) {
    bbox.min[2] = std::min(bbox.min[2], input.terrain_base);
    bbox.max[2] = std::max(bbox.max[2], input.terrain_base);
  }
  if (options.bbox) bbox = *options.bbox;
  const Quantizer quantizer = resolve_quantizer(bbox, on_the_cells(input, bbox, options));
  mesh::TerrainOptions columns;
  columns.base = input.terrain_base;
  columns.surface_only = input.terrain_surface_only;
  Tree tree = mesh::terrain_columns(cells, quantizer, columns, &report);
  tree.georef().bbox = bbox;
  return tree;
}

}  // namespace vola::convert_detail
