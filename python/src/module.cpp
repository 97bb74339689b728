// The vola Python module (vola._vola): the error family and the parts, each in its own
// file (building.cpp, tree.cpp, tree_analysis.cpp, setops.cpp, morphology.cpp, render.cpp,
// collide.cpp, export.cpp, filters.cpp, tiling.cpp, tiles.cpp, map.cpp).
#include "python_support.hpp"

#include <string>

PYBIND11_MODULE(_vola, m) {
  m.doc() = "VOLA volumetric trees (compiled core of the vola package).";
  m.attr("__version__") = VOLA_PYTHON_VERSION;

  // Most specific last: pybind11 tries the latest registered translator first.
  static py::exception<vola::Error> error(m, "Error", PyExc_RuntimeError);
  // vola.NAME, a subclass of vola.Error and of a Python exception `also`, added to the
  // module. Both bases share BaseException's layout (OSError extends it); the type lives
  // as long as the module (never freed).
  const auto error_that_is_also = [&](const char* name, PyObject* also) {
    const py::tuple bases = py::make_tuple(error, py::handle(also));
    PyObject* type = PyErr_NewException((std::string("vola._vola.") + name).c_str(), bases.ptr(), nullptr);
    if (!type) throw py::error_already_set();
    m.add_object(name, py::handle(type));
    return type;
  };
  // A bad argument is a ValueError too, as Python code expects of one (`except
  // ValueError` caught numpy's complaints but not a bad voxel size).
  static PyObject* const invalid = error_that_is_also("InvalidArgument", PyExc_ValueError);
  // A file that cannot be read or written is an OSError too (`except OSError` around
  // file handling caught Python's own errors but not vola's).
  static PyObject* const io_error = error_that_is_also("IoError", PyExc_OSError);
  static py::exception<vola::FormatError> format_error(m, "FormatError", error.ptr());
  py::register_exception_translator([](std::exception_ptr p) {
    try {
      if (p) std::rethrow_exception(p);
    } catch (const vola::FormatError& e) {
      format_error(e.what());
    } catch (const vola::IoError& e) {
      PyErr_SetString(io_error, e.what());
    } catch (const vola::InvalidArgument& e) {
      PyErr_SetString(invalid, e.what());
    } catch (const vola::Error& e) {
      error(e.what());
    }
  });

  using namespace vola::python;
  py::class_<Tree> tree = bind_tree(m);
  bind_tree_analysis(tree);
  bind_setops(m, tree);
  bind_morphology(tree);
  bind_collide(tree);
  bind_building(m);
  bind_export(m, tree);
  bind_filters(m);
  bind_tiling(m);
  bind_tiles(m);
  bind_render(tree, m);
  bind_map(m);
}
