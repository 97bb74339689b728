// vola.Tree: its properties, voxels, lookups, views of its words and columns, writing.
#include "python_support.hpp"

#include <cstdint>
#include <filesystem>

#include "vola/file.hpp"
#include "vola/map/state_map.hpp"

namespace vola::python {

namespace {

// ---- reading a tree ----

// `level` checked against the tree's (an index out of range read past the level counts);
// -1, where the finest is the default, stands for it.
int checked_level(const Tree& tree, int level, bool minus_one_is_finest) {
  if (minus_one_is_finest && level == -1) return tree.depth() - 1;
  if (level < 0 || level >= tree.depth())
    throw vola::InvalidArgument("level " + std::to_string(level) + " is outside 0.." + std::to_string(tree.depth() - 1) +
                                (minus_one_is_finest ? " (or -1: the voxels)" : ""));
  return level;
}

py::array_t<std::uint32_t> voxels_of(const Tree& tree, int level) {
  level = checked_level(tree, level, true);
  const auto n = static_cast<py::ssize_t>(tree.node_count(level));
  py::array_t<std::uint32_t> out({n, py::ssize_t{3}});
  std::uint32_t* p = out.mutable_data();
  std::uint32_t* const end = p + 3 * n;
  {
    py::gil_scoped_release release;
    // A mapped file rewritten meanwhile may hold more voxels than the count read at its
    // opening: the rows stop at the array's end (the wrapper's check_mapped then fails the
    // call) rather than run past it.
    tree.for_each_node(level, [&](const Voxel& v) {
      if (p == end) return;
      p[0] = v.x;
      p[1] = v.y;
      p[2] = v.z;
      p += 3;
    });
    std::fill(p, end, 0u);  // fewer: a cut mapping's zeros
  }
  return out;
}

// The tree's world placement, for centres and world points. A tree with no grid frame
// and a bbox of no extent (built from voxel indices) has none: the toolkit's rule would
// put every voxel at one point and every world point in voxel 0.
vola::Quantizer placed_quantizer(const Tree& tree, const char* what) {
  const auto frame = tree.stored_frame();
  const vola::Box& box = tree.georef().bbox;
  const bool no_extent = box.max[0] <= box.min[0] && box.max[1] <= box.min[1] && box.max[2] <= box.min[2];
  if ((!frame || frame->quantization != vola::Quantization::grid) && no_extent && tree.voxel_count() > 1)
    throw vola::InvalidArgument(std::string(what) +
                                ": this tree has no world placement (built from voxel indices, with no grid frame "
                                "and an empty bbox); its voxel indices are its only coordinates. Give it one with "
                                "vola.from_dense(grid, origin=..., voxel_size=...) or vola.build(points, ...)");
  return tree.quantizer();
}

py::array_t<double> centers_of(const Tree& tree) {
  const auto n = static_cast<py::ssize_t>(tree.voxel_count());
  py::array_t<double> out({n, py::ssize_t{3}});
  double* p = out.mutable_data();
  double* const end = p + 3 * n;
  const vola::Quantizer quantizer = placed_quantizer(tree, "centers");
  {
    py::gil_scoped_release release;
    tree.for_each_voxel([&](const Voxel& v) {
      if (p == end) return;  // a rewritten mapping, as in voxels_of
      const vola::Point c = quantizer.center(v);
      p[0] = c[0];
      p[1] = c[1];
      p[2] = c[2];
      p += 3;
    });
    std::fill(p, end, 0.0);  // fewer: a cut mapping's zeros
  }
  return out;
}

py::object contains(const Tree& tree, const py::handle& input) {
  const auto xyz = voxel_rows(input, "contains");
  const auto n = xyz.shape(0);
  py::array_t<bool> out(n);
  bool* hit = out.mutable_data();
  const std::int64_t* p = xyz.data();
  const bool state_map = vola::map::is_state_map(tree);
  {
    py::gil_scoped_release release;
    constexpr std::int64_t limit = std::numeric_limits<std::uint32_t>::max();
    for (py::ssize_t i = 0; i < n; ++i, p += 3) {
      const bool representable = p[0] >= 0 && p[1] >= 0 && p[2] >= 0 && p[0] <= limit && p[1] <= limit && p[2] <= limit;
      if (!representable) {
        hit[i] = false;
      } else if (state_map) {  // occupied, not merely known (a state map holds its free voxels too)
        const vola::Voxel v{static_cast<std::uint32_t>(p[0]), static_cast<std::uint32_t>(p[1]),
                            static_cast<std::uint32_t>(p[2])};
        hit[i] = vola::map::state_at(tree, v) == vola::map::VoxelState::occupied;
      } else {
        hit[i] = tree.contains(static_cast<std::uint32_t>(p[0]), static_cast<std::uint32_t>(p[1]),
                               static_cast<std::uint32_t>(p[2]));
      }
    }
  }
  if (single_row(input)) return py::bool_(hit[0]);
  return std::move(out);
}

py::object rank_of(const Tree& tree, const py::handle& input) {
  const auto xyz = voxel_rows(input, "rank");
  const auto n = xyz.shape(0);
  py::array_t<std::int64_t> out(n);
  std::int64_t* rank = out.mutable_data();
  const std::int64_t* p = xyz.data();
  {
    py::gil_scoped_release release;
    constexpr std::int64_t limit = std::numeric_limits<std::uint32_t>::max();
    for (py::ssize_t i = 0; i < n; ++i, p += 3) {
      rank[i] = -1;
      if (p[0] < 0 || p[1] < 0 || p[2] < 0 || p[0] > limit || p[1] > limit || p[2] > limit) continue;
      const auto r = tree.rank(Voxel{static_cast<std::uint32_t>(p[0]), static_cast<std::uint32_t>(p[1]), static_cast<std::uint32_t>(p[2])});
      if (r) rank[i] = static_cast<std::int64_t>(*r);
    }
  }
  if (single_row(input)) return py::int_(rank[0]);
  return std::move(out);
}

// World points -> voxel indices, and which of them fall on the grid.
py::tuple world_to_voxel(const Tree& tree, const py::handle& input) {
  const auto xyz = rows_of_three<double>(input, "points");
  const auto n = xyz.shape(0);
  py::array_t<std::int64_t> voxels({n, py::ssize_t{3}});
  py::array_t<bool> inside(n);
  std::int64_t* v = voxels.mutable_data();
  bool* ok = inside.mutable_data();
  const double* p = xyz.data();
  const vola::Quantizer quantizer = placed_quantizer(tree, "world_to_voxel");
  // Without a grid frame, a bbox of no extent along an axis (one point, or coincident
  // ones, placed by the toolkit's rule) gives every coordinate on that axis voxel 0:
  // only the bbox's own coordinate lies in it (every world point was "inside" voxel 0).
  const auto frame = tree.stored_frame();
  const bool toolkit = !frame || frame->quantization != vola::Quantization::grid;
  const vola::Box box = tree.georef().bbox;
  const auto on_flat_axes = [&](const double* q) {
    for (int a = 0; a < 3; ++a)
      if (toolkit && !(box.max[a] > box.min[a]) && q[a] != box.min[a]) return false;
    return true;
  };
  {
    py::gil_scoped_release release;
    for (py::ssize_t i = 0; i < n; ++i, p += 3, v += 3) {
      Voxel cell;
      ok[i] = quantizer.to_voxel(vola::Point{p[0], p[1], p[2]}, cell) && on_flat_axes(p);
      v[0] = ok[i] ? std::int64_t{cell.x} : -1;
      v[1] = ok[i] ? std::int64_t{cell.y} : -1;
      v[2] = ok[i] ? std::int64_t{cell.z} : -1;
    }
  }
  return py::make_tuple(voxels, inside);
}

py::array_t<bool> to_dense(const Tree& tree, int level, std::uint64_t max_cells) {
  level = checked_level(tree, level, true);
  const std::uint64_t side = vola::side_of(level + 1);
  if (side > 4096 || side * side * side > max_cells)
    throw vola::InvalidArgument("to_dense: a " + std::to_string(side) + "^3 grid is more than max_cells=" + std::to_string(max_cells) +
                                " cells; pass a coarser level or a larger max_cells");
  const auto s = static_cast<py::ssize_t>(side);
  py::array_t<bool> out({s, s, s});
  bool* cells = out.mutable_data();
  {
    py::gil_scoped_release release;
    std::fill(cells, cells + side * side * side, false);
    tree.for_each_node(level, [&](const Voxel& v) { cells[(v.x * side + v.y) * side + v.z] = true; });
  }
  return out;
}

py::array level_words(const py::object& self, int level, bool payload) {
  const Tree& tree = py::cast<const Tree&>(self);
  level = checked_level(tree, level, false);
  const auto words = payload ? tree.payload(level) : tree.occupancy(level);
  return readonly_view(py::dtype::of<std::uint64_t>(), {static_cast<py::ssize_t>(words.size())}, words.data(), self);
}

py::array attribute_view(const py::object& self, const std::string& name) {
  const Tree& tree = py::cast<const Tree&>(self);
  const vola::AttributeColumn* column = tree.attributes().find(name);
  if (!column) {
    std::string known;
    for (const auto& c : tree.attributes().columns()) known += (known.empty() ? "" : ", ") + c.name();
    throw py::key_error("no attribute '" + name + "' (the tree has: " + (known.empty() ? "none" : known) + ")");
  }
  return readonly_view(dtype_of(column->type()), {static_cast<py::ssize_t>(column->size())}, column->bytes().data(), self);
}

py::dict attributes_of(const py::object& self) {
  py::dict out;
  for (const auto& column : py::cast<const Tree&>(self).attributes().columns())
    out[py::str(column.name())] = attribute_view(self, column.name());
  return out;
}

vola::WriteOptions write_options(bool dense, bool compress, bool compress_max) {
  if (dense && (compress || compress_max)) throw py::value_error("compressed files are sparse: not with dense=True");
  vola::WriteOptions options;
  options.layout = dense ? vola::Layout::dense : vola::Layout::sparse;
  options.compress = compress || compress_max;
  options.mix_occupancy_models = compress_max;
  return options;
}

py::bytes to_bytes(const Tree& tree, bool dense, bool compress, bool compress_max) {
  const vola::WriteOptions options = write_options(dense, compress, compress_max);
  std::vector<std::uint8_t> bytes;
  {
    py::gil_scoped_release release;  // compressing takes seconds for a large tree
    bytes = vola::serialize(tree, options);
  }
  return py::bytes(reinterpret_cast<const char*>(bytes.data()), bytes.size());
}

void write_file(const Tree& tree, const std::filesystem::path& path, bool dense, bool compress, bool compress_max) {
  const vola::WriteOptions options = write_options(dense, compress, compress_max);
  py::gil_scoped_release release;
  vola::write(tree, path.string(), options);
}

Tree level_of_detail(const Tree& tree, int depth) {
  if (depth < 1 || depth > tree.depth())
    throw vola::InvalidArgument("level_of_detail: depth " + std::to_string(depth) + " is outside 1.." + std::to_string(tree.depth()));
  return tree.level_of_detail(depth);
}


std::string repr(const Tree& tree) {
  const vola::Frame frame = tree.frame();
  std::string s = "<vola.Tree depth=" + std::to_string(tree.depth()) + " voxels=" + std::to_string(tree.voxel_count()) +
                  " " + (frame.quantization == vola::Quantization::grid ? "grid" : "toolkit") +
                  " voxel_size=" + py::cast<std::string>(py::repr(py::float_(frame.voxel_size)));
  if (!tree.attributes().empty()) {
    s += " attributes=";
    for (std::size_t i = 0; i < tree.attributes().size(); ++i)
      s += (i ? "," : "") + tree.attributes().columns()[i].name();
  }
  return s + (tree.is_mapped() ? " mapped>" : ">");
}


}  // namespace

py::class_<Tree> bind_tree(py::module_& m) {
  return py::class_<Tree>(m, "Tree", "An immutable VOLA tree: levels of 64-bit occupancy words, one per 4x4x4 block.")
      .def_property_readonly("depth", &Tree::depth, "Number of levels (1..10); the grid has 4**depth voxels per axis.")
      .def_property_readonly("side", &Tree::side, "Voxels per axis: 4**depth.")
      .def_property_readonly("voxel_count", &Tree::voxel_count, "Number of occupied voxels.")
      .def("__len__", [](const Tree& t) { return t.voxel_count(); })
      .def("__repr__", &repr)
      .def_property_readonly("is_mapped", &Tree::is_mapped, "True when the level words live in a file mapping.")
      .def(
          "check_mapped", [](const Tree& t) { vola::check_mapped(t); },
          "Raises vola.IoError when the file this tree maps was cut (truncated, or copied over in place) since it\n"
          "was opened: the mapping then reads zeros. Every Tree method and vola function does this before and\n"
          "after its work (looking at the file's size and time at most once a millisecond per file); numpy views\n"
          "of the levels (occupancy(), payload()) cannot, so call it after using them.")
      // The per-call check of vola/__init__.py's wrapper: a stat per call doubled the
      // cost of a one-point query on a mapped tree (2.8 -> 7 us), so it looks at most once
      // a millisecond; a cut is still found at once.
      .def(
          "_check_mapped_often", [](const Tree& t) { vola::check_mapped_often(t); },
          "check_mapped, looking at the file at most once a millisecond (the methods' own check).")
      .def_property_readonly(
          "is_state_map", [](const Tree& t) { return t.payload_meaning() == vola::PayloadMeaning::occupancy_state; },
          "True for a state map (vola map, vola.Map.save): known voxels, payload bit set = occupied.")
      .def_property_readonly("memory_bytes", &Tree::memory_bytes, "Bytes held in memory (mapped words not counted).")
      .def(
          "node_count", [](const Tree& tree, int level) { return tree.node_count(checked_level(tree, level, false)); },
          py::arg("level"), "Occupied cells of `level` (depth - 1 = voxels).")
      .def_property_readonly(
          "quantization",
          [](const Tree& t) { return t.frame().quantization == vola::Quantization::grid ? "grid" : "toolkit"; },
          "'grid' (floor((p - origin) / voxel_size)) or 'toolkit' (the reference's rounding).")
      .def_property_readonly(
          "origin", [](const Tree& t) { return t.frame().origin; }, "World position of voxel (0, 0, 0)'s corner.")
      .def_property_readonly(
          "voxel_size", [](const Tree& t) { return t.frame().voxel_size; }, "World edge of one voxel.")
      .def_property_readonly(
          "epsg", [](const Tree& t) { return t.georef().epsg; },
          "EPSG code in the header (2000 = the reference's default).")
      .def_property_readonly(
          "crs_wkt", [](const Tree& t) { return t.georef().crs_wkt; }, "The CRS as WKT ('' when unknown).")
      .def_property_readonly(
          "bbox", [](const Tree& t) { return py::make_tuple(t.georef().bbox.min, t.georef().bbox.max); },
          "(min, max) of the input points in world coordinates, as the header records it.")
      .def_property_readonly(
          "lat_lon", [](const Tree& t) { return py::make_tuple(t.georef().lat, t.georef().lon); },
          "WGS84 latitude and longitude of the bbox centre (0, 0 when unknown).")
      .def_property_readonly(
          "attribute_names",
          [](const Tree& t) {
            // Bytes that are not UTF-8 (a name in a hostile file) become U+FFFD rather than
            // a UnicodeDecodeError; the readers write UTF-8 names.
            py::list names;
            for (const auto& c : t.attributes().columns()) {
              const std::string& n = c.name();
              PyObject* text = PyUnicode_DecodeUTF8(n.data(), static_cast<Py_ssize_t>(n.size()), "replace");
              if (!text) throw py::error_already_set();
              names.append(py::reinterpret_steal<py::str>(text));
            }
            return names;
          },
          "Names of the per-voxel attribute columns.")
      .def("contains", &contains, py::arg("voxels"),
           "Occupancy of integer voxels: an (M, 3) array gives an (M,) bool array, one (3,) row gives a bool\n"
           "(of a state map, whether the voxel is occupied: its free voxels are False).\n"
           "Voxels off the grid (negative, >= side) are False; floats that are not whole numbers raise\n"
           "ValueError (world coordinates go through world_to_voxel first). Runs in C++ without the GIL.")
      .def("rank", &rank_of, py::arg("voxels"),
           "Index of each voxel among all voxels in key order (its attribute row), -1 when empty.")
      .def("voxels", &voxels_of, py::arg("level") = -1,
           "Occupied voxels as an (N, 3) uint32 array in key order (rank order); `level` < depth - 1 gives the\n"
           "occupied cells of that coarser level.")
      .def("centers", &centers_of, "World coordinates of the voxel centres, (N, 3) float64 in rank order.")
      .def("world_to_voxel", &world_to_voxel, py::arg("points"),
           "World points (M, 3) -> (voxels (M, 3) int64, inside (M,) bool); voxels off the grid are -1.")
      .def("to_dense", &to_dense, py::arg("level") = -1, py::arg("max_cells") = std::uint64_t{1} << 30,
           "A dense bool grid indexed [x, y, z] of `level` (default: the voxels). Refuses grids above max_cells.")
      .def(
          "occupancy", [](const py::object& self, int level) { return level_words(self, level, false); },
          py::arg("level"),
          "The occupancy words of `level` as a read-only uint64 view (of the file mapping for a mapped tree).")
      .def(
          "payload", [](const py::object& self, int level) { return level_words(self, level, true); }, py::arg("level"),
          "The payload words of `level` (empty without payload) as a read-only uint64 view.")
      .def("attribute", &attribute_view, py::arg("name"),
           "Attribute column `name` as a read-only view, one value per voxel in rank order. KeyError if missing.")
      .def("attributes", &attributes_of, "Every attribute column: {name: read-only array in rank order}.")
      .def("level_of_detail", &level_of_detail, py::arg("depth"),
           "The first `depth` levels as a coarser tree (shares the words; voxel size grows 4x per level dropped).")
      .def("write", &write_file, py::arg("path"), py::arg("dense") = false, py::arg("compress") = false,
           py::arg("compress_max") = false,
           "Writes a .vol file (through a temporary file and a rename). dense: the reference's dense layout\n"
           "(depth <= 5); compress: compressed levels and attributes (a version-2 file only vola reads);\n"
           "compress_max: as compress with mixed occupancy models (about a tenth smaller, slower to open).")
      .def("to_bytes", &to_bytes, py::arg("dense") = false, py::arg("compress") = false,
           py::arg("compress_max") = false, "The .vol file's bytes.")
      // Pickled as its .vol bytes (what the file would hold: levels, attributes, CRS), so
      // trees travel to multiprocessing workers and into caches.
      .def(py::pickle([](const Tree& t) { return to_bytes(t, false, false, false); },
                      [](const py::bytes& data) {
                        const std::string bytes = data;
                        return vola::parse(std::span(reinterpret_cast<const std::uint8_t*>(bytes.data()), bytes.size()),
                                           "<pickle>");
                      }));
}

}  // namespace vola::python
