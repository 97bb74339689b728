#include "convert_input.hpp"

#include <algorithm>

#include "vola/error.hpp"
#include "vola/geo/crs.hpp"
#include "vola/io/input.hpp"
#include "vola/mesh/terrain.hpp"
#include "vola/mesh/voxelize.hpp"

namespace vola::python {

namespace {

Tree from_grid_cells(const io::VoxelGrid& grid, int requested_depth) {
  const std::uint32_t largest = std::max({grid.dims[0], grid.dims[1], grid.dims[2], 1u});
  int depth = requested_depth;
  if (depth == 0)
    for (depth = 1; depth < kMaxDepth && side_of(depth) < largest; ++depth) {
    }
  if (side_of(depth) < largest)
    throw InvalidArgument("a " + std::to_string(largest) + "-cell grid does not fit depth " + std::to_string(depth));
  Tree tree = build_from_voxels(grid.voxels, depth);
  tree.set_frame(Frame{Quantization::grid, grid.origin, grid.voxel_size});
  Box box{grid.origin, grid.origin};
  for (int i = 0; i < 3; ++i) box.max[i] += grid.voxel_size * grid.dims[i];
  tree.georef().bbox = box;
  return tree;
}

PointCloud cell_centres(const io::VoxelGrid& grid) {
  PointCloud cloud;
  cloud.xyz.reserve(3 * grid.voxels.size());
  for (const Voxel& v : grid.voxels) {
    cloud.xyz.push_back(grid.origin[0] + (v.x + 0.5) * grid.voxel_size);
    cloud.xyz.push_back(grid.origin[1] + (v.y + 0.5) * grid.voxel_size);
    cloud.xyz.push_back(grid.origin[2] + (v.z + 0.5) * grid.voxel_size);
  }
  return cloud;
}

Tree from_mesh(const io::Input& input, BuildOptions options, bool solid, BuildReport& report) {
  const Box bbox = mesh::triangle_bounds(input.triangles);
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

Tree from_terrain(const io::Input& input, BuildOptions options, BuildReport& report) {
  Box bbox = input.cloud.bounds();
  if (!input.terrain_surface_only) {
    bbox.min[2] = std::min(bbox.min[2], input.terrain_base);
    bbox.max[2] = std::max(bbox.max[2], input.terrain_base);
  }
  const Quantizer quantizer = resolve_quantizer(bbox, options);
  mesh::TerrainOptions columns;
  columns.base = input.terrain_base;
  columns.surface_only = input.terrain_surface_only;
  Tree tree = mesh::terrain_columns(input.cloud, quantizer, columns, &report);
  tree.georef().bbox = bbox;
  return tree;
}

}  // namespace

Tree convert(const std::string& path, const ConvertOptions& options, BuildReport* report_out) {
  if (options.epsg) geo::crs_wkt(*options.epsg);  // an unknown code fails before reading
  const io::InputFormat& format = io::find_input_format(path, options.format);
  if (format.name != "dem" && (options.dem_base || options.dem_surface_only))
    throw InvalidArgument("dem_base and dem_surface_only apply to DEM input");
  io::InputOptions input_options;
  input_options.attributes = options.attributes;
  input_options.dem_base = options.dem_base;
  input_options.dem_surface_only = options.dem_surface_only;
  io::Input input = format.read(path, input_options);
  if (options.solid && !input.is_mesh()) throw InvalidArgument("solid applies to mesh input (triangles)");
  if (!input.epsg && !input.wkt.empty()) input.epsg = geo::epsg_from_wkt(input.wkt);

  const std::string quantize = options.quantize.empty() ? (options.voxel_size > 0 ? "grid" : "toolkit") : options.quantize;
  const bool one_to_one = input.grid && options.quantize.empty() && options.voxel_size <= 0.0;
  BuildOptions build_options;
  if (quantize == "toolkit") {
    build_options.quantization = Quantization::toolkit;
    if (options.depth == 0 && !one_to_one) throw InvalidArgument("toolkit quantization needs a depth (1..10)");
    if (options.voxel_size > 0.0) throw InvalidArgument("a voxel size applies to grid quantization");
  } else if (quantize == "grid") {
    build_options.quantization = Quantization::grid;
    if (options.depth == 0 && options.voxel_size <= 0.0) throw InvalidArgument("grid quantization needs a voxel size or a depth");
  } else {
    throw InvalidArgument("quantize '" + quantize + "': expected 'toolkit' or 'grid'");
  }
  build_options.depth = options.depth;
  build_options.voxel_size = options.voxel_size;
  const std::optional<std::uint32_t> epsg = options.epsg ? options.epsg : input.epsg;
  if (epsg) build_options.epsg = *epsg;

  BuildReport report;
  Tree tree;
  if (one_to_one) {
    tree = from_grid_cells(*input.grid, options.depth);
    report.points_in = input.grid->voxels.size();
    report.voxels = tree.voxel_count();
  } else {
    if (input.grid) input.cloud = cell_centres(*input.grid);
    if (input.is_mesh()) {
      tree = from_mesh(input, build_options, options.solid, report);
    } else {
      if (input.cloud.size() == 0) throw InvalidArgument(path + ": no points");
      tree = input.terrain ? from_terrain(input, build_options, report) : build(input.cloud, build_options, &report);
    }
  }
  tree.georef().epsg = build_options.epsg;
  try {
    const auto [lat, lon] = epsg || input.wkt.empty() ? geo::centre_lat_lon(build_options.epsg, tree.georef().bbox)
                                                      : geo::centre_lat_lon(input.wkt, tree.georef().bbox);
    tree.georef().lat = lat;
    tree.georef().lon = lon;
  } catch (const Error&) {
    // A CRS PROJ cannot place leaves the centre at 0, 0, as vola convert does.
  }
  if (options.epsg) tree.georef().crs_wkt = geo::crs_wkt(*options.epsg);
  else if (!input.wkt.empty()) tree.georef().crs_wkt = input.wkt;
  else if (input.epsg) tree.georef().crs_wkt = geo::crs_wkt(*input.epsg);
  if (report_out) *report_out = report;
  return tree;
}

}  // namespace vola::python
