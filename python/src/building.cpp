// vola.build, build_from_voxels, from_dense, read, open_mapped, parse and convert: making trees.
#include "python_support.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <filesystem>
#include <optional>

#include "vola/builder.hpp"
#include "vola/convert.hpp"
#include "vola/file.hpp"
#include "vola/filters/stages.hpp"
#include "vola/geo/crs.hpp"
#include "vola/io/column_reduction.hpp"
#include "vola/io/input.hpp"
#include "vola/io/translate.hpp"

namespace vola::python {

namespace {

// ---- building ----

// The CRS recorded as vola convert records it: a WKT's EPSG code in the header when PROJ
// names one (build left the header at 2000), a code and a WKT that name different CRSs
// refused, and the WGS84 latitude and longitude of the bbox centre (left at 0, 0).
void georeference_built(Tree& tree, std::uint32_t epsg, const std::string& crs_wkt) {
  vola::Georef& georef = tree.georef();
  georef.epsg = epsg;
  georef.crs_wkt = crs_wkt;  // kept in the extension, as vola convert keeps a WKT
  if (!crs_wkt.empty()) {
    const std::optional<std::uint32_t> named = vola::geo::epsg_from_wkt(crs_wkt);  // throws for a WKT PROJ cannot read
    if (epsg != vola::geo::kUnsetEpsg && !vola::geo::same_crs("EPSG:" + std::to_string(epsg), crs_wkt))
      throw vola::InvalidArgument("epsg=" + std::to_string(epsg) + " and crs_wkt name different CRSs" +
                                  (named ? " (the WKT is EPSG:" + std::to_string(*named) + ")" : std::string()) +
                                  ": give one");
    if (epsg == vola::geo::kUnsetEpsg && named) georef.epsg = *named;
  }
  if (const auto definition = vola::geo::crs_definition(georef)) {
    try {
      const auto [lat, lon] = vola::geo::centre_lat_lon(*definition, georef.bbox);
      georef.lat = lat;
      georef.lon = lon;
    } catch (const vola::Error&) {
      // A CRS PROJ cannot place (an engineering CRS): no centre, as in vola convert.
    }
  }
}

// A CRS PROJ does not know is refused before anything is built, as vola convert refuses
// --assign-crs (it was written to the file, and only `vola info` said so later).
void check_crs(std::uint32_t epsg, const std::string& crs_wkt) {
  const auto refuse = [](const std::string& argument, const std::string& shown, const vola::Error& e) {
    throw vola::InvalidArgument(argument + "=" + shown + " is not a CRS PROJ knows: " + e.what());
  };
  if (epsg != vola::geo::kUnsetEpsg) try {
      (void)vola::geo::crs_wkt("EPSG:" + std::to_string(epsg));
    } catch (const vola::Error& e) {
      refuse("epsg", std::to_string(epsg), e);
    }
  if (!crs_wkt.empty()) try {
      (void)vola::geo::crs_wkt(crs_wkt);
    } catch (const vola::Error& e) {
      refuse("crs_wkt", "'" + crs_wkt.substr(0, 40) + (crs_wkt.size() > 40 ? "...'" : "'"), e);
    }
}

// Points with a coordinate that is not finite (NaN, inf, None in an object array) are
// left out by the build, as the readers leave them out: said with a warning and a count
// (vola convert and Map.insert count them too), never silently.
void warn_not_finite(const vola::PointCloud& cloud) {
  std::size_t not_finite = 0;
  for (std::size_t i = 0; i < cloud.size(); ++i) {
    const double* p = cloud.xyz.data() + 3 * i;
    not_finite += std::isfinite(p[0]) && std::isfinite(p[1]) && std::isfinite(p[2]) ? 0 : 1;
  }
  if (not_finite == 0) return;
  const std::string message = "vola.build: " + std::to_string(not_finite) + " of the " + std::to_string(cloud.size()) +
                              " points have a coordinate that is not finite (NaN or inf) and are left out";
  if (PyErr_WarnEx(PyExc_UserWarning, message.c_str(), 1) != 0) throw py::error_already_set();
}

Tree build_points(const py::handle& points, int depth, double voxel_size, const std::string& quantize,
                  std::optional<std::array<double, 3>> origin, const py::dict& attributes, const py::dict& reductions,
                  std::uint32_t epsg, const std::string& crs_wkt) {
  vola::PointCloud cloud = point_cloud_of(points, attributes);
  for (vola::PointAttribute& a : cloud.attributes) {
    // As the readers reduce a column of that name: classes and ids by majority, ...
    a.reduction = vola::io::default_reduction(a.name);
    if (!reductions.contains(a.name)) continue;
    const py::object given = reductions[py::str(a.name)];
    if (!py::isinstance<py::str>(given))
      throw py::type_error("reductions['" + a.name + "']: a reduction's name (last, mean, max, min, majority), not " +
                           py::cast<std::string>(py::repr(given)));
    const auto name = py::cast<std::string>(given);
    const auto r = vola::parse_reduction(name);
    if (!r) throw vola::InvalidArgument("attribute '" + a.name + "': reduction '" + name + "' is not one of last mean max min majority");
    a.reduction = *r;
  }
  for (const auto& [key, value] : reductions)
    if (!attributes.contains(key)) throw vola::InvalidArgument("reductions names '" + py::cast<std::string>(key) + "', which is not an attribute");
  vola::BuildOptions options;
  options.quantization = parse_quantization(quantize);
  options.depth = depth;
  options.voxel_size = voxel_size;
  if (origin) options.origin = to_point(*origin);
  options.epsg = epsg;
  with_python_names([&] { options.check(); });
  check_crs(epsg, crs_wkt);
  warn_not_finite(cloud);
  py::gil_scoped_release release;
  Tree tree = vola::build(cloud, options);
  georeference_built(tree, epsg, crs_wkt);
  return tree;
}

std::vector<Voxel> voxels_from(const py::handle& input, int depth) {
  const auto xyz = voxel_rows(input, "voxels");
  const std::int64_t side = vola::side_of(depth);
  std::vector<Voxel> voxels(static_cast<std::size_t>(xyz.shape(0)));
  const std::int64_t* p = xyz.data();
  for (std::size_t i = 0; i < voxels.size(); ++i, p += 3) {
    if (p[0] < 0 || p[1] < 0 || p[2] < 0 || p[0] >= side || p[1] >= side || p[2] >= side)
      throw vola::InvalidArgument("voxel " + std::to_string(i) + " (" + std::to_string(p[0]) + ", " + std::to_string(p[1]) +
                                  ", " + std::to_string(p[2]) + ") is outside the depth-" + std::to_string(depth) +
                                  " grid 0.." + std::to_string(side - 1));
    voxels[i] = Voxel{static_cast<std::uint32_t>(p[0]), static_cast<std::uint32_t>(p[1]), static_cast<std::uint32_t>(p[2])};
  }
  return voxels;
}

void check_depth(int depth) {
  if (depth < vola::kMinDepth || depth > vola::kMaxDepth)
    throw vola::InvalidArgument("depth " + std::to_string(depth) + " is outside 1..10");
}

Tree build_voxels(const py::handle& input, int depth) {
  check_depth(depth);
  std::vector<Voxel> voxels = voxels_from(input, depth);
  py::gil_scoped_release release;
  return vola::build_from_voxels(voxels, depth);
}

Tree from_dense(const py::handle& input, std::optional<std::array<double, 3>> origin, std::optional<double> voxel_size,
                int depth) {
  const py::array raw = py::array::ensure(input);
  if (!raw || raw.ndim() != 3) throw py::value_error("from_dense: expected a 3-D array indexed [x, y, z]");
  const auto grid = ensure_array<bool>(raw.attr("astype")(py::dtype::of<bool>(), py::arg("copy") = false));
  if (!grid) throw py::type_error("from_dense: the grid's values cannot be read as booleans");
  const auto largest = std::max({grid.shape(0), grid.shape(1), grid.shape(2), py::ssize_t{1}});
  if (depth == 0)
    for (depth = 1; depth < vola::kMaxDepth && vola::side_of(depth) < largest; ++depth) {
    }
  check_depth(depth);
  if (vola::side_of(depth) < largest)
    throw vola::InvalidArgument("from_dense: a grid of " + std::to_string(largest) + " cells per axis does not fit depth " +
                                std::to_string(depth));
  std::vector<Voxel> voxels;
  {
    py::gil_scoped_release release;
    const bool* cell = grid.data();
    const auto nx = grid.shape(0), ny = grid.shape(1), nz = grid.shape(2);
    for (py::ssize_t x = 0; x < nx; ++x)
      for (py::ssize_t y = 0; y < ny; ++y)
        for (py::ssize_t z = 0; z < nz; ++z, ++cell)
          if (*cell) voxels.push_back(Voxel{static_cast<std::uint32_t>(x), static_cast<std::uint32_t>(y), static_cast<std::uint32_t>(z)});
  }
  Tree tree = vola::build_from_voxels(voxels, depth);
  if (origin || voxel_size) {
    const double size = voxel_size.value_or(1.0);
    if (!(size > 0.0) || !std::isfinite(size)) throw vola::InvalidArgument("from_dense: voxel_size must be finite and > 0");
    const vola::Point o = origin ? to_point(*origin) : vola::Point{0, 0, 0};
    tree.set_frame(vola::Frame{vola::Quantization::grid, o, size});
    vola::Box box{o, o};
    for (int i = 0; i < 3; ++i) box.max[i] += size * static_cast<double>(grid.shape(i));
    tree.georef().bbox = box;
  }
  return tree;
}

Tree convert(const std::filesystem::path& path, int depth, double voxel_size, const std::string& quantize,
             const std::string& format, std::optional<std::uint32_t> epsg, bool solid, bool attributes,
             std::optional<double> dem_base, bool dem_surface_only, std::optional<std::array<double, 3>> origin,
             std::optional<std::array<double, 6>> bbox, int nbits, std::optional<std::array<int, 3>> columns,
             std::vector<int> payload_columns, std::vector<std::string> text_attributes, int skip_lines, bool dense,
             bool compress, const std::optional<std::filesystem::path>& output, const std::string& target_crs,
             std::optional<int> level, const std::string& assign_crs, bool allow_geographic, const std::string& grid,
             std::vector<std::string> filters, bool compress_max, double map_height) {
  vola::ConvertOptions options;
  options.filters = std::move(filters);
  options.format = format;
  if (!quantize.empty()) options.quantization = parse_quantization(quantize);
  options.depth = depth;
  options.voxel_size = voxel_size;
  if (origin) options.origin = to_point(*origin);
  if (bbox) options.bbox = vola::Box{{(*bbox)[0], (*bbox)[1], (*bbox)[2]}, {(*bbox)[3], (*bbox)[4], (*bbox)[5]}};
  options.nbits = nbits;
  options.epsg = epsg;
  options.assign_crs = assign_crs;
  options.target_crs = target_crs;
  options.allow_geographic = allow_geographic;
  options.level = level;
  options.grid = grid;
  options.attributes = attributes;
  options.columns = columns;  // None: by a header's names, else 1 2 3
  options.payload_columns = std::move(payload_columns);
  options.text_attributes = std::move(text_attributes);
  options.skip_lines = skip_lines;
  options.solid = solid;
  options.dem_base = dem_base;
  options.dem_surface_only = dem_surface_only;
  options.map_height = map_height;
  options.dense = dense;
  options.compress = compress;
  options.compress_max = compress_max;
  vola::ConvertReport report;
  std::optional<Tree> tree;
  {
    py::gil_scoped_release release;
    tree = with_python_names([&] {
      // The CLI's refusals first: the input itself as output, or a .vol under another format's name.
      if (output) vola::check_convert_output(path.string(), output->string());
      Tree converted = vola::convert(path.string(), options, interruptible(), &report);
      if (output) vola::write(converted, output->string(), vola::write_options_of(options));
      return converted;
    });
  }
  // What the CLI warns of (a CRS relabelled, z left in feet, voxels in degrees), as warnings.
  for (const std::string& warning : report.warnings)
    if (PyErr_WarnEx(PyExc_UserWarning, warning.c_str(), 1) < 0) throw py::error_already_set();
  // The CLI's summary counts the points left out; here nothing would (vola.build warns of them too).
  const vola::BuildReport& counts = report.build;
  if (counts.points_outside > 0 && counts.points_outside < counts.points_in) {
    const std::string left_out = path.string() + ": " + std::to_string(counts.points_outside) + " of its " +
                                 std::to_string(counts.points_in) + " " + report.unit +
                                 " are left out (not finite, or outside the grid given)";
    if (PyErr_WarnEx(PyExc_UserWarning, left_out.c_str(), 1) < 0) throw py::error_already_set();
  }
  return std::move(*tree);
}

}  // namespace

void bind_building(py::module_& m) {
  m.def("describe_crs", [](const std::string& definition) {
        const vola::geo::CrsDescription d = with_python_names([&] { return vola::geo::describe_crs(definition); });
        py::dict out;
        out["name"] = d.name;
        out["kind"] = d.kind;
        out["epsg"] = d.epsg ? py::object(py::int_(*d.epsg)) : py::object(py::none());
        out["unit"] = d.horizontal_unit;
        out["vertical"] = d.vertical_name.empty() ? py::object(py::none()) : py::object(py::str(d.vertical_name));
        out["vertical_unit"] = d.vertical_unit.empty() ? py::object(py::none()) : py::object(py::str(d.vertical_unit));
        return out;
      }, py::arg("definition"),
      "What PROJ says a CRS is (as `vola info` prints it): {'name', 'kind', 'epsg' (None unless PROJ identifies\n"
      "one with confidence), 'unit' (horizontal: 'metre', 'foot', 'US survey foot', 'degree', ...), 'vertical',\n"
      "'vertical_unit'}. definition: WKT (tree.crs_wkt), 'EPSG:n' or a PROJ string.");
  m.def("build", &build_points, py::arg("points"), py::arg("depth") = 0, py::arg("voxel_size") = 0.0,
        py::arg("quantize") = "grid", py::arg("origin") = py::none(), py::arg("attributes") = py::dict(),
        py::arg("reductions") = py::dict(), py::arg("epsg") = 2000u, py::arg("crs_wkt") = "",
        "Builds a tree from an (N, 3) array of world points.\n"
        "quantize='grid': voxel_size and/or depth; origin defaults to the bbox minimum snapped to the voxel size.\n"
        "quantize='toolkit': the reference's rounding, needs depth.\n"
        "attributes: {name: (N,) array}; the column type follows the dtype; reductions: {name: "
        "'mean'|'max'|'min'|'majority'|'last'}\n"
        "(default by name, as the file readers: classification/class/label, ids such as treeID and cluster/segment/\n"
        "instance by majority, number_of_returns by max, the rest mean).\n"
        "epsg: the header's CRS code; crs_wkt: the CRS as WKT, kept in the file (its EPSG code, when PROJ names\n"
        "one, goes into the header; an epsg naming another CRS is refused); lat_lon is the bbox centre's.");
  m.def("build_from_voxels", &build_voxels, py::arg("voxels"), py::arg("depth"),
        "Builds a tree from an (N, 3) array of integer voxels, each below 4**depth (duplicates allowed).");
  m.def("from_dense", &from_dense, py::arg("grid"), py::arg("origin") = py::none(), py::arg("voxel_size") = py::none(),
        py::arg("depth") = 0, "Builds a tree from a dense 3-D array indexed [x, y, z] (non-zero = occupied).");
  m.def("read", [](const std::filesystem::path& p) { py::gil_scoped_release r; return vola::read(p.string()); }, py::arg("path"),
        "Reads a .vol file into memory, as it is: a state map's voxels are all its known voxels, free ones\n"
        "too (tree.is_state_map), so census() and voxels() count them; vola.open reads its occupied voxels,\n"
        "as every vola command does.");
  m.def("open_mapped", [](const std::filesystem::path& p) { py::gil_scoped_release r; return vola::open_mapped(p.string()); },
        py::arg("path"), "Memory-maps a .vol file, as it is (a state map's free voxels too; see read): a sparse\n"
        "uncompressed file's level words are used in place.");
  m.def("parse", [](py::bytes data, const std::string& name) {
          const std::string bytes = data;
          py::gil_scoped_release release;
          return vola::parse(std::span(reinterpret_cast<const std::uint8_t*>(bytes.data()), bytes.size()), name);
        }, py::arg("data"), py::arg("name") = "<bytes>", "Parses the bytes of a .vol file.");
  m.def(
      "convert", &convert, py::arg("path"), py::arg("depth") = 0, py::arg("voxel_size") = 0.0, py::arg("quantize") = "",
      py::arg("format") = "auto", py::arg("epsg") = py::none(), py::arg("solid") = false, py::arg("attributes") = true,
      py::arg("dem_base") = py::none(), py::arg("dem_surface_only") = false, py::arg("origin") = py::none(),
      py::arg("bbox") = py::none(), py::arg("nbits") = 0, py::arg("columns") = py::none(),
      py::arg("payload_columns") = std::vector<int>{}, py::arg("text_attributes") = std::vector<std::string>{},
      py::arg("skip_lines") = 0, py::arg("dense") = false, py::arg("compress") = false, py::arg("output") = py::none(),
      py::arg("target_crs") = "", py::arg("level") = py::none(), py::arg("assign_crs") = "",
      py::arg("allow_geographic") = false, py::arg("grid") = "", py::arg("filters") = std::vector<std::string>{},
      py::arg("compress_max") = false, py::arg("map_height") = 0.0,
      "Reads any input `vola convert` reads (LAS, text, NPY, PLY, PCD, KITTI, binvox, meshes, DEM, OctoMap .bt/.ot,\n"
      "OpenVDB .vdb) and builds its\n"
      "tree through the same pipeline (LAS streams: memory follows voxels, not points); with output=, also writes\n"
      "it (dense=, compress=, compress_max=: smallest, slower to open). Every `vola convert` option is a keyword: "
      "quantize ('grid', default with\n"
      "voxel_size/origin, or 'toolkit', needs depth), depth, voxel_size, origin=(x, y, z), bbox=(minx, miny, minz,\n"
      "maxx, maxy, maxz) (the box to quantize against instead of the points' bounds, not a crop: toolkit quantization\n"
      "puts points outside it on its border voxels, as the reference clips them, with a warning; grid quantization\n"
      "drops those outside the grid it makes; to cut points, filters=['crop:...']), nbits, epsg, attributes (False: "
      "occupancy only), text input's columns (x y z, from 1),\n"
      "payload_columns, text_attributes=['NAME=COLUMN[:TYPE[:REDUCTION]]', ...], skip_lines; solid (meshes);\n"
      "dem_base, dem_surface_only (DEM); target_crs='EPSG:32610' (or WKT, a PROJ string) reprojects the points\n"
      "first (grid options then in its units); assign_crs= (or epsg=) relabels the input's CRS without moving it;\n"
      "a geographic CRS's degrees are refused as grid voxels unless allow_geographic=True; level=L reads a COPC\n"
      "file's octree down to level L. Voxel grids map cell to voxel unless another grid is asked for;\n"
      "maps (.bt, .ot, .vdb, ROS .yaml) keep their own cells (another voxel_size is refused); map_height=H makes a "
      "ROS\n"
      "map's occupied cells columns H high; grid='NAME' picks a .vdb grid or "
      "an .npz array.\n"
      "filters=['smrf', 'hag', 'where:HeightAboveGround > 2', 'voxel:1', 'outlier', 'crop:X0,Y0,X1,Y1', ...]: point\n"
      "filters run in order before voxelising, as `vola convert --filter/--where/--crop` (docs/FILTERS.md).\n"
      "output= the input itself, or a name with another format's extension (a.las), is refused as the CLI refuses\n"
      "it; what the CLI warns of (a CRS relabelled, heights left in feet) comes as UserWarning.");
  m.def(
      "translate",
      [](const std::filesystem::path& input, const std::filesystem::path& output,
         const std::vector<std::string>& filters, const std::string& format) {
        std::vector<std::string> warnings;
        {
          py::gil_scoped_release release;
          with_python_names([&] {
            const auto stages = vola::filters::parse_stages(filters);
            vola::io::PointEdit edit;
            if (!stages.empty())
              edit = [&](vola::io::PointTable& table) {
                return vola::filters::run_stages(stages, table.cloud, table.epsg, table.wkt).kept;
              };
            warnings = vola::io::translate_points(input.string(), output.string(), {}, edit, format);
          });
        }
        for (const auto& w : warnings)  // what the output cannot hold (a PLY has no CRS)
          if (PyErr_WarnEx(PyExc_UserWarning, w.c_str(), 1) < 0) throw py::error_already_set();
      },
      py::arg("input"), py::arg("output"), py::arg("filters") = std::vector<std::string>{}, py::arg("format") = "auto",
      "Point file to point file, point by point, no voxels (`vola translate`): LAS, LAZ, COPC, PLY, PCD, XYZ,\n"
      "NPY or KITTI in; LAS, LAZ (record for record from LAS/LAZ), PLY or XYZ out, chosen by the extension.\n"
      "filters=['smrf'] etc. as `vola translate --filter` (docs/FILTERS.md): LAS/LAZ out keeps the records left,\n"
      "classification updated. format='nuscenes' (or any name of input_formats()) reads the input by that\n"
      "reader whatever its extension (a Lyft sweep is a plain .bin of five floats a point).");
  m.def("input_formats", [] {
        std::vector<std::pair<std::string, std::vector<std::string>>> out;
        for (const auto& f : vola::io::input_formats()) out.emplace_back(f.name, f.extensions);
        return out;
      }, "(name, extensions) of every input format this build reads.");
  m.def("compression_available", &vola::compression_available, "Whether this build writes zstd-compressed files.");
}

}  // namespace vola::python
