// Internal to the Python module: numpy arrays in and out, and the library's option
// names in Python's words. Arrays come in as numpy arrays (converted only when their
// dtype or layout differs) and go out as numpy arrays; level words and attribute columns
// go out as read-only views that keep their tree alive (a mapped tree's words are then
// views of the file mapping).
#pragma once

#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>
#include <pybind11/stl/filesystem.h>

#include <array>
#include <chrono>
#include <cstdint>
#include <functional>
#include <memory>
#include <cmath>
#include <string>
#include <vector>

#include "vola/attributes.hpp"
#include "vola/builder.hpp"
#include "vola/error.hpp"
#include "vola/frame.hpp"
#include "vola/tree.hpp"

namespace py = pybind11;

namespace vola::python {

using vola::Tree;
using vola::Voxel;

template <class T>
using CArray = py::array_t<T, py::array::c_style | py::array::forcecast>;

// CArray<T>::ensure(input), except that a MemoryError (numpy had no room for the
// converted copy) is raised as one: ensure() swallows every error and gives a null
// array, which callers took for "not an array" or, unchecked, used as one (a crash).
template <class T>
CArray<T> ensure_array(const py::handle& input) {
  try {
    return CArray<T>(py::reinterpret_borrow<py::object>(input));
  } catch (py::error_already_set& e) {
    if (e.matches(PyExc_MemoryError)) throw;
    return py::reinterpret_steal<CArray<T>>(py::handle());
  }
}

// A numpy array that owns `values` (moved, not copied).
template <class T>
inline py::array_t<T> owning_array(std::vector<T>&& values, std::vector<py::ssize_t> shape) {
  auto* heap = new std::vector<T>(std::move(values));
  py::capsule owner(heap, [](void* p) { delete static_cast<std::vector<T>*>(p); });
  return py::array_t<T>(shape, heap->data(), owner);
}

// A read-only view of `count` items at `data`, kept alive by `owner`.
inline py::array readonly_view(py::dtype dtype, std::vector<py::ssize_t> shape, const void* data, py::handle owner) {
  py::array view(dtype, shape, data, owner);
  py::detail::array_proxy(view.ptr())->flags &= ~py::detail::npy_api::NPY_ARRAY_WRITEABLE_;
  return view;
}

// (N, 3) from an array of N rows of three, or a single row of three (N = 1).
template <class T>
CArray<T> rows_of_three(const py::handle& input, const char* what) {
  auto array = ensure_array<T>(input);
  if (!array) throw py::type_error(std::string(what) + ": expected an array of shape (N, 3)");
  if (array.ndim() == 1 && array.shape(0) == 3) array = array.reshape({py::ssize_t{1}, py::ssize_t{3}});
  if (array.ndim() != 2 || array.shape(1) != 3)
    throw py::value_error(std::string(what) + ": expected shape (N, 3), got " +
                          std::string(py::str(py::tuple(py::cast(std::vector<py::ssize_t>(
                              array.shape(), array.shape() + array.ndim()))))));
  return array;
}

// (N, 3) voxel indices: an array of floats is taken only when every value is a whole
// number, so world coordinates (or 62.9 for voxel 63) are not truncated without a word.
inline CArray<std::int64_t> voxel_rows(const py::handle& input, const char* what) {
  const py::array raw = py::array::ensure(input);
  if (raw && raw.dtype().kind() == 'f') {
    const auto values = ensure_array<double>(raw);
    const double* v = values.data();
    for (py::ssize_t i = 0; i < values.size(); ++i)
      if (!(std::isfinite(v[i]) && v[i] == std::floor(v[i])))
        throw py::value_error(std::string(what) + ": expects voxel indices (integers), got " + py::cast<std::string>(py::str(py::float_(v[i]))) +
                              "; for world coordinates use tree.world_to_voxel(points) first");
  }
  return rows_of_three<std::int64_t>(input, what);
}

inline bool single_row(const py::handle& input) {
  return py::array::ensure(input) && py::array::ensure(input).ndim() == 1;
}

inline vola::ValueType value_type_of(const py::dtype& dtype) {
  const char kind = dtype.kind();
  const auto size = dtype.itemsize();
  if (kind == 'u') return size == 1 ? vola::ValueType::u8 : size == 2 ? vola::ValueType::u16 : size == 4 ? vola::ValueType::u32 : vola::ValueType::u64;
  if (kind == 'i') return size == 1 ? vola::ValueType::i8 : size == 2 ? vola::ValueType::i16 : size == 4 ? vola::ValueType::i32 : vola::ValueType::i64;
  if (kind == 'b') return vola::ValueType::u8;
  if (kind == 'f') return size <= 4 ? vola::ValueType::f32 : vola::ValueType::f64;
  throw py::type_error("attribute dtype " + py::cast<std::string>(dtype.attr("name")) + " is not a number type");
}

// Columns hold doubles: a 64-bit integer above 2^53 in size comes back rounded (2^53 + 1
// as 2^53). Said with a warning rather than stored wrong without a word.
inline void warn_inexact_integers(const py::array& raw, const std::string& name) {
  const char kind = raw.dtype().kind();
  if ((kind != 'i' && kind != 'u') || raw.dtype().itemsize() != 8) return;
  const py::int_ limit(std::int64_t{1} << 53);  // compared as integers: 2^53 + 1 as a double is 2^53
  py::object too_large = raw.attr("__gt__")(limit);
  if (kind == 'i') too_large = too_large.attr("__or__")(raw.attr("__lt__")(py::int_(-(std::int64_t{1} << 53))));
  const auto count = py::cast<std::uint64_t>(py::module_::import("numpy").attr("count_nonzero")(too_large));
  if (count == 0) return;
  const std::string warning = "attribute '" + name + "': " + std::to_string(count) +
                              " values are larger than 2^53 and are kept rounded to the nearest double (columns "
                              "hold doubles); store offsets from a base value to keep them exact";
  if (PyErr_WarnEx(PyExc_UserWarning, warning.c_str(), 1) < 0) throw py::error_already_set();
}

// An (N, 3) array of points and {name: (N,) array} as a point cloud: each column typed by
// its dtype (reduction mean; callers set others), one value per point or an error.
inline vola::PointCloud point_cloud_of(const py::handle& points, const py::dict& attributes) {
  const auto xyz = rows_of_three<double>(points, "points");
  const auto n = static_cast<std::size_t>(xyz.shape(0));
  vola::PointCloud cloud;
  cloud.xyz.assign(xyz.data(), xyz.data() + 3 * n);
  for (const auto& [key, value] : attributes) {
    vola::PointAttribute a;
    if (!py::isinstance<py::str>(key))
      throw py::type_error("attributes: the keys are column names (str), not " +
                           py::cast<std::string>(py::str(py::type::of(key).attr("__name__"))));
    a.name = py::cast<std::string>(key);
    const py::array raw = py::array::ensure(value);
    if (!raw) throw py::type_error("attribute '" + a.name + "': expected an array");
    a.type = value_type_of(raw.dtype());
    const auto column = ensure_array<double>(raw);
    if (!column) throw py::type_error("attribute '" + a.name + "': its values cannot be read as numbers");
    warn_inexact_integers(raw, a.name);
    if (column.ndim() != 1 || static_cast<std::size_t>(column.shape(0)) != n)
      throw vola::InvalidArgument("attribute '" + a.name + "': expected one value per point (" + std::to_string(n) +
                                  "), got shape " + std::string(py::str(raw.attr("shape"))));
    a.values.assign(column.data(), column.data() + n);
    cloud.attributes.push_back(std::move(a));
  }
  return cloud;
}

inline py::dtype dtype_of(vola::ValueType type) {
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

inline vola::Quantization parse_quantization(const std::string& name) {
  if (name == "grid") return vola::Quantization::grid;
  if (name == "toolkit") return vola::Quantization::toolkit;
  throw vola::InvalidArgument("quantize '" + name + "': expected 'grid' or 'toolkit'");
}

inline vola::Point to_point(const std::array<double, 3>& p) { return vola::Point{p[0], p[1], p[2]}; }

// The library names options as its structs do; Python's keywords are the same names but
// for quantize.
inline std::string python_keyword(const std::string& option) { return option == "quantization" ? std::string("quantize") : option; }

// A library message (a cause, a warning) with each `member` named as its keyword.
inline std::string python_words(std::string text) {
  for (auto open = text.find('`'); open != std::string::npos; open = text.find('`', open)) {
    const auto close = text.find('`', open + 1);
    if (close == std::string::npos) break;
    const std::string name = python_keyword(text.substr(open + 1, close - open - 1));
    text.replace(open, close - open + 1, name);
    open += name.size();
  }
  return text;
}

// Runs `body`, rethrowing an OptionError in the keywords' words.
template <class Body>
auto with_python_names(Body&& body) {
  try {
    return body();
  } catch (const vola::OptionError& e) {
    if (e.option().empty()) throw vola::InvalidArgument(python_words(e.cause()));
    throw vola::InvalidArgument(python_keyword(e.option()) + ": " + python_words(e.cause()));
  }
}


// Ctrl-C during a long call. Long calls run without the GIL, and Python acts on a signal
// only between the main thread's bytecodes, so a KeyboardInterrupt used to wait for the
// whole call (minutes for a large conversion or dilation). Those calls take interruptible()
// as their progress callback: at most every 50 ms it takes the GIL and lets Python run
// its pending signal handlers (PyErr_CheckSignals: on the main thread only, as Python
// itself does); when a handler raises, it throws error_already_set, which unwinds the
// library's work (output temporaries removed, as for any error) and reaches the caller as
// the handler's exception, KeyboardInterrupt for Ctrl-C.
inline std::function<void(std::uint64_t, std::uint64_t)> interruptible() {
  auto last = std::make_shared<std::chrono::steady_clock::time_point>(std::chrono::steady_clock::now());
  return [last](std::uint64_t, std::uint64_t) {
    const auto now = std::chrono::steady_clock::now();
    if (now - *last < std::chrono::milliseconds(50)) return;
    *last = now;
    py::gil_scoped_acquire gil;
    if (PyErr_CheckSignals() != 0) throw py::error_already_set();
  };
}

// Each part of the module adds its functions and classes.
void bind_building(py::module_& m);
py::class_<Tree> bind_tree(py::module_& m);
void bind_tree_analysis(py::class_<Tree>& tree);
void bind_tiles(py::module_& m);
void bind_map(py::module_& m);
void bind_setops(py::module_& m, py::class_<Tree>& tree);
void bind_morphology(py::class_<Tree>& tree);
// After bind_tiles: it adds TileSet.render.
void bind_render(py::class_<Tree>& tree, py::module_& m);
void bind_collide(py::class_<Tree>& tree);
void bind_export(py::module_& m, py::class_<Tree>& tree);
void bind_filters(py::module_& m);
void bind_tiling(py::module_& m);

}  // namespace vola::python
