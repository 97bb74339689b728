// vola.export_*: every format `vola export` writes, each through the library writer the
// CLI calls (include/vola/io/export.hpp, binvox.hpp, occupancy_maps.hpp); Tree.raster gives
// the GeoTIFF's grid as a numpy array. depth=K is the CLI's --depth K: the grid of the
// tree's first K levels.
#include "python_support.hpp"

#include <algorithm>
#include <cctype>
#include <cstdint>
#include <filesystem>
#include <optional>

#include "vola/io/binvox.hpp"
#include "vola/io/export.hpp"
#include "vola/io/export_format.hpp"
#include "vola/io/input.hpp"
#include "vola/io/occupancy_maps.hpp"
#include "vola/io/ros_map.hpp"
#include "vola/map/state_map.hpp"

namespace vola::python {

namespace {

// Runs a writer without the GIL, its OptionErrors in Python's words.
template <class Write>
auto write_released(Write&& write) {
  py::gil_scoped_release release;
  return with_python_names(std::forward<Write>(write));
}

// write(tree) on the tree's first `depth` levels (0: the tree itself), as `vola export
// --depth` does. A state map's occupied voxels, as `vola export` reads one: its free
// voxels are known empty space, not points, cells or returns.
template <class Write>
auto at_depth(const Tree& given, int depth, Write&& write) {
  if (depth < 0 || depth > given.depth())
    throw vola::OptionError("depth", "`depth` " + std::to_string(depth) + " is not one of the tree's depths 1.." +
                                         std::to_string(given.depth()) + " (0: the tree's own)");
  std::optional<Tree> occupied;
  if (vola::map::is_state_map(given)) occupied = vola::map::occupied_tree(given);
  const Tree& tree = occupied ? *occupied : given;
  if (depth == 0 || depth == tree.depth()) return write(tree);
  return write(tree.level_of_detail(depth));
}

vola::io::RasterOptions raster_options(const std::string& product, double resolution) {
  const auto kind = vola::io::raster_product(product);
  if (!kind) throw vola::InvalidArgument("product '" + product + "': expected 'dsm', 'dtm', 'intensity', 'density' or 'count'");
  vola::io::RasterOptions options;
  options.product = *kind;
  options.resolution = resolution;
  return options;
}

py::tuple raster(const Tree& tree, const std::string& product, double resolution, int depth) {
  const auto options = raster_options(product, resolution);
  vola::io::Raster r = write_released([&] {
    return at_depth(tree, depth, [&](const Tree& t) { return vola::io::make_raster(t, options); });
  });
  const auto h = static_cast<py::ssize_t>(r.height), w = static_cast<py::ssize_t>(r.width);
  const auto& g = r.geotransform;
  return py::make_tuple(owning_array(std::move(r.values), {h, w}), py::make_tuple(g[0], g[1], g[2], g[3], g[4], g[5]));
}

py::dict export_raster(const Tree& tree, const std::filesystem::path& path, const std::string& product, double resolution,
                       int depth) {
  const auto options = raster_options(product, resolution);
  const vola::io::RasterReport r = write_released([&] {
    return at_depth(tree, depth, [&](const Tree& t) { return vola::io::write_geotiff(t, path.string(), options); });
  });
  py::dict out;
  out["width"] = r.width;
  out["height"] = r.height;
  out["resolution"] = r.resolution;
  out["cells_with_data"] = r.cells_with_data;
  out["rule"] = r.rule;
  out["has_crs"] = r.has_crs;
  return out;
}

py::dict export_las(const Tree& tree, const std::filesystem::path& path, int depth) {
  const vola::io::LasReport r = write_released([&] {
    return at_depth(tree, depth, [&](const Tree& t) { return vola::io::write_las(t, path.string()); });
  });
  py::dict out;
  out["point_format"] = r.point_format;
  out["scale"] = r.scale;
  out["has_crs"] = r.has_crs;
  out["extra_bytes"] = r.extra_bytes;
  out["clamped_intensities"] = r.clamped_intensities;
  out["unfit_values"] = r.unfit_values;
  for (const std::string& unfit : r.unfit_values)  // values were changed: said as the CLI says it
    if (PyErr_WarnEx(PyExc_UserWarning, (path.string() + ": " + unfit).c_str(), 1) < 0) throw py::error_already_set();
  return out;
}

// A map's occupied and free voxels on one grid, at `depth`. A state map (vola map,
// Map.save) holds its free voxels: split it as `vola export` does, so that reports count
// occupied and free voxels (they counted every known voxel as occupied, though the file
// was right).
vola::io::MapVoxels gathered_map(const Tree& given, const Tree* given_free, int depth) {
  std::optional<Tree> occupied, own_free;
  if (vola::map::is_state_map(given)) {
    if (given_free) throw vola::InvalidArgument("the tree is a state map and holds its free voxels; free is for plain trees");
    occupied = vola::map::occupied_tree(given);
    own_free = vola::map::free_tree(given);
  }
  const Tree& tree = occupied ? *occupied : given;
  const Tree* free = own_free ? &*own_free : given_free;
  // A coarse cell holding occupied and free voxels is occupied, as in `vola export`.
  const std::optional<Tree> coarse_free =
      free && depth > 0 && depth < free->depth()
          ? std::optional<Tree>(vola::map::free_at_depth(*free, tree.level_of_detail(depth), depth))
          : std::nullopt;
  return at_depth(tree, depth,
                  [&](const Tree& t) { return vola::io::map_voxels(t, coarse_free ? &*coarse_free : free); });
}

py::dict export_map(const Tree& given, const std::filesystem::path& path, const Tree* given_free, int depth) {
  const vola::io::MapExportReport r = write_released([&] {
    const vola::io::MapVoxels voxels = gathered_map(given, given_free, depth);
    return vola::io::lower_extension(path.string()) == ".vdb" ? vola::io::write_vdb(voxels, path.string()) : vola::io::write_octomap(voxels, path.string());
  });
  py::dict report;
  report["occupied"] = r.occupied;
  report["free"] = r.free;
  report["log_odds"] = r.log_odds;
  report["shift"] = py::make_tuple(r.shift[0], r.shift[1], r.shift[2]);
  report["nodes"] = r.nodes;
  report["grids"] = r.grids;
  report["warnings"] = r.warnings;
  return report;
}

py::dict export_ros_map(const Tree& given, const std::filesystem::path& path, std::pair<double, double> band,
                        const Tree* given_free, int depth) {
  const vola::io::RosMapReport r = write_released([&] {
    return vola::io::write_ros_map(gathered_map(given, given_free, depth), path.string(), {band.first, band.second});
  });
  py::dict report;
  report["image"] = r.image;
  report["width"] = r.width;
  report["height"] = r.height;
  report["resolution"] = r.resolution;
  report["origin"] = py::make_tuple(r.origin[0], r.origin[1]);
  report["occupied"] = r.occupied;
  report["free"] = r.free;
  report["unknown"] = r.unknown;
  report["free_from_ground"] = r.free_from_ground;
  return report;
}

}  // namespace

void bind_export(py::module_& m, py::class_<Tree>& tree) {
  m.attr("RASTER_NODATA") = vola::io::kRasterNodata;
  m.def(
      "_export_format",
      [](const std::filesystem::path& path, bool slices, bool map, bool occupancy_above, bool raster, bool resolution,
         bool ascii, bool cubes, bool bits, bool free, bool band, const std::string& format) {
        vola::io::ExportRequest request;
        request.output = path.string();
        request.format = format;
        request.slices = slices;
        request.map = map;
        request.occupancy_above = occupancy_above;
        request.raster = raster;
        request.resolution = resolution;
        request.ascii = ascii;
        request.cubes = cubes;
        request.bits = bits;
        request.free = free;
        request.band = band;
        return with_python_names([&] { return vola::io::resolve_export_format(request); });
      },
      py::arg("path"), py::arg("slices"), py::arg("map"), py::arg("occupancy_above"), py::arg("raster"),
      py::arg("resolution"), py::arg("ascii"), py::arg("cubes"), py::arg("bits"), py::arg("free"),
      py::arg("band") = false, py::arg("format") = "auto",
      "vola.export's format ('ply', 'xyz', 'csv', 'las', 'binvox', 'npy', 'png', 'tif', 'octomap', 'vdb', 'rosmap') "
      "from the\n"
      "path's extension (or format, when not 'auto') and which options were given (True: given), by the rule `vola "
      "export` uses;\n"
      "InvalidArgument when an option does not apply to the format.");
  tree.def("raster", &raster, py::arg("product") = "dsm", py::arg("resolution") = 0.0, py::arg("depth") = 0,
           "The grid `vola export --raster PRODUCT` writes, in memory: (values (H, W) float32, row 0 the\n"
           "northernmost, vola.RASTER_NODATA where a cell has no voxel; geotransform: GDAL's six numbers, cell\n"
           "(c, r) has its top-left corner at (gt[0] + c*gt[1], gt[3] + r*gt[5])). product: 'dsm' (max height\n"
           "column, else top face), 'dtm' (min over ground voxels), 'intensity', 'density', 'count'; resolution:\n"
           "cell edge in the CRS's units (0: the voxel size, not finer). Cropped to the occupied cells.");
  m.def("export_raster", &export_raster, py::arg("tree"), py::arg("path"), py::arg("product") = "dsm",
        py::arg("resolution") = 0.0, py::arg("depth") = 0,
        "tree.raster(product, resolution) as a Float32 cloud-optimised GeoTIFF through GDAL (`vola export TREE\n"
        "OUT.tif --raster PRODUCT [--resolution R]`): the tree's CRS, nodata vola.RASTER_NODATA. Returns {width,\n"
        "height, resolution, cells_with_data, rule, has_crs}.");
  m.def("export_ply", [](const Tree& tree, const std::filesystem::path& path, bool ascii, bool cubes, int depth) {
        vola::io::PlyOptions options;
        options.ascii = ascii;
        options.cubes = cubes;
        const vola::io::PlyReport r = write_released([&] {
          return at_depth(tree, depth, [&](const Tree& t) { return vola::io::write_ply(t, path.string(), options); });
        });
        py::dict out;
        out["vertices"] = r.vertices;
        out["faces"] = r.faces;
        return out;
      }, py::arg("tree"), py::arg("path"), py::arg("ascii") = false, py::arg("cubes") = false, py::arg("depth") = 0,
      "PLY (`vola export TREE OUT.ply [--ascii] [--cubes]`): voxel centres with every attribute as a vertex\n"
      "property, or with cubes=True the voxels' outer surface as quads. Returns {vertices, faces}.");
  m.def("export_xyz", [](const Tree& tree, const std::filesystem::path& path, int depth) {
        write_released([&] { at_depth(tree, depth, [&](const Tree& t) { vola::io::write_xyz(t, path.string()); }); });
      }, py::arg("tree"), py::arg("path"), py::arg("depth") = 0,
      "'x y z [attributes]' text per voxel centre, full double precision (`vola export TREE OUT.xyz`).");
  m.def(
      "export_csv",
      [](const Tree& tree, const std::filesystem::path& path, int depth) {
        write_released([&] { at_depth(tree, depth, [&](const Tree& t) { vola::io::write_csv(t, path.string()); }); });
      },
      py::arg("tree"), py::arg("path"), py::arg("depth") = 0,
      "The voxel centres as CSV with PDAL's writers.text header (\"X\",\"Y\",\"Z\",\"Intensity\",...)\n"
      "(`vola export TREE OUT.csv`): pandas.read_csv reads it by name.");
  m.def("export_las", &export_las, py::arg("tree"), py::arg("path"), py::arg("depth") = 0,
        "The tree's voxel centres as LAS 1.4 points (`vola export TREE OUT.las`): colour, intensity,\n"
        "classification and returns into their fields, other columns as extra bytes, the CRS as WKT; a path\n"
        "ending in .laz is LASzip-compressed. Returns {point_format, scale, has_crs, extra_bytes,\n"
        "clamped_intensities, unfit_values}: values a field cannot hold (a classification of 300, a NaN\n"
        "intensity) are written clamped (NaN as 0), each field's count said in unfit_values and a UserWarning.");
  m.def("export_binvox", [](const Tree& tree, const std::filesystem::path& path, int depth) {
        write_released([&] { at_depth(tree, depth, [&](const Tree& t) { vola::io::write_binvox(t, path.string()); }); });
      }, py::arg("tree"), py::arg("path"), py::arg("depth") = 0, "A binvox voxel grid (`vola export TREE OUT.binvox`), side <= 4096.");
  m.def("export_npy", [](const Tree& tree, const std::filesystem::path& path, int depth) {
        write_released([&] { at_depth(tree, depth, [&](const Tree& t) { vola::io::write_npy_grid(t, path.string()); }); });
      }, py::arg("tree"), py::arg("path"), py::arg("depth") = 0,
      "A uint8 0/1 array of shape (S, S, S), index [x, y, z] (`vola export TREE OUT.npy`), depth <= 5.");
  m.def("export_slices", [](const Tree& tree, const std::filesystem::path& directory, bool world_files, int depth) {
        return write_released([&] {
          return at_depth(tree, depth, [&](const Tree& t) { return vola::io::write_png_slices(t, directory.string(), world_files); });
        });
      }, py::arg("tree"), py::arg("directory"), py::arg("world_files") = true, py::arg("depth") = 0,
      "One 8-bit PNG per z slice, occupied white, named depth<D>-<z>.png, each with a .pgw world file\n"
      "(`vola export TREE DIR --slices`), depth <= 5. Returns the number of images.");
  m.def("export_height_map", [](const Tree& tree, const std::filesystem::path& path, int bits, int depth) {
        return write_released([&] {
          return at_depth(tree, depth, [&](const Tree& t) {
            vola::io::write_png_height_map(t, path.string(), bits);
            return vola::io::write_world_file(t, path.string());
          });
        });
      }, py::arg("tree"), py::arg("path"), py::arg("bits") = 16, py::arg("depth") = 0,
      "Top-down PNG height map in voxel units (`vola export TREE OUT.png --map [--bits 8]`): highest z index\n"
      "+ 1 per column, 0 empty (bits=8 scales to 1..255), and its .pgw world file, whose path is returned.\n"
      "For elevations, tree.raster('dsm').");
  m.def("export_occupancy_above", [](const Tree& tree, const std::filesystem::path& path, std::uint32_t min_z, int depth) {
        return write_released([&] {
          return at_depth(tree, depth, [&](const Tree& t) {
            vola::io::write_png_occupancy_above(t, path.string(), min_z);
            return vola::io::write_world_file(t, path.string());
          });
        });
      }, py::arg("tree"), py::arg("path"), py::arg("min_z"), py::arg("depth") = 0,
      "Top-down PNG occupancy map (`vola export TREE OUT.png --occupancy-above Z`): black where a column has a\n"
      "voxel at z index >= min_z, else white; and its .pgw world file, whose path is returned.");
  m.def("export_map", &export_map, py::arg("tree"), py::arg("path"), py::arg("free") = py::none(), py::arg("depth") = 0,
        "The tree as an occupancy map (`vola export TREE OUT.bt|.ot|.vdb [--free FREE]`): OctoMap .bt (binary,\n"
        "maximum likelihood) or .ot (log-odds from a log_odds column, else the clamping maximum) through\n"
        "liboctomap, or OpenVDB .vdb (grid 'occupied', or 'log_odds'; 'free'/'free_log_odds' with free=)\n"
        "through OpenVDB; free= is a tree of free voxels on the same grid (vola map --free). Returns a dict:\n"
        "occupied, free, log_odds, shift (added to coordinates when OctoMap's cells needed it), nodes, grids,\n"
        "warnings.");
  m.def("export_ros_map", &export_ros_map, py::arg("tree"), py::arg("path"), py::arg("band"),
        py::arg("free") = py::none(), py::arg("depth") = 0,
        "A 2D map for ROS navigation (`vola export TREE OUT.yaml --band ZMIN:ZMAX [--free FREE]`): OUT.yaml and\n"
        "OUT.pgm as map_saver writes them (trinary), one cell per voxel column, cropped to the columns with\n"
        "voxels: occupied where a voxel centre lies in band=(zmin, zmax) (file units), free where a free voxel\n"
        "does (a state map's own, or free=), or with no free voxels where the column has voxels below the band\n"
        "and none in it; else unknown. Returns {image, width, height, resolution, origin, occupied, free,\n"
        "unknown, free_from_ground}.");
}

}  // namespace vola::python
