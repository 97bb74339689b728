// Tree.collide_segment, collide_sphere and collide_box: `vola collide`'s three queries
// through raycast::Collider, one per row of an array of queries.
#include "python_support.hpp"

#include <cmath>
#include <cstdint>
#include <limits>
#include <optional>

#include "vola/map/state_map.hpp"
#include "vola/raycast/collision.hpp"
#include "vola/raycast/world.hpp"

namespace vola::python {

namespace {

// Runs query(collider, i) for every row, the collider built and the rows answered without
// the GIL; an InvalidArgument names the row when there are several.
// A state map (vola.read, vola.open(..., states=True)) collides with its occupied voxels,
// as `vola collide` does with the file: its free voxels are not obstacles.
template <class Query>
void each_query(const Tree& tree, py::ssize_t n, const char* what, Query&& query) {
  py::gil_scoped_release release;
  std::optional<Tree> occupied;
  if (vola::map::is_state_map(tree)) occupied = vola::map::occupied_tree(tree);
  const vola::raycast::Collider collider(occupied ? *occupied : tree);
  for (py::ssize_t i = 0; i < n; ++i) {
    try {
      query(collider, i);
    } catch (const vola::InvalidArgument& e) {
      if (n == 1) throw;
      throw vola::InvalidArgument(std::string(what) + " " + std::to_string(i) + ": " + e.what());
    }
  }
}

py::dict collide_segment(const Tree& tree, const py::handle& starts_in, const py::handle& ends_in, bool world) {
  const auto starts = rows_of_three<double>(starts_in, "starts");
  const auto ends = rows_of_three<double>(ends_in, "ends");
  if (starts.shape(0) != ends.shape(0))
    throw vola::InvalidArgument("collide_segment: " + std::to_string(starts.shape(0)) + " starts for " +
                                std::to_string(ends.shape(0)) + " ends");
  const auto n = starts.shape(0);
  const vola::Frame frame = tree.frame();
  py::array_t<bool> hit(n);
  py::array_t<std::int64_t> voxel({n, py::ssize_t{3}});
  py::array_t<double> t(n), distance(n);
  py::array_t<double> point({n, py::ssize_t{3}});
  py::array_t<std::int8_t> normal({n, py::ssize_t{3}});
  auto h = hit.mutable_unchecked<1>();
  auto v = voxel.mutable_unchecked<2>();
  auto tt = t.mutable_unchecked<1>();
  auto dist = distance.mutable_unchecked<1>();
  auto at = point.mutable_unchecked<2>();
  auto nn = normal.mutable_unchecked<2>();
  const double* a = starts.data();
  const double* b = ends.data();
  each_query(tree, n, "segment", [&](const vola::raycast::Collider& collider, py::ssize_t i) {
    const vola::Point from{a[3 * i], a[3 * i + 1], a[3 * i + 2]}, to{b[3 * i], b[3 * i + 1], b[3 * i + 2]};
    const auto found = world ? collider.segment(vola::raycast::world_to_grid(frame, from), vola::raycast::world_to_grid(frame, to))
                             : collider.segment(from, to);
    h(i) = found.has_value();
    double length = 0.0;
    for (int c = 0; c < 3; ++c) length += (to[c] - from[c]) * (to[c] - from[c]);
    tt(i) = found ? found->t : std::numeric_limits<double>::infinity();
    dist(i) = found ? found->t * std::sqrt(length) : std::numeric_limits<double>::infinity();
    for (int c = 0; c < 3; ++c) {
      v(i, c) = found ? std::int64_t{c == 0 ? found->voxel.x : c == 1 ? found->voxel.y : found->voxel.z} : -1;
      at(i, c) = found ? from[c] + found->t * (to[c] - from[c]) : std::nan("");
      nn(i, c) = static_cast<std::int8_t>(found ? found->normal[c] : 0);
    }
  });
  py::dict out;
  out["hit"] = hit;
  out["voxel"] = voxel;
  out["t"] = t;
  out["distance"] = distance;
  out["point"] = point;
  out["normal"] = normal;
  return out;
}

py::object collide_sphere(const Tree& tree, const py::handle& centres_in, const py::handle& radius_in, bool world) {
  const auto centres = rows_of_three<double>(centres_in, "centres");
  const auto n = centres.shape(0);
  auto radii = ensure_array<double>(radius_in);
  if (!radii || radii.ndim() > 1 || (radii.ndim() == 1 && radii.shape(0) != n))
    throw vola::InvalidArgument("collide_sphere: radius must be one number or one per centre (" + std::to_string(n) + ")");
  const bool one_radius = radii.ndim() == 0;
  const vola::Frame frame = tree.frame();
  py::array_t<bool> hit(n);
  bool* out = hit.mutable_data();
  const double* c = centres.data();
  const double* r = radii.data();
  each_query(tree, n, "sphere", [&](const vola::raycast::Collider& collider, py::ssize_t i) {
    const vola::Point centre{c[3 * i], c[3 * i + 1], c[3 * i + 2]};
    const double radius = r[one_radius ? 0 : i];
    out[i] = world ? collider.sphere(vola::raycast::world_to_grid(frame, centre), radius / frame.voxel_size)
                   : collider.sphere(centre, radius);
  });
  if (single_row(centres_in)) return py::bool_(out[0]);
  return std::move(hit);
}

py::object collide_box(const Tree& tree, const py::handle& boxes_in, bool world) {
  auto boxes = ensure_array<double>(boxes_in);
  if (boxes && boxes.ndim() == 1 && boxes.shape(0) == 6) boxes = boxes.reshape({py::ssize_t{1}, py::ssize_t{6}});
  if (!boxes || boxes.ndim() != 2 || boxes.shape(1) != 6)
    throw vola::InvalidArgument("collide_box: expected boxes (xmin, ymin, zmin, xmax, ymax, zmax) as shape (6,) or (N, 6)");
  const auto n = boxes.shape(0);
  const vola::Frame frame = tree.frame();
  py::array_t<bool> hit(n);
  bool* out = hit.mutable_data();
  const double* b = boxes.data();
  each_query(tree, n, "box", [&](const vola::raycast::Collider& collider, py::ssize_t i) {
    vola::Box box{{b[6 * i], b[6 * i + 1], b[6 * i + 2]}, {b[6 * i + 3], b[6 * i + 4], b[6 * i + 5]}};
    if (world) box = vola::Box{vola::raycast::world_to_grid(frame, box.min), vola::raycast::world_to_grid(frame, box.max)};
    out[i] = collider.box(box);
  });
  if (single_row(boxes_in)) return py::bool_(out[0]);
  return std::move(hit);
}

}  // namespace

void bind_collide(py::class_<Tree>& tree) {
  tree.def("collide_segment", &collide_segment, py::arg("starts"), py::arg("ends"), py::arg("world") = true,
           "The first occupied voxel each segment start -> end enters (`vola collide --segment`); starts, ends:\n"
           "(N, 3) or one (3,). Returns {'hit': (N,) bool, 'voxel': (N, 3) int64 (-1 when free), 't': fraction of\n"
           "the segment at the entry (0 when it starts inside; inf when free), 'distance': from the start, 'point':\n"
           "the entry point, 'normal': (N, 3) int8 face entered}. World coordinates unless world=False (then\n"
           "voxel (i, j, k) is the cube [i, i+1] x [j, j+1] x [k, k+1]).")
      .def("collide_sphere", &collide_sphere, py::arg("centres"), py::arg("radius"), py::arg("world") = true,
           "Whether any occupied voxel is within `radius` of each centre, touching counts (`vola collide\n"
           "--sphere`). centres (N, 3) -> (N,) bool, one (3,) -> bool; radius: one number or (N,).")
      .def("collide_box", &collide_box, py::arg("boxes"), py::arg("world") = true,
           "Whether any occupied voxel overlaps each box's interior, touching faces do not count (`vola collide\n"
           "--box`). boxes (N, 6) of xmin, ymin, zmin, xmax, ymax, zmax -> (N,) bool, one (6,) -> bool.");
}

}  // namespace vola::python
