// vola.Map (an occupancy map from range scans, as vola map builds it) and the state of
// points in a loaded state map (vola.state, vola.probability).
#include <cmath>
#include <cstdio>
#include <limits>
#include <memory>
#include <mutex>
#include <shared_mutex>

#include "python_support.hpp"
#include "vola/file.hpp"
#include "vola/map/distance_field.hpp"
#include "vola/map/occupancy_map.hpp"
#include "vola/map/state_map.hpp"

namespace vola::python {

namespace {

using map::OccupancyMap;
using map::VoxelState;

// One scan's report as a dict of counts.
py::dict report_dict(const map::ScanReport& r) {
  py::dict d;
  d["points"] = r.points;
  d["not_finite"] = r.not_finite;
  d["outside"] = r.outside;
  d["cut"] = r.cut;
  d["hit_voxels"] = r.hit_voxels;
  d["free_voxels"] = r.free_voxels;
  return d;
}

// f(point) for each row of `points`, without the GIL, into an (N,) array of T.
template <class T, class F>
py::array_t<T> per_point(const py::handle& points, F&& f) {
  const auto xyz = rows_of_three<double>(points, "points");
  const auto n = static_cast<std::size_t>(xyz.shape(0));
  std::vector<T> out(n);
  const double* p = xyz.data();
  {
    py::gil_scoped_release release;
    for (std::size_t i = 0; i < n; ++i) out[i] = f(Point{p[3 * i], p[3 * i + 1], p[3 * i + 2]});
  }
  return owning_array(std::move(out), {static_cast<py::ssize_t>(n)});
}

// The map and a lock: insert() runs without the GIL, so two Python threads may insert,
// or read while another inserts (that crashed the interpreter); inserts are exclusive,
// reads shared. (Shared, so that PyMap moves.)
struct PyMap {
  OccupancyMap map;
  double max_range;
  std::shared_ptr<std::shared_mutex> guard = std::make_shared<std::shared_mutex>();
};

// A distance field and its lock, as PyMap: update() runs without the GIL, and a read
// while it ran mixed the old field with the new (78 of 763 concurrent reads).
struct PyDistanceField {
  map::DistanceField field;
  std::shared_ptr<std::shared_mutex> guard = std::make_shared<std::shared_mutex>();
};

// The locks are taken without the GIL: a thread holding the GIL while it waits would stop
// the inserting thread from ever handing its result back.
std::shared_lock<std::shared_mutex> reading(const std::shared_ptr<std::shared_mutex>& guard) {
  py::gil_scoped_release release;
  return std::shared_lock(*guard);
}
std::shared_lock<std::shared_mutex> reading(const PyMap& self) { return reading(self.guard); }

// map::RayExtent's guard, as `vola map --max-ray-voxels` applies it.
void check_ray_extent(std::span<const double> xyz, const std::array<double, 3>& origin, const PyMap& self,
                      double max_ray_voxels) {
  if (!(max_ray_voxels >= 0.0)) throw InvalidArgument("max_ray_voxels must be >= 0 (0: no limit)");
  if (max_ray_voxels == 0.0) return;
  const map::RayExtent e = map::ray_extent(xyz, to_point(origin), self.map.voxel_size(), self.max_range);
  if (e.voxel_steps <= max_ray_voxels) return;
  char text[480];
  std::snprintf(text, sizeof text,
                "the scan's rays cross up to %.3g voxels of %.6g, more than max_ray_voxels %.3g (each may become a "
                "known voxel of ~40 bytes): its points lie %.6g on average and up to %.6g from the origin (%.10g, "
                "%.10g, %.10g). Check that origin is the sensor's position in the points' frame and the voxel "
                "size's unit; give the Map a max_range, or a larger max_ray_voxels for a scan this large",
                e.voxel_steps, self.map.voxel_size(), max_ray_voxels, e.mean, e.longest, origin[0], origin[1],
                origin[2]);
  throw InvalidArgument(text);
}

VoxelState map_state(const OccupancyMap& m, const Point& p) {
  const auto v = m.voxel_of(p);
  const auto value = v ? m.log_odds(*v) : std::nullopt;
  if (!value) return VoxelState::unknown;
  return m.occupied(*value) ? VoxelState::occupied : VoxelState::free;
}

}  // namespace

void bind_map(py::module_& m) {
  m.attr("UNKNOWN") = static_cast<int>(VoxelState::unknown);
  m.attr("FREE") = static_cast<int>(VoxelState::free);
  m.attr("OCCUPIED") = static_cast<int>(VoxelState::occupied);

  py::class_<PyMap>(m, "Map", "A probabilistic occupancy map from range scans, as `vola map` builds it.")
      .def(py::init([](double voxel_size, double max_range) {
             if (!(max_range >= 0.0)) throw InvalidArgument("max_range must be >= 0 (0: no limit)");
             return PyMap{OccupancyMap(voxel_size), max_range};
           }),
           py::arg("voxel_size"), py::arg("max_range") = 0.0,
           "An empty map of voxels of edge voxel_size (voxel (i,j,k) covers [i*R, (i+1)*R)); points farther than\n"
           "max_range (> 0) from the sensor mark their ray free up to it and hit nothing.")
      .def_static(
          "from_tree",
          [](const Tree& state_map, double max_range) {
            if (!(max_range >= 0.0)) throw InvalidArgument("max_range must be >= 0 (0: no limit)");
            if (!map::is_state_map(state_map))
              throw InvalidArgument(
                  "not a state map: give a tree read with its states, vola.read('map.vol') or "
                  "vola.open('map.vol', states=True) (vola.open alone gives a state map's occupied voxels only)");
            return PyMap{map::thaw(state_map), max_range};
          },
          py::arg("tree"), py::arg("max_range") = 0.0,
          "The map a state map was saved from (vola.read('map.vol')), to insert more scans into: saving it\n"
          "again gives the bytes of inserting every scan at once.")
      .def_property_readonly("voxel_size", [](const PyMap& self) { return self.map.voxel_size(); })
      .def_property_readonly("max_range", [](const PyMap& self) { return self.max_range; })
      .def("__len__",
           [](const PyMap& self) {
             const auto lock = reading(self);
             return self.map.size();
           })
      .def(
          "insert",
          [](PyMap& self, const py::handle& points, const std::array<double, 3>& origin, double max_ray_voxels) {
            const auto xyz = rows_of_three<double>(points, "points");
            const std::span<const double> values(xyz.data(), static_cast<std::size_t>(xyz.size()));
            map::ScanReport report;
            {
              py::gil_scoped_release release;
              check_ray_extent(values, origin, self, max_ray_voxels);
              const std::unique_lock lock(*self.guard);
              report = self.map.insert_scan(values, to_point(origin), self.max_range);
            }
            return report_dict(report);
          },
          py::arg("points"), py::arg("origin"), py::arg("max_ray_voxels") = 2e8,
          "One scan: points (N, 3) in world coordinates, each a ray from origin (the sensor). Returns the counts\n"
          "of `vola map`'s summary (points, not_finite, outside, cut, hit_voxels, free_voxels).\n"
          "A scan whose rays would cross more than max_ray_voxels voxels in all (each may become a known voxel\n"
          "of ~40 bytes; 2e8 is about 8 GB) raises vola.InvalidArgument before any work, as `vola map\n"
          "--max-ray-voxels` does: usually points and origin in different frames or units. 0: no limit.")
      .def("state",
           [](const PyMap& self, const py::handle& points) {
             const auto lock = reading(self);
             return per_point<std::int8_t>(points, [&](const Point& p) {
               return static_cast<std::int8_t>(map_state(self.map, p));
             });
           },
           py::arg("points"), "(N,) int8 per world point: vola.UNKNOWN 0, vola.FREE 1, vola.OCCUPIED 2.")
      .def("probability",
           [](const PyMap& self, const py::handle& points) {
             const auto lock = reading(self);
             return per_point<double>(points, [&](const Point& p) {
               const auto v = self.map.voxel_of(p);
               const auto value = v ? self.map.log_odds(*v) : std::nullopt;
               return value ? map::occupancy_probability(*value) : std::numeric_limits<double>::quiet_NaN();
             });
           },
           py::arg("points"), "(N,) float64 occupancy probability per world point, NaN where unknown.")
      .def("tree",
           [](const PyMap& self) {
             const auto lock = reading(self);
             return map::freeze(self.map);
           },
           "The map as a state map tree (Tree.is_state_map), as save() writes it.")
      .def(
          "save",
          [](const PyMap& self, const std::filesystem::path& path) {
            py::gil_scoped_release release;
            const std::shared_lock lock(*self.guard);
            write(map::freeze(self.map), path.string());
          },
          py::arg("path"), "Writes the state map: the bytes `vola map` writes for the same scans.");

  m.def(
      "state",
      [](const Tree& tree, const py::handle& points) {
        const map::StateLookup lookup(tree);
        auto out = per_point<std::int8_t>(points, [&](const Point& p) { return static_cast<std::int8_t>(lookup.at(p).state); });
        check_mapped(tree);
        return out;
      },
      py::arg("tree"), py::arg("points"),
      "(N,) int8 state per world point of a loaded tree: a state map's UNKNOWN/FREE/OCCUPIED; any other tree's\n"
      "voxels are OCCUPIED and the rest FREE.");
  m.def(
      "probability",
      [](const Tree& tree, const py::handle& points) {
        const map::StateLookup lookup(tree);
        auto out = per_point<double>(points, [&](const Point& p) {
          const auto s = lookup.at(p);
          return s.log_odds ? map::occupancy_probability(*s.log_odds) : std::numeric_limits<double>::quiet_NaN();
        });
        check_mapped(tree);
        return out;
      },
      py::arg("tree"), py::arg("points"),
      "(N,) float64 occupancy probability per world point from the tree's log_odds column, NaN where there is none.");
  const auto box_of = [](const py::handle& lo, const py::handle& hi) {
    const auto l = lo.cast<std::array<std::int64_t, 3>>(), h = hi.cast<std::array<std::int64_t, 3>>();
    return map::GridBox{l, h};
  };
  py::class_<PyDistanceField>(
      m, "DistanceField",
      "Exact Euclidean distances (world units) from voxel centres to the nearest obstacle voxel's\n"
      "centre, capped at max_distance (vola/map/distance_field.hpp): the ESDF planners use.")
      .def(py::init([box_of](const Tree& tree, double max_distance, const py::object& lo, const py::object& hi) {
             if (lo.is_none() != hi.is_none()) throw InvalidArgument("give both lo and hi, or neither");
             const std::optional<map::GridBox> box = lo.is_none() ? std::nullopt : std::optional(box_of(lo, hi));
             py::gil_scoped_release release;
             return std::make_unique<PyDistanceField>(box ? map::DistanceField(tree, *box, max_distance)
                                                          : map::DistanceField(tree, max_distance));
           }),
           py::arg("tree"), py::arg("max_distance"), py::arg("lo") = py::none(), py::arg("hi") = py::none(),
           "The field of the tree's voxels (a state map's occupied ones) over grid voxels lo..hi-1 (default: the\n"
           "voxels' box grown by max_distance); the box may reach past the grid's faces, where cells lie near the\n"
           "obstacles on them, and is clipped max_distance beyond them.")
      .def(
          "distance",
          [](const PyDistanceField& self, const py::handle& points) {
            const auto lock = reading(self.guard);
            return per_point<double>(points, [&](const Point& p) { return self.field.distance(p); });
          },
          py::arg("points"), "(N,) distance at each world point (its voxel's value; max_distance outside the box).")
      .def(
          "gradient",
          [](const PyDistanceField& self, const py::handle& points) {
            const auto xyz = rows_of_three<double>(points, "points");
            const auto lock = reading(self.guard);
            const auto n = static_cast<std::size_t>(xyz.shape(0));
            std::vector<double> out(3 * n);
            const double* p = xyz.data();
            {
              py::gil_scoped_release release;
              for (std::size_t i = 0; i < n; ++i) {
                const Point g = self.field.gradient(Point{p[3 * i], p[3 * i + 1], p[3 * i + 2]});
                std::copy(g.begin(), g.end(), out.begin() + static_cast<std::ptrdiff_t>(3 * i));
              }
            }
            return owning_array(std::move(out), {static_cast<py::ssize_t>(n), 3});
          },
          py::arg("points"), "(N, 3) gradient of the distance at each world point (away from the nearest obstacle).")
      .def(
          "update",
          [box_of](PyDistanceField& self, const Tree& tree, const py::handle& lo, const py::handle& hi) {
            const map::GridBox box = box_of(lo, hi);
            py::gil_scoped_release release;
            const std::unique_lock lock(*self.guard);
            self.field.update(tree, box);
          },
          py::arg("tree"), py::arg("lo"), py::arg("hi"),
          "Recomputes the cells near grid voxels lo..hi-1, where `tree` (same grid) changed.")
      .def_property_readonly(
          "box", [](const PyDistanceField& self) { return py::make_tuple(self.field.box().lo, self.field.box().hi); })
      .def_property_readonly("max_distance", [](const PyDistanceField& self) { return self.field.max_distance(); });
  m.def("occupied_tree", &map::occupied_tree, py::arg("tree"),
        "A state map's occupied voxels as a plain tree (columns kept); any other tree as it is.");
  m.def("free_tree", &map::free_tree, py::arg("tree"), "A state map's free voxels as a plain tree (columns kept).");
}

}  // namespace vola::python
