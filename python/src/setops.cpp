// vola.union, intersect, difference (and Tree's |, &, -): the set operations of
// `vola union | intersect | diff`, through the same library calls.
#include "python_support.hpp"

#include "vola/error.hpp"
#include "vola/geo/crs.hpp"
#include "vola/setops.hpp"

namespace vola::python {

namespace {

vola::FrameCheck frame_check(bool ignore_frame) {
  return ignore_frame ? vola::FrameCheck::ignore : vola::FrameCheck::require_equal;
}

template <Tree (*Op)(const Tree&, const Tree&, vola::FrameCheck)>
Tree combine(const Tree& a, const Tree& b, bool ignore_frame) {
  py::gil_scoped_release release;
  if (!ignore_frame)
    if (const auto differ = vola::geo::different_crs(a.georef(), b.georef()))
      throw vola::InvalidArgument("a is in " + differ->a + ", b in " + differ->b +
                                  ": the same voxel indices are different places; reproject one "
                                  "(vola.convert(..., target_crs=...)) or pass ignore_frame=True");
  return Op(a, b, frame_check(ignore_frame));
}

}  // namespace

void bind_setops(py::module_& m, py::class_<Tree>& tree) {
  constexpr const char* kCarried =
      "\nBoth trees must lie on one grid, else InvalidArgument, as the CLI says: the same depth, origin and voxel\n"
      "size, or grid trees of one voxel size whose origins are whole voxels apart (any depths: the result is on\n"
      "the lower origin, at the smallest depth that holds both); and the same CRS when both state one (a tree\n"
      "with none takes the other's). ignore_frame=True combines voxel indices anyway. The result keeps a's frame\n"
      "and CRS otherwise; payloads and attribute columns are not carried.";
  m.def("union", &combine<&vola::unite>, py::arg("a"), py::arg("b"), py::arg("ignore_frame") = false,
        (std::string("Voxels in a or b (`vola union`; also a | b).") + kCarried).c_str());
  m.def("intersect", &combine<&vola::intersect>, py::arg("a"), py::arg("b"), py::arg("ignore_frame") = false,
        (std::string("Voxels in both a and b (`vola intersect`; also a & b).") + kCarried).c_str());
  m.def("difference", &combine<&vola::subtract>, py::arg("a"), py::arg("b"), py::arg("ignore_frame") = false,
        (std::string("Voxels in a but not in b (`vola diff A B OUT`; also a - b).") + kCarried).c_str());
  tree.def("__or__", [](const Tree& a, const Tree& b) { return combine<&vola::unite>(a, b, false); }, py::is_operator())
      .def("__and__", [](const Tree& a, const Tree& b) { return combine<&vola::intersect>(a, b, false); }, py::is_operator())
      .def("__sub__", [](const Tree& a, const Tree& b) { return combine<&vola::subtract>(a, b, false); }, py::is_operator());
}

}  // namespace vola::python
