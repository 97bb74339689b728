// Tree.dilate, erode, fill, crop and downsample: `vola dilate | erode | fill | crop |
// downsample` through the same library calls. Results keep the grid and CRS; attribute
// columns and payloads are dropped.
#include "python_support.hpp"

#include <cstdint>
#include <limits>

#include "vola/analysis/crop.hpp"
#include "vola/analysis/downsample.hpp"
#include "vola/analysis/fill.hpp"
#include "vola/analysis/morphology.hpp"

namespace vola::python {

namespace {

vola::analysis::Element element_of(const std::string& name) {
  if (name == "sphere") return vola::analysis::Element::sphere;
  if (name == "cube") return vola::analysis::Element::cube;
  throw vola::InvalidArgument("element '" + name + "': expected 'sphere' or 'cube'");
}

template <Tree (*Op)(const Tree&, int, vola::analysis::Element, const vola::analysis::MorphProgress&)>
Tree morph(const Tree& tree, int radius, const std::string& element) {
  const auto kind = element_of(element);
  py::gil_scoped_release release;
  return Op(tree, radius, kind, interruptible());
}

Tree dilate(const Tree& tree, int radius, const std::string& element, bool keep_grid) {
  const auto kind = element_of(element);
  py::gil_scoped_release release;
  return keep_grid ? vola::analysis::dilate(tree, radius, kind, interruptible())
                   : vola::analysis::dilate_unclipped(tree, radius, kind, interruptible());
}

py::tuple fill(const Tree& tree) {
  vola::analysis::FillReport report;
  Tree out;
  {
    py::gil_scoped_release release;
    out = vola::analysis::fill_cavities(tree, &report);
  }
  return py::make_tuple(std::move(out), report.filled);
}

Voxel voxel_of(const std::array<std::int64_t, 3>& v, const char* what) {
  constexpr std::int64_t limit = std::numeric_limits<std::uint32_t>::max();
  for (const std::int64_t c : v)
    if (c < 0 || c > limit)
      throw vola::InvalidArgument(std::string("crop: ") + what + " (" + std::to_string(v[0]) + ", " +
                                  std::to_string(v[1]) + ", " + std::to_string(v[2]) + ") is not a voxel index");
  return Voxel{static_cast<std::uint32_t>(v[0]), static_cast<std::uint32_t>(v[1]), static_cast<std::uint32_t>(v[2])};
}

Tree crop(const Tree& tree, const std::array<std::int64_t, 3>& min, const std::array<std::int64_t, 3>& max) {
  const Voxel lo = voxel_of(min, "min"), hi = voxel_of(max, "max");
  py::gil_scoped_release release;
  return vola::analysis::crop(tree, lo, hi);
}

Tree downsample(const Tree& tree, int depth, std::uint64_t min_voxels) {
  py::gil_scoped_release release;
  return vola::analysis::downsample(tree, depth, min_voxels);
}

}  // namespace

void bind_morphology(py::class_<Tree>& tree) {
  tree.def("dilate", &dilate, py::arg("radius"), py::arg("element") = "sphere", py::arg("keep_grid") = false,
           "The voxels within `radius` voxels of an occupied voxel (`vola dilate`). Where they come within\n"
           "`radius` of the grid's faces the grid grows (origin moved down by whole voxels, depth raised), so\n"
           "nothing is cut and every voxel keeps its world place; keep_grid=True clips to the grid instead.\n"
           "element: 'sphere' (dx^2+dy^2+dz^2 <= r^2) or 'cube' (max |d| <= r). Attributes are dropped.")
      .def("erode", &morph<&vola::analysis::erode>, py::arg("radius"), py::arg("element") = "sphere",
           "The voxels whose whole element of `radius` is occupied (`vola erode`); cells outside the grid\n"
           "count as empty (scipy.ndimage.binary_erosion's border_value=0). Attributes are dropped.")
      .def("fill", &fill,
           "Fills enclosed cavities (`vola fill`): empty cells the outside cannot reach face to face become\n"
           "voxels (scipy.ndimage.binary_fill_holes). Returns (tree, cells filled). Works in the voxels'\n"
           "bounding box, refused beyond 2**33 cells (crop first).")
      .def("crop", &crop, py::arg("min"), py::arg("max"),
           "The voxels with min <= (x, y, z) <= max per axis, voxel indices, both inclusive (`vola crop`).")
      .def("downsample", &downsample, py::arg("depth"), py::arg("min_voxels") = std::uint64_t{1},
           "The depth-`depth` cells holding at least `min_voxels` voxels (`vola downsample`); min_voxels=1 gives\n"
           "level_of_detail's voxels. The voxel size grows 4x per level dropped; attributes are dropped.");
}

}  // namespace vola::python
