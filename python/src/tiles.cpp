// vola.open_tiles / TileSet: a `vola tile` set through its index.geojson, world queries, tiles
// mapped on demand.
#include "python_support.hpp"

#include <algorithm>
#include <cstdint>
#include <limits>
#include <filesystem>
#include <memory>

#include "vola/tile/tile_set.hpp"

namespace vola::python {

namespace {


// One value of type T per world point (M, 3): answer(lookup) for each point's tile lookup,
// without the GIL; a single point (3,) gives a Python scalar.
template <class T, class Answer>
py::object per_point(const vola::tile::TileSet& tiles, const py::handle& input, Answer&& answer) {
  const auto xyz = rows_of_three<double>(input, "points");
  const auto n = xyz.shape(0);
  py::array_t<T> out(n);
  T* value = out.mutable_data();
  const double* p = xyz.data();
  {
    py::gil_scoped_release release;
    for (py::ssize_t i = 0; i < n; ++i, p += 3) value[i] = answer(tiles.locate(vola::Point{p[0], p[1], p[2]}));
  }
  if (single_row(input)) return py::cast(value[0]);
  return std::move(out);
}

py::object tiles_contain(const vola::tile::TileSet& tiles, const py::handle& input) {
  return per_point<bool>(tiles, input, [](const vola::tile::TileLookup& hit) { return hit.rank.has_value(); });
}

// Attribute `name` at each world point's voxel: NaN where no tile has the voxel.
py::object tiles_values(const vola::tile::TileSet& tiles, const py::handle& input, const std::string& name) {
  const auto& names = tiles.index().attributes;
  if (std::find(names.begin(), names.end(), name) == names.end()) {
    std::string known;
    for (const auto& n : names) known += (known.empty() ? "" : ", ") + n;
    throw py::key_error("no attribute '" + name + "' (the tile set has: " + (known.empty() ? "none" : known) + ")");
  }
  return per_point<double>(tiles, input, [&](const vola::tile::TileLookup& hit) {
    if (!hit.rank) return std::numeric_limits<double>::quiet_NaN();
    const vola::AttributeColumn* column = tiles.tree(hit.tile)->attributes().find(name);
    if (!column) throw vola::FormatError(name, 0, "a tile of the set has no such column, though the index lists it");
    return column->get(*hit.rank);
  });
}

py::list tile_entries(const vola::tile::TileSet& tiles) {
  py::list out;
  for (const auto& e : tiles.index().tiles)
    out.append(py::dict(py::arg("tile") = py::make_tuple(e.tile.i, e.tile.j, e.tile.k), py::arg("file") = e.file,
                        py::arg("points") = e.points, py::arg("voxels") = e.voxels, py::arg("bytes") = e.bytes));
  return out;
}

py::object tile_tree(const vola::tile::TileSet& tiles, std::int32_t i, std::int32_t j, std::int32_t k) {
  const Tree* t = tiles.tree({i, j, k});
  if (!t) return py::none();
  return py::cast(*t);  // shares the mapped words
}


}  // namespace

void bind_tiles(py::module_& m) {
  py::class_<vola::tile::TileSet>(m, "TileSet",
                                  "A tile set written by `vola tile`, opened through its index.geojson; each tile "
                                  "is memory-mapped only when a query first needs it.")
      .def(py::init([](const std::filesystem::path& p) { return std::make_unique<vola::tile::TileSet>(p.string()); }),
           py::arg("index"))
      .def_property_readonly("tile_size", [](const vola::tile::TileSet& t) { return t.grid().tile_size; })
      .def_property_readonly("depth", [](const vola::tile::TileSet& t) { return t.grid().depth; })
      .def_property_readonly("voxel_size", [](const vola::tile::TileSet& t) { return t.grid().voxel_size(); })
      .def_property_readonly("epsg", [](const vola::tile::TileSet& t) -> py::object {
        return t.index().epsg ? py::cast(*t.index().epsg) : py::none();
      })
      .def_property_readonly("tiles_opened", &vola::tile::TileSet::tiles_opened, "How many tiles queries have mapped so far.")
      .def("__len__", [](const vola::tile::TileSet& t) { return t.index().tiles.size(); })
      .def("__repr__",
           [](const vola::tile::TileSet& t) {
             std::string crs = t.index().epsg ? " EPSG:" + std::to_string(*t.index().epsg) : "";
             return "<vola.TileSet tiles=" + std::to_string(t.index().tiles.size()) +
                    " tile_size=" + py::cast<std::string>(py::repr(py::float_(t.grid().tile_size))) +
                    " depth=" + std::to_string(t.grid().depth) +
                    " voxel_size=" + py::cast<std::string>(py::repr(py::float_(t.grid().voxel_size()))) + crs + ">";
           })
      .def_property_readonly("attributes", [](const vola::tile::TileSet& t) { return t.index().attributes; },
                             "The attribute columns every tile carries (e.g. ['red', ..., 'classification']).")
      .def("values", &tiles_values, py::arg("points"), py::arg("name"),
           "World points (M, 3) -> (M,) float64: attribute `name` of each point's voxel, NaN where no tile "
           "has the voxel. Opens only the tiles hit.")
      .def("tiles", &tile_entries, "Every tile: {tile: (i, j, k), file, points, voxels, bytes}, from the index.")
      .def("contains", &tiles_contain, py::arg("points"),
           "World points (M, 3) -> (M,) bool: is each point's voxel occupied? Opens only the tiles hit.")
      .def("tile", &tile_tree, py::arg("i"), py::arg("j"), py::arg("k"),
           "The Tree of tile (i, j, k), memory-mapped, or None when the set has no such tile.");
  m.def("open_tiles", [](const std::filesystem::path& p) { return std::make_unique<vola::tile::TileSet>(p.string()); },
        py::arg("index"), "Opens a tile set through its index.geojson (no tile is mapped yet).");
}

}  // namespace vola::python
