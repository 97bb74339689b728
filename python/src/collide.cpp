// Tree.collide_segment, collide_sphere and collide_box: `vola collide`'s three queries
// through raycast::Collider, one per row of an array of queries.
#include "python_support.hpp"

#include <cmath>
#include <cstdint>
#include <limits>
#include <optional>

#include "vola/map/state_map.hpp"
#include "vola/map/unknown_space.hpp"
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

// A state map's unknown voxels a free query reaches; -1 when there were too many to count.
std::int64_t unknown_count(std::optional<std::uint64_t> unknown) {
  return unknown ? static_cast<std::int64_t>(*unknown) : -1;
}

// The answer to n sphere or box queries: bools (one bool for a single query given as one
// row), or with unknown=True a dict that adds the unknown voxels each free query reaches.
py::object collide_answer(const py::handle& rows_in, py::array_t<bool>& hit, py::array_t<std::int64_t>& unknown,
                          bool with_unknown) {
  const bool one = single_row(rows_in);
  if (!with_unknown) return one ? py::object(py::bool_(hit.data()[0])) : py::object(hit);
  py::dict out;
  out["hit"] = one ? py::object(py::bool_(hit.data()[0])) : py::object(hit);
  out["unknown"] = one ? py::object(py::int_(unknown.data()[0])) : py::object(unknown);
  return out;
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
  py::array_t<std::int64_t> unknown(n);
  auto h = hit.mutable_unchecked<1>();
  auto u = unknown.mutable_unchecked<1>();
  auto v = voxel.mutable_unchecked<2>();
  auto tt = t.mutable_unchecked<1>();
  auto dist = distance.mutable_unchecked<1>();
  auto at = point.mutable_unchecked<2>();
  auto nn = normal.mutable_unchecked<2>();
  const double* a = starts.data();
  const double* b = ends.data();
  each_query(tree, n, "segment", [&](const vola::raycast::Collider& collider, py::ssize_t i) {
    const vola::Point from{a[3 * i], a[3 * i + 1], a[3 * i + 2]}, to{b[3 * i], b[3 * i + 1], b[3 * i + 2]};
    const vola::Point grid_from = world ? vola::raycast::world_to_grid(frame, from) : from;
    const vola::Point grid_to = world ? vola::raycast::world_to_grid(frame, to) : to;
    const auto found = collider.segment(grid_from, grid_to);
    h(i) = found.has_value();
    u(i) = found ? 0 : unknown_count(vola::map::unknown_voxels_on_segment(tree, grid_from, grid_to));
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
  out["unknown"] = unknown;
  return out;
}

py::object collide_sphere(const Tree& tree, const py::handle& centres_in, const py::handle& radius_in, bool world,
                          bool with_unknown) {
  const auto centres = rows_of_three<double>(centres_in, "centres");
  const auto n = centres.shape(0);
  auto radii = ensure_array<double>(radius_in);
  if (!radii || radii.ndim() > 1 || (radii.ndim() == 1 && radii.shape(0) != n))
    throw vola::InvalidArgument("collide_sphere: radius must be one number or one per centre (" + std::to_string(n) + ")");
  const bool one_radius = radii.ndim() == 0;
  const vola::Frame frame = tree.frame();
  py::array_t<bool> hit(n);
  py::array_t<std::int64_t> unknown(n);
  bool* out = hit.mutable_data();
  std::int64_t* unseen = unknown.mutable_data();
  const double* c = centres.data();
  const double* r = radii.data();
  each_query(tree, n, "sphere", [&](const vola::raycast::Collider& collider, py::ssize_t i) {
    const vola::Point given{c[3 * i], c[3 * i + 1], c[3 * i + 2]};
    const vola::Point centre = world ? vola::raycast::world_to_grid(frame, given) : given;
    const double radius = world ? r[one_radius ? 0 : i] / frame.voxel_size : r[one_radius ? 0 : i];
    out[i] = collider.sphere(centre, radius);
    unseen[i] = out[i] || !with_unknown ? 0 : unknown_count(vola::map::unknown_voxels_in_sphere(tree, centre, radius));
  });
  return collide_answer(centres_in, hit, unknown, with_unknown);
}

py::object collide_box(const Tree& tree, const py::handle& boxes_in, bool world, bool with_unknown) {
  auto boxes = ensure_array<double>(boxes_in);
  if (boxes && boxes.ndim() == 1 && boxes.shape(0) == 6) boxes = boxes.reshape({py::ssize_t{1}, py::ssize_t{6}});
  if (!boxes || boxes.ndim() != 2 || boxes.shape(1) != 6)
    throw vola::InvalidArgument("collide_box: expected boxes (xmin, ymin, zmin, xmax, ymax, zmax) as shape (6,) or (N, 6)");
  const auto n = boxes.shape(0);
  const vola::Frame frame = tree.frame();
  py::array_t<bool> hit(n);
  py::array_t<std::int64_t> unknown(n);
  bool* out = hit.mutable_data();
  std::int64_t* unseen = unknown.mutable_data();
  const double* b = boxes.data();
  each_query(tree, n, "box", [&](const vola::raycast::Collider& collider, py::ssize_t i) {
    vola::Box box{{b[6 * i], b[6 * i + 1], b[6 * i + 2]}, {b[6 * i + 3], b[6 * i + 4], b[6 * i + 5]}};
    if (world) box = vola::Box{vola::raycast::world_to_grid(frame, box.min), vola::raycast::world_to_grid(frame, box.max)};
    out[i] = collider.box(box);
    unseen[i] = out[i] || !with_unknown ? 0 : unknown_count(vola::map::unknown_voxels_in_box(tree, box));
  });
  return collide_answer(boxes_in, hit, unknown, with_unknown);
}

}  // namespace

void bind_collide(py::class_<Tree>& tree) {
  tree.def("collide_segment", &collide_segment, py::arg("starts"), py::arg("ends"), py::arg("world") = true,
           "The first occupied voxel each segment start -> end enters (`vola collide --segment`); starts, ends:\n"
           "(N, 3) or one (3,). Returns {'hit': (N,) bool, 'voxel': (N, 3) int64 (-1 when free), 't': fraction of\n"
           "the segment at the entry (0 when it starts inside; inf when free), 'distance': from the start, 'point':\n"
           "the entry point, 'normal': (N, 3) int8 face entered, 'unknown': (N,) int64 voxels a free segment passes\n"
           "through that a state map has not seen (0 on a hit or a plain tree; -1: more than 2**26, not counted)}.\n"
           "World coordinates unless world=False (then voxel (i, j, k) is the cube [i, i+1] x [j, j+1] x [k, k+1]).")
      .def("collide_sphere", &collide_sphere, py::arg("centres"), py::arg("radius"), py::arg("world") = true,
           py::arg("unknown") = false,
           "Whether any occupied voxel is within `radius` of each centre, touching counts (`vola collide\n"
           "--sphere`). centres (N, 3) -> (N,) bool, one (3,) -> bool; radius: one number or (N,).\n"
           "unknown=True: {'hit': the same, 'unknown': (N,) int64 (or int) voxels a free sphere reaches that a\n"
           "state map has not seen (0 on a hit or a plain tree; -1: more than 2**26, not counted)}.")
      .def(
          "collide_box", &collide_box, py::arg("boxes"), py::arg("world") = true, py::arg("unknown") = false,
          "Whether any occupied voxel overlaps each box's interior, touching faces do not count (`vola collide\n"
          "--box`). boxes (N, 6) of xmin, ymin, zmin, xmax, ymax, zmax -> (N,) bool, one (6,) -> bool.\n"
          "unknown=True: {'hit': the same, 'unknown': voxels of a free box a state map has not seen, as for spheres}.");
}

}  // namespace vola::python
