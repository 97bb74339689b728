// The vola Python module (vola._vola): the whole pybind11 surface in this one file, so
// that the heavy pybind11 headers compile once. Arrays come in as numpy arrays (converted
// only when their dtype or layout differs) and go out as numpy arrays; level words and
// attribute columns go out as read-only views that keep their tree alive (a mapped
// tree's words are then views of the file mapping).
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>
#include <pybind11/stl/filesystem.h>

#include <cmath>
#include <cstdint>
#include <filesystem>
#include <limits>
#include <optional>
#include <string>
#include <vector>

#include "vola/tile/tile_set.hpp"
#include "vola/analysis/census.hpp"
#include "vola/analysis/components.hpp"
#include "vola/builder.hpp"
#include "vola/convert.hpp"
#include "vola/error.hpp"
#include "vola/file.hpp"
#include "vola/io/input.hpp"
#include "vola/raycast/path_planner.hpp"
#include "vola/raycast/ray_caster.hpp"
#include "vola/raycast/world.hpp"
#include "vola/tree.hpp"

namespace py = pybind11;

namespace {

using vola::Tree;
using vola::Voxel;

template <class T>
using CArray = py::array_t<T, py::array::c_style | py::array::forcecast>;

// A numpy array that owns `values` (moved, not copied).
template <class T>
py::array_t<T> owning_array(std::vector<T>&& values, std::vector<py::ssize_t> shape) {
  auto* heap = new std::vector<T>(std::move(values));
  py::capsule owner(heap, [](void* p) { delete static_cast<std::vector<T>*>(p); });
  return py::array_t<T>(shape, heap->data(), owner);
}

// A read-only view of `count` items at `data`, kept alive by `owner`.
py::array readonly_view(py::dtype dtype, std::vector<py::ssize_t> shape, const void* data, py::handle owner) {
  py::array view(dtype, shape, data, owner);
  py::detail::array_proxy(view.ptr())->flags &= ~py::detail::npy_api::NPY_ARRAY_WRITEABLE_;
  return view;
}

// (N, 3) from an array of N rows of three, or a single row of three (N = 1).
template <class T>
CArray<T> rows_of_three(const py::handle& input, const char* what) {
  auto array = CArray<T>::ensure(input);
  if (!array) throw py::type_error(std::string(what) + ": expected an array of shape (N, 3)");
  if (array.ndim() == 1 && array.shape(0) == 3) array = array.reshape({py::ssize_t{1}, py::ssize_t{3}});
  if (array.ndim() != 2 || array.shape(1) != 3)
    throw py::value_error(std::string(what) + ": expected shape (N, 3), got " +
                          std::string(py::str(py::tuple(py::cast(std::vector<py::ssize_t>(
                              array.shape(), array.shape() + array.ndim()))))));
  return array;
}

bool single_row(const py::handle& input) {
  return py::array::ensure(input) && py::array::ensure(input).ndim() == 1;
}

vola::ValueType value_type_of(const py::dtype& dtype) {
  const char kind = dtype.kind();
  const auto size = dtype.itemsize();
  if (kind == 'u') return size == 1 ? vola::ValueType::u8 : size == 2 ? vola::ValueType::u16 : size == 4 ? vola::ValueType::u32 : vola::ValueType::u64;
  if (kind == 'i') return size == 1 ? vola::ValueType::i8 : size == 2 ? vola::ValueType::i16 : size == 4 ? vola::ValueType::i32 : vola::ValueType::i64;
  if (kind == 'b') return vola::ValueType::u8;
  if (kind == 'f') return size <= 4 ? vola::ValueType::f32 : vola::ValueType::f64;
  throw py::type_error("attribute dtype " + py::cast<std::string>(dtype.attr("name")) + " is not a number type");
}

py::dtype dtype_of(vola::ValueType type) {
  switch (type) {
    case vola::ValueType::u8: return py::dtype::of<std::uint8_t>();
    case vola::ValueType::u16: return py::dtype::of<std::uint16_t>();
    case vola::ValueType::u32: return py::dtype::of<std::uint32_t>();
    case vola::ValueType::u64: return py::dtype::of<std::uint64_t>();
    case vola::ValueType::i8: return py::dtype::of<std::int8_t>();
    case vola::ValueType::i16: return py::dtype::of<std::int16_t>();
    case vola::ValueType::i32: return py::dtype::of<std::int32_t>();
    case vola::ValueType::i64: return py::dtype::of<std::int64_t>();
    case vola::ValueType::f32: return py::dtype::of<float>();
    case vola::ValueType::f64: return py::dtype::of<double>();
  }
  throw vola::InvalidArgument("unknown attribute type");
}

vola::Quantization parse_quantization(const std::string& name) {
  if (name == "grid") return vola::Quantization::grid;
  if (name == "toolkit") return vola::Quantization::toolkit;
  throw vola::InvalidArgument("quantize '" + name + "': expected 'grid' or 'toolkit'");
}

vola::Point to_point(const std::array<double, 3>& p) { return vola::Point{p[0], p[1], p[2]}; }

// The library names options as its structs do; Python's keywords are the same names but
// for quantize. Runs `body`, rethrowing an OptionError in the keywords' words.
template <class Body>
auto with_python_names(Body&& body) {
  const auto keyword = [](const std::string& option) { return option == "quantization" ? std::string("quantize") : option; };
  try {
    return body();
  } catch (const vola::OptionError& e) {
    std::string cause = e.cause();
    for (auto open = cause.find('`'); open != std::string::npos; open = cause.find('`', open)) {
      const auto close = cause.find('`', open + 1);
      if (close == std::string::npos) break;
      const std::string name = keyword(cause.substr(open + 1, close - open - 1));
      cause.replace(open, close - open + 1, name);
      open += name.size();
    }
    throw vola::InvalidArgument(keyword(e.option()) + ": " + cause);
  }
}

// ---- building ----

Tree build_points(const py::handle& points, int depth, double voxel_size, const std::string& quantize,
                  std::optional<std::array<double, 3>> origin, const py::dict& attributes, const py::dict& reductions,
                  std::uint32_t epsg) {
  const auto xyz = rows_of_three<double>(points, "points");
  const auto n = static_cast<std::size_t>(xyz.shape(0));
  vola::PointCloud cloud;
  cloud.xyz.assign(xyz.data(), xyz.data() + 3 * n);
  for (const auto& [key, value] : attributes) {
    vola::PointAttribute a;
    a.name = py::cast<std::string>(key);
    const py::array raw = py::array::ensure(value);
    if (!raw) throw py::type_error("attribute '" + a.name + "': expected an array");
    a.type = value_type_of(raw.dtype());
    const auto column = CArray<double>::ensure(raw);
    if (column.ndim() != 1 || static_cast<std::size_t>(column.shape(0)) != n)
      throw vola::InvalidArgument("attribute '" + a.name + "': expected one value per point (" + std::to_string(n) +
                                  "), got shape " + std::string(py::str(raw.attr("shape"))));
    a.values.assign(column.data(), column.data() + n);
    a.reduction = vola::Reduction::mean;
    if (reductions.contains(key)) {
      const auto name = py::cast<std::string>(reductions[key]);
      const auto r = vola::parse_reduction(name);
      if (!r) throw vola::InvalidArgument("attribute '" + a.name + "': reduction '" + name + "' is not one of last mean max min majority");
      a.reduction = *r;
    }
    cloud.attributes.push_back(std::move(a));
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
  py::gil_scoped_release release;
  Tree tree = vola::build(cloud, options);
  tree.georef().epsg = epsg;
  return tree;
}

std::vector<Voxel> voxels_from(const py::handle& input, int depth) {
  const auto xyz = rows_of_three<std::int64_t>(input, "voxels");
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
  const auto grid = CArray<bool>::ensure(raw.attr("astype")(py::dtype::of<bool>(), py::arg("copy") = false));
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

// ---- reading a tree ----

py::array_t<std::uint32_t> voxels_of(const Tree& tree, int level) {
  if (level < 0) level = tree.depth() - 1;
  if (level >= tree.depth()) throw vola::InvalidArgument("level " + std::to_string(level) + " is outside 0.." + std::to_string(tree.depth() - 1));
  const auto n = static_cast<py::ssize_t>(tree.node_count(level));
  py::array_t<std::uint32_t> out({n, py::ssize_t{3}});
  std::uint32_t* p = out.mutable_data();
  {
    py::gil_scoped_release release;
    tree.for_each_node(level, [&](const Voxel& v) {
      p[0] = v.x;
      p[1] = v.y;
      p[2] = v.z;
      p += 3;
    });
  }
  return out;
}

py::array_t<double> centers_of(const Tree& tree) {
  const auto n = static_cast<py::ssize_t>(tree.voxel_count());
  py::array_t<double> out({n, py::ssize_t{3}});
  double* p = out.mutable_data();
  const vola::Quantizer quantizer = tree.quantizer();
  {
    py::gil_scoped_release release;
    tree.for_each_voxel([&](const Voxel& v) {
      const vola::Point c = quantizer.center(v);
      p[0] = c[0];
      p[1] = c[1];
      p[2] = c[2];
      p += 3;
    });
  }
  return out;
}

py::object contains(const Tree& tree, const py::handle& input) {
  const auto xyz = rows_of_three<std::int64_t>(input, "contains");
  const auto n = xyz.shape(0);
  py::array_t<bool> out(n);
  bool* hit = out.mutable_data();
  const std::int64_t* p = xyz.data();
  {
    py::gil_scoped_release release;
    constexpr std::int64_t limit = std::numeric_limits<std::uint32_t>::max();
    for (py::ssize_t i = 0; i < n; ++i, p += 3) {
      const bool representable = p[0] >= 0 && p[1] >= 0 && p[2] >= 0 && p[0] <= limit && p[1] <= limit && p[2] <= limit;
      hit[i] = representable && tree.contains(static_cast<std::uint32_t>(p[0]), static_cast<std::uint32_t>(p[1]),
                                              static_cast<std::uint32_t>(p[2]));
    }
  }
  if (single_row(input)) return py::bool_(hit[0]);
  return std::move(out);
}

py::object rank_of(const Tree& tree, const py::handle& input) {
  const auto xyz = rows_of_three<std::int64_t>(input, "rank");
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
  const vola::Quantizer quantizer = tree.quantizer();
  {
    py::gil_scoped_release release;
    for (py::ssize_t i = 0; i < n; ++i, p += 3, v += 3) {
      Voxel cell;
      ok[i] = quantizer.to_voxel(vola::Point{p[0], p[1], p[2]}, cell);
      v[0] = ok[i] ? std::int64_t{cell.x} : -1;
      v[1] = ok[i] ? std::int64_t{cell.y} : -1;
      v[2] = ok[i] ? std::int64_t{cell.z} : -1;
    }
  }
  return py::make_tuple(voxels, inside);
}

py::array_t<bool> to_dense(const Tree& tree, int level, std::uint64_t max_cells) {
  if (level < 0) level = tree.depth() - 1;
  if (level >= tree.depth()) throw vola::InvalidArgument("level " + std::to_string(level) + " is outside 0.." + std::to_string(tree.depth() - 1));
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
  if (level < 0 || level >= tree.depth())
    throw vola::InvalidArgument("level " + std::to_string(level) + " is outside 0.." + std::to_string(tree.depth() - 1));
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

py::bytes to_bytes(const Tree& tree, bool dense, bool compress) {
  vola::WriteOptions options;
  options.layout = dense ? vola::Layout::dense : vola::Layout::sparse;
  options.compress = compress;
  const auto bytes = vola::serialize(tree, options);
  return py::bytes(reinterpret_cast<const char*>(bytes.data()), bytes.size());
}

void write_file(const Tree& tree, const std::filesystem::path& path, bool dense, bool compress) {
  vola::WriteOptions options;
  options.layout = dense ? vola::Layout::dense : vola::Layout::sparse;
  options.compress = compress;
  py::gil_scoped_release release;
  vola::write(tree, path.string(), options);
}

Tree level_of_detail(const Tree& tree, int depth) {
  if (depth < 1 || depth > tree.depth())
    throw vola::InvalidArgument("level_of_detail: depth " + std::to_string(depth) + " is outside 1.." + std::to_string(tree.depth()));
  return tree.level_of_detail(depth);
}

// ---- analysis, rays, paths ----

py::dict components(const Tree& tree, int connectivity) {
  const auto kind = vola::analysis::parse_connectivity(connectivity);
  vola::analysis::ComponentLabels labels;
  {
    py::gil_scoped_release release;
    labels = vola::analysis::label_components(tree, kind);
  }
  const auto k = static_cast<py::ssize_t>(labels.components.size());
  py::array_t<std::uint64_t> sizes(k), first(k);
  py::array_t<std::uint32_t> lo({k, py::ssize_t{3}}), hi({k, py::ssize_t{3}});
  py::array_t<double> centroid({k, py::ssize_t{3}});
  for (py::ssize_t i = 0; i < k; ++i) {
    const auto& c = labels.components[static_cast<std::size_t>(i)];
    sizes.mutable_at(i) = c.voxels;
    first.mutable_at(i) = c.first_rank;
    lo.mutable_at(i, 0) = c.min.x, lo.mutable_at(i, 1) = c.min.y, lo.mutable_at(i, 2) = c.min.z;
    hi.mutable_at(i, 0) = c.max.x, hi.mutable_at(i, 1) = c.max.y, hi.mutable_at(i, 2) = c.max.z;
    for (int a = 0; a < 3; ++a) centroid.mutable_at(i, a) = c.centroid[a];
  }
  const auto n = static_cast<py::ssize_t>(labels.label.size());
  py::dict out;
  out["labels"] = owning_array(std::move(labels.label), {n});
  out["sizes"] = sizes;
  out["min"] = lo;
  out["max"] = hi;
  out["centroid"] = centroid;
  out["first_rank"] = first;
  return out;
}

py::dict census(const Tree& tree, int bins) {
  vola::analysis::CensusOptions options;
  options.bins = bins;
  vola::analysis::Census c;
  {
    py::gil_scoped_release release;
    c = vola::analysis::take_census(tree, options);
  }
  auto histogram = [](const vola::analysis::Histogram& h) {
    py::dict d;
    d["min"] = h.min;
    d["max"] = h.max;
    d["counts"] = py::array_t<std::uint64_t>(static_cast<py::ssize_t>(h.counts.size()), h.counts.data());
    return d;
  };
  py::list levels;
  for (const auto& l : c.levels) {
    py::dict d;
    d["blocks"] = l.blocks;
    d["cells"] = l.cells;
    d["fill"] = l.fill;
    levels.append(d);
  }
  py::list attributes;
  for (const auto& a : c.attributes) {
    py::dict d;
    d["name"] = a.name;
    d["count"] = a.count;
    d["mean"] = a.mean;
    d["histogram"] = histogram(a.histogram);
    py::list classes;
    for (const auto& k : a.classes)
      classes.append(py::make_tuple(k.code, std::string(vola::analysis::asprs_class_name(k.code)), k.voxels));
    d["classes"] = classes;
    attributes.append(d);
  }
  py::dict out;
  out["depth"] = c.depth;
  out["voxels"] = c.voxels;
  out["levels"] = levels;
  out["voxel_size"] = c.voxel_size ? py::object(py::float_(*c.voxel_size)) : py::object(py::none());
  out["volume"] = c.voxel_size ? py::object(py::float_(c.volume())) : py::object(py::none());
  out["columns"] = c.columns;
  out["footprint_area"] = c.voxel_size ? py::object(py::float_(c.footprint_area())) : py::object(py::none());
  out["heights"] = histogram(c.heights);
  out["attributes"] = attributes;
  return out;
}

py::dict raycast(const Tree& tree, const py::handle& origins_in, const py::handle& directions_in, double t_max, bool world,
                 unsigned threads) {
  const auto origins = rows_of_three<double>(origins_in, "origins");
  const auto directions = rows_of_three<double>(directions_in, "directions");
  if (origins.shape(0) != directions.shape(0) && origins.shape(0) != 1)
    throw vola::InvalidArgument("raycast: " + std::to_string(origins.shape(0)) + " origins for " +
                                std::to_string(directions.shape(0)) + " directions (give one origin or one per direction)");
  const auto n = directions.shape(0);
  const vola::Frame frame = tree.frame();
  std::vector<vola::raycast::Ray> rays(static_cast<std::size_t>(n));
  for (py::ssize_t i = 0; i < n; ++i) {
    const double* o = origins.data() + 3 * (origins.shape(0) == 1 ? 0 : i);
    const double* d = directions.data() + 3 * i;
    vola::raycast::Ray ray{{o[0], o[1], o[2]}, {d[0], d[1], d[2]}, t_max};
    if (world) ray = vola::raycast::world_ray_to_grid(frame, ray);
    vola::raycast::check_ray(ray);
    rays[static_cast<std::size_t>(i)] = ray;
  }
  std::vector<std::optional<vola::raycast::RayHit>> hits(rays.size());
  {
    py::gil_scoped_release release;
    vola::raycast::RayCaster(tree).cast(rays, hits, threads);
  }
  py::array_t<bool> hit(n);
  py::array_t<std::int64_t> voxel({n, py::ssize_t{3}});
  py::array_t<double> t(n);
  py::array_t<std::int8_t> normal({n, py::ssize_t{3}});
  py::array_t<double> point({n, py::ssize_t{3}});
  for (py::ssize_t i = 0; i < n; ++i) {
    const auto& h = hits[static_cast<std::size_t>(i)];
    hit.mutable_at(i) = h.has_value();
    t.mutable_at(i) = h ? (world ? h->t * frame.voxel_size : h->t) : std::numeric_limits<double>::infinity();
    const vola::raycast::Ray& ray = rays[static_cast<std::size_t>(i)];
    vola::Point at{std::nan(""), std::nan(""), std::nan("")};
    if (h) {
      for (int a = 0; a < 3; ++a) at[a] = ray.origin[a] + h->t * ray.direction[a];
      if (world) at = vola::raycast::grid_to_world(frame, at);
    }
    voxel.mutable_at(i, 0) = h ? std::int64_t{h->voxel.x} : -1;
    voxel.mutable_at(i, 1) = h ? std::int64_t{h->voxel.y} : -1;
    voxel.mutable_at(i, 2) = h ? std::int64_t{h->voxel.z} : -1;
    for (int a = 0; a < 3; ++a) {
      normal.mutable_at(i, a) = static_cast<std::int8_t>(h ? h->normal[a] : 0);
      point.mutable_at(i, a) = at[a];
    }
  }
  py::dict out;
  out["hit"] = hit;
  out["voxel"] = voxel;
  out["t"] = t;
  out["normal"] = normal;
  out["point"] = point;
  return out;
}

py::dict plan(const Tree& tree, std::array<double, 3> start, std::array<double, 3> goal, double radius, bool world, bool smooth,
              int level, bool hierarchical, std::uint64_t max_expansions) {
  const vola::Frame frame = tree.frame();
  vola::Point a = to_point(start), b = to_point(goal);
  if (world) {
    a = vola::raycast::world_to_grid(frame, a);
    b = vola::raycast::world_to_grid(frame, b);
    radius /= frame.voxel_size;
  }
  vola::raycast::PlanOptions options;
  options.radius = radius;
  options.smooth = smooth;
  options.level = level;
  options.hierarchical = hierarchical;
  options.max_expansions = max_expansions;
  vola::raycast::PlannedPath path;
  {
    py::gil_scoped_release release;
    path = vola::raycast::plan_path(tree, a, b, options);
  }
  const auto k = static_cast<py::ssize_t>(path.points.size());
  py::array_t<double> points({k, py::ssize_t{3}});
  for (py::ssize_t i = 0; i < k; ++i) {
    vola::Point p = path.points[static_cast<std::size_t>(i)];
    if (world) p = vola::raycast::grid_to_world(frame, p);
    for (int c = 0; c < 3; ++c) points.mutable_at(i, c) = p[c];
  }
  const double scale = world ? frame.voxel_size : 1.0;
  py::dict out;
  out["points"] = points;
  out["cost"] = path.cost * scale;
  out["length"] = path.length * scale;
  out["expanded"] = path.expanded;
  return out;
}

Tree convert(const std::filesystem::path& path, int depth,
             double voxel_size, const std::string& quantize, const std::string& format, std::optional<std::uint32_t> epsg,
             bool solid, bool attributes, std::optional<double> dem_base, bool dem_surface_only,
             std::optional<std::array<double, 3>> origin, std::optional<std::array<double, 6>> bbox, int nbits,
             std::array<int, 3> columns, std::vector<int> payload_columns, std::vector<std::string> text_attributes,
             int skip_lines, bool dense, bool compress, const std::optional<std::filesystem::path>& output) {
  vola::ConvertOptions options;
  options.format = format;
  if (!quantize.empty()) options.quantization = parse_quantization(quantize);
  options.depth = depth;
  options.voxel_size = voxel_size;
  if (origin) options.origin = to_point(*origin);
  if (bbox) options.bbox = vola::Box{{(*bbox)[0], (*bbox)[1], (*bbox)[2]}, {(*bbox)[3], (*bbox)[4], (*bbox)[5]}};
  options.nbits = nbits;
  options.epsg = epsg;
  options.attributes = attributes;
  options.columns = columns;
  options.payload_columns = std::move(payload_columns);
  options.text_attributes = std::move(text_attributes);
  options.skip_lines = skip_lines;
  options.solid = solid;
  options.dem_base = dem_base;
  options.dem_surface_only = dem_surface_only;
  options.dense = dense;
  options.compress = compress;
  py::gil_scoped_release release;
  return with_python_names([&] {
    Tree tree = vola::convert(path.string(), options);
    if (output) {
      vola::WriteOptions w;
      w.layout = dense ? vola::Layout::dense : vola::Layout::sparse;
      w.compress = compress;
      vola::write(tree, output->string(), w);
    }
    return tree;
  });
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

// ---- tile sets (vola tile's index.geojson): world queries, tiles mapped on demand ----

py::object tiles_contain(const vola::tile::TileSet& tiles, const py::handle& input) {
  const auto xyz = rows_of_three<double>(input, "points");
  const auto n = xyz.shape(0);
  py::array_t<bool> out(n);
  bool* hit = out.mutable_data();
  const double* p = xyz.data();
  {
    py::gil_scoped_release release;
    for (py::ssize_t i = 0; i < n; ++i, p += 3) hit[i] = tiles.locate(vola::Point{p[0], p[1], p[2]}).rank.has_value();
  }
  if (single_row(input)) return py::bool_(hit[0]);
  return std::move(out);
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

PYBIND11_MODULE(_vola, m) {
  m.doc() = "VOLA volumetric trees (compiled core of the vola package).";
  m.attr("__version__") = VOLA_PYTHON_VERSION;

  // Most specific last: pybind11 tries the latest registered translator first.
  static py::exception<vola::Error> error(m, "Error", PyExc_RuntimeError);
  static py::exception<vola::InvalidArgument> invalid(m, "InvalidArgument", error.ptr());
  static py::exception<vola::IoError> io_error(m, "IoError", error.ptr());
  static py::exception<vola::FormatError> format_error(m, "FormatError", error.ptr());
  py::register_exception_translator([](std::exception_ptr p) {
    try {
      if (p) std::rethrow_exception(p);
    } catch (const vola::FormatError& e) {
      format_error(e.what());
    } catch (const vola::IoError& e) {
      io_error(e.what());
    } catch (const vola::InvalidArgument& e) {
      invalid(e.what());
    } catch (const vola::Error& e) {
      error(e.what());
    }
  });

  py::class_<Tree>(m, "Tree", "An immutable VOLA tree: levels of 64-bit occupancy words, one per 4x4x4 block.")
      .def_property_readonly("depth", &Tree::depth, "Number of levels (1..10); the grid has 4**depth voxels per axis.")
      .def_property_readonly("side", &Tree::side, "Voxels per axis: 4**depth.")
      .def_property_readonly("voxel_count", &Tree::voxel_count, "Number of occupied voxels.")
      .def("__len__", [](const Tree& t) { return t.voxel_count(); })
      .def("__repr__", &repr)
      .def_property_readonly("is_mapped", &Tree::is_mapped, "True when the level words live in a file mapping.")
      .def_property_readonly("memory_bytes", &Tree::memory_bytes, "Bytes held in memory (mapped words not counted).")
      .def("node_count", &Tree::node_count, py::arg("level"), "Occupied cells of `level` (depth - 1 = voxels).")
      .def_property_readonly("quantization", [](const Tree& t) { return t.frame().quantization == vola::Quantization::grid ? "grid" : "toolkit"; },
                             "'grid' (floor((p - origin) / voxel_size)) or 'toolkit' (the reference's rounding).")
      .def_property_readonly("origin", [](const Tree& t) { return t.frame().origin; }, "World position of voxel (0, 0, 0)'s corner.")
      .def_property_readonly("voxel_size", [](const Tree& t) { return t.frame().voxel_size; }, "World edge of one voxel.")
      .def_property_readonly("epsg", [](const Tree& t) { return t.georef().epsg; }, "EPSG code in the header (2000 = the reference's default).")
      .def_property_readonly("crs_wkt", [](const Tree& t) { return t.georef().crs_wkt; }, "The CRS as WKT ('' when unknown).")
      .def_property_readonly("bbox", [](const Tree& t) { return py::make_tuple(t.georef().bbox.min, t.georef().bbox.max); },
                             "(min, max) of the input points in world coordinates, as the header records it.")
      .def_property_readonly("lat_lon", [](const Tree& t) { return py::make_tuple(t.georef().lat, t.georef().lon); },
                             "WGS84 latitude and longitude of the bbox centre (0, 0 when unknown).")
      .def_property_readonly("attribute_names", [](const Tree& t) {
            std::vector<std::string> names;
            for (const auto& c : t.attributes().columns()) names.push_back(c.name());
            return names;
          }, "Names of the per-voxel attribute columns.")
      .def("contains", &contains, py::arg("voxels"),
           "Occupancy of integer voxels: an (M, 3) array gives an (M,) bool array, one (3,) row gives a bool.\n"
           "Voxels off the grid (negative, >= side) are False. Runs in C++ without the GIL.")
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
      .def("occupancy", [](const py::object& self, int level) { return level_words(self, level, false); }, py::arg("level"),
           "The occupancy words of `level` as a read-only uint64 view (of the file mapping for a mapped tree).")
      .def("payload", [](const py::object& self, int level) { return level_words(self, level, true); }, py::arg("level"),
           "The payload words of `level` (empty without payload) as a read-only uint64 view.")
      .def("attribute", &attribute_view, py::arg("name"),
           "Attribute column `name` as a read-only view, one value per voxel in rank order. KeyError if missing.")
      .def("attributes", &attributes_of, "Every attribute column: {name: read-only array in rank order}.")
      .def("level_of_detail", &level_of_detail, py::arg("depth"),
           "The first `depth` levels as a coarser tree (shares the words; voxel size grows 4x per level dropped).")
      .def("write", &write_file, py::arg("path"), py::arg("dense") = false, py::arg("compress") = false,
           "Writes a .vol file (through a temporary file and a rename). dense: the reference's dense layout\n"
           "(depth <= 5); compress: zstd levels (a version-2 file only vola reads).")
      .def("to_bytes", &to_bytes, py::arg("dense") = false, py::arg("compress") = false, "The .vol file's bytes.")
      .def("components", &components, py::arg("connectivity") = 26,
           "Connected components (6, 18 or 26 neighbours). Returns {'labels': (N,) uint32 per voxel in rank order,\n"
           "'sizes', 'min', 'max', 'centroid', 'first_rank'}, components largest first.")
      .def("census", &census, py::arg("bins") = 16,
           "Per-level blocks and cells, height and attribute histograms, ASPRS class counts, volume and footprint.")
      .def("raycast", &raycast, py::arg("origins"), py::arg("directions"), py::arg("t_max") = std::numeric_limits<double>::infinity(),
           py::arg("world") = false, py::arg("threads") = 0u,
           "First occupied voxel along each ray (hierarchical DDA). origins: (R, 3) or one (3,); directions: (R, 3).\n"
           "Grid coordinates (voxel (i,j,k) = [i,i+1]^3) unless world=True. Returns {'hit', 'voxel', 't', 'normal', 'point'}.")
      .def("plan", &plan, py::arg("start"), py::arg("goal"), py::arg("radius") = 0.0, py::arg("world") = false,
           py::arg("smooth") = true, py::arg("level") = -1, py::arg("hierarchical") = false,
           py::arg("max_expansions") = std::uint64_t{20'000'000},
           "A* path over free voxels for a robot of `radius`. Returns {'points': (K, 3), 'cost', 'length', 'expanded'}.\n"
           "Grid coordinates unless world=True. Raises InvalidArgument when start/goal are blocked or unreachable.");

  m.def("build", &build_points, py::arg("points"), py::arg("depth") = 0, py::arg("voxel_size") = 0.0,
        py::arg("quantize") = "grid", py::arg("origin") = py::none(), py::arg("attributes") = py::dict(),
        py::arg("reductions") = py::dict(), py::arg("epsg") = 2000u,
        "Builds a tree from an (N, 3) array of world points.\n"
        "quantize='grid': voxel_size and/or depth; origin defaults to the bbox minimum snapped to the voxel size.\n"
        "quantize='toolkit': the reference's rounding, needs depth.\n"
        "attributes: {name: (N,) array}; the column type follows the dtype; reductions: {name: 'mean'|'max'|'min'|'majority'|'last'}.");
  m.def("build_from_voxels", &build_voxels, py::arg("voxels"), py::arg("depth"),
        "Builds a tree from an (N, 3) array of integer voxels, each below 4**depth (duplicates allowed).");
  m.def("from_dense", &from_dense, py::arg("grid"), py::arg("origin") = py::none(), py::arg("voxel_size") = py::none(),
        py::arg("depth") = 0, "Builds a tree from a dense 3-D array indexed [x, y, z] (non-zero = occupied).");
  m.def("read", [](const std::filesystem::path& p) { py::gil_scoped_release r; return vola::read(p.string()); }, py::arg("path"),
        "Reads a .vol file into memory.");
  m.def("open_mapped", [](const std::filesystem::path& p) { py::gil_scoped_release r; return vola::open_mapped(p.string()); },
        py::arg("path"), "Memory-maps a .vol file: a sparse uncompressed file's level words are used in place.");
  m.def("parse", [](py::bytes data, const std::string& name) {
          const std::string bytes = data;
          return vola::parse(std::span(reinterpret_cast<const std::uint8_t*>(bytes.data()), bytes.size()), name);
        }, py::arg("data"), py::arg("name") = "<bytes>", "Parses the bytes of a .vol file.");
  m.def("convert", &convert, py::arg("path"), py::arg("depth") = 0,
        py::arg("voxel_size") = 0.0, py::arg("quantize") = "", py::arg("format") = "auto", py::arg("epsg") = py::none(),
        py::arg("solid") = false, py::arg("attributes") = true, py::arg("dem_base") = py::none(),
        py::arg("dem_surface_only") = false, py::arg("origin") = py::none(), py::arg("bbox") = py::none(),
        py::arg("nbits") = 0, py::arg("columns") = std::array<int, 3>{1, 2, 3},
        py::arg("payload_columns") = std::vector<int>{}, py::arg("text_attributes") = std::vector<std::string>{},
        py::arg("skip_lines") = 0, py::arg("dense") = false, py::arg("compress") = false,
        py::arg("output") = py::none(),
        "Reads any input `vola convert` reads (LAS, text, NPY, PLY, PCD, KITTI, binvox, meshes, DEM) and builds its\n"
        "tree through the same pipeline (LAS streams: memory follows voxels, not points); with output=, also writes\n"
        "it (dense=, compress=). Every `vola convert` option is a keyword: quantize ('grid', default with\n"
        "voxel_size/origin, or 'toolkit', needs depth), depth, voxel_size, origin=(x, y, z), bbox=(minx, miny, minz,\n"
        "maxx, maxy, maxz), nbits, epsg, attributes (False: occupancy only), text input's columns (x y z, from 1),\n"
        "payload_columns, text_attributes=['NAME=COLUMN[:TYPE[:REDUCTION]]', ...], skip_lines; solid (meshes);\n"
        "dem_base, dem_surface_only (DEM). Voxel grids map cell to voxel unless another grid is asked for.");
  m.def("input_formats", [] {
        std::vector<std::pair<std::string, std::vector<std::string>>> out;
        for (const auto& f : vola::io::input_formats()) out.emplace_back(f.name, f.extensions);
        return out;
      }, "(name, extensions) of every input format this build reads.");
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
      .def("tiles", &tile_entries, "Every tile: {tile: (i, j, k), file, points, voxels, bytes}, from the index.")
      .def("contains", &tiles_contain, py::arg("points"),
           "World points (M, 3) -> (M,) bool: is each point's voxel occupied? Opens only the tiles hit.")
      .def("tile", &tile_tree, py::arg("i"), py::arg("j"), py::arg("k"),
           "The Tree of tile (i, j, k), memory-mapped, or None when the set has no such tile.");
  m.def("open_tiles", [](const std::filesystem::path& p) { return std::make_unique<vola::tile::TileSet>(p.string()); },
        py::arg("index"), "Opens a tile set through its index.geojson (no tile is mapped yet).");
  m.def("compression_available", &vola::compression_available, "Whether this build writes zstd-compressed files.");
}
