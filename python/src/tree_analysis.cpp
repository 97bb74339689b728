// Tree.components, census, raycast and plan: the analysis, ray and planning modules.
#include "python_support.hpp"

#include <cmath>
#include <cstdint>
#include <limits>
#include <optional>
#include <string>

#include "vola/analysis/census.hpp"
#include "vola/analysis/components.hpp"
#include "vola/map/state_map.hpp"
#include "vola/raycast/path_planner.hpp"
#include "vola/raycast/ray_caster.hpp"
#include "vola/raycast/world.hpp"

namespace vola::python {

namespace {

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
    d["without_value"] = a.without_value;
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
    // A state map's rays stop at its occupied voxels, as collide_segment's do, not at the
    // free ones it also holds.
    std::optional<Tree> occupied;
    if (vola::map::is_state_map(tree)) occupied = vola::map::occupied_tree(tree);
    vola::raycast::RayCaster(occupied ? *occupied : tree).cast(rays, hits, threads);
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

py::dict plan(const Tree& tree, std::array<double, 3> start, std::array<double, 3> goal, double radius, bool world,
              bool smooth, int level, bool hierarchical, std::uint64_t max_expansions, bool solid_ground,
              const std::string& unknown) {
  if (!unknown.empty() && unknown != "occupied" && unknown != "free")
    throw vola::InvalidArgument("unknown must be 'occupied' or 'free', not '" + unknown + "'");
  // A state map (vola.read, vola.open(..., states=True)) is planned in as `vola plan`
  // plans in the file: its occupied voxels are obstacles and, unless unknown='free',
  // unknown space is one too. A tree of points has no unknown space.
  const bool state_map = vola::map::is_state_map(tree);
  if (!state_map && unknown == "occupied")
    throw vola::InvalidArgument(
        "unknown='occupied': this tree is not a state map (vola.read('map.vol') or vola.open('map.vol', "
        "states=True) gives one): its empty space is free, it has no unknown space");
  std::optional<Tree> occupied;
  if (state_map) occupied = vola::map::occupied_tree(tree);
  const Tree& obstacles = occupied ? *occupied : tree;
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
  options.solid_ground = solid_ground;
  if (state_map && unknown != "free") options.known = &tree;
  if (world) options.world = &frame;
  vola::raycast::PlannedPath path;
  {
    py::gil_scoped_release release;
    path = vola::raycast::plan_path(obstacles, a, b, options);
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

}  // namespace

void bind_tree_analysis(py::class_<Tree>& tree) {
  tree.def("components", &components, py::arg("connectivity") = 26,
           "Connected components (6, 18 or 26 neighbours). Returns {'labels': (N,) uint32 per voxel in rank order,\n"
           "'sizes', 'min', 'max', 'centroid', 'first_rank'}, components largest first.")
      .def("census", &census, py::arg("bins") = 16,
           "Per-level blocks and cells, height and attribute histograms, ASPRS class counts, volume and footprint.")
      .def("raycast", &raycast, py::arg("origins"), py::arg("directions"),
           py::arg("t_max") = std::numeric_limits<double>::infinity(), py::arg("world") = false,
           py::arg("threads") = 0u,
           "First occupied voxel along each ray (hierarchical DDA; of a state map, its occupied voxels, not its\n"
           "free ones). origins: (R, 3) or one (3,); directions: (R, 3).\n"
           "Grid coordinates (voxel (i,j,k) = [i,i+1]^3) unless world=True. Returns {'hit', 'voxel', 't', 'normal', "
           "'point'}.")
      .def(
          "plan", &plan, py::arg("start"), py::arg("goal"), py::arg("radius") = 0.0, py::arg("world") = false,
          py::arg("smooth") = true, py::arg("level") = -1, py::arg("hierarchical") = false,
          py::arg("max_expansions") = std::uint64_t{20'000'000}, py::arg("solid_ground") = false,
          py::arg("unknown") = "",
          "A* path over free voxels for a robot of `radius` (no corner cutting: every leg keeps the sphere clear).\n"
          "hierarchical=True: a coarse route first, then the voxels near it (scales; cost not guaranteed optimal).\n"
          "solid_ground=True: the space under each column's lowest voxel is an obstacle (`vola plan --solid-ground`).\n"
          "A state map (vola.read('map.vol'), vola.open('map.vol', states=True)) plans as `vola plan` does: its\n"
          "occupied voxels are obstacles, and unknown space too unless unknown='free' (vola.open('map.vol')\n"
          "alone gives the occupied voxels only, so everything else counts as free).\n"
          "Start and goal are snapped to their voxels' centres, the path's first and last points.\n"
          "Returns {'points': (K, 3), 'cost', 'length', 'expanded'}.\n"
          "Grid coordinates unless world=True. Raises InvalidArgument when start/goal are blocked or unreachable.");
}

}  // namespace vola::python
