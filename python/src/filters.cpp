// vola.filter_points: the point filters of `vola convert/translate/tile --filter` (and
// `vola pipeline`) on arrays, through filters::run_stages as those commands call it.
#include "python_support.hpp"

#include <cstdint>
#include <optional>

#include "vola/crs_rules.hpp"
#include "vola/filters/stages.hpp"
#include "vola/geo/crs.hpp"
#include "vola/pipeline.hpp"

namespace vola::python {

namespace {

py::dict stage_dict(const vola::filters::StageReport& s) {
  return py::dict(py::arg("spec") = s.spec, py::arg("points_in") = s.points_in, py::arg("points_out") = s.points_out,
                  py::arg("ground") = s.ground);
}

py::dict filter_points(const py::handle& points, const py::dict& attributes, const std::vector<std::string>& filters,
                       const std::string& crs) {
  vola::PointCloud cloud = point_cloud_of(points, attributes);
  const std::optional<std::uint32_t> epsg = crs.empty() ? std::nullopt : vola::epsg_code_of(crs);
  const std::string wkt = epsg ? std::string() : crs;
  // A CRS PROJ does not know is refused, as vola.build refuses one: taken as no CRS, SMRF
  // and hag read feet as metres.
  if (!crs.empty()) try {
      (void)vola::geo::crs_wkt(epsg ? "EPSG:" + std::to_string(*epsg) : crs);
    } catch (const vola::Error& e) {
      throw vola::InvalidArgument("crs='" + crs.substr(0, 40) + (crs.size() > 40 ? "...'" : "'") +
                                  " is not a CRS PROJ knows: " + e.what());
    }
  vola::filters::FilterResult result;
  {
    py::gil_scoped_release release;
    result = with_python_names([&] {
      const auto stages = vola::filters::parse_stages(filters);
      return vola::filters::run_stages(stages, cloud, epsg, wkt);
    });
  }
  const auto k = static_cast<py::ssize_t>(cloud.size());
  py::dict columns;
  for (auto& a : cloud.attributes) {
    const py::array values = owning_array(std::move(a.values), {k});
    columns[py::str(a.name)] = values.attr("astype")(dtype_of(a.type));
  }
  py::list stages;
  for (const auto& s : result.stages) stages.append(stage_dict(s));
  py::dict out;
  out["points"] = owning_array(std::move(cloud.xyz), {k, py::ssize_t{3}});
  out["attributes"] = columns;
  out["kept"] = owning_array(std::move(result.kept), {k});
  out["stages"] = stages;
  return out;
}

// vola::run_pipeline's reports as one dict per writer (vola.pipeline in __init__.py reads
// the pipeline from a file, a JSON string or Python lists and dicts).
py::list run_pipeline(const std::string& json, const std::string& name) {
  std::vector<vola::PipelineOutputReport> reports;
  {
    py::gil_scoped_release release;
    reports = with_python_names([&] { return vola::run_pipeline(json, name); });
  }
  py::list out;
  for (const auto& r : reports) {
    py::list stages;
    for (const auto& s : r.stages) stages.append(stage_dict(s));
    out.append(py::dict(py::arg("input") = r.input, py::arg("output") = r.output, py::arg("voxels") = r.voxels,
                        py::arg("voxel_count") = r.voxel_count, py::arg("filters") = r.filter_lines,
                        py::arg("stages") = stages, py::arg("warnings") = r.warnings));
  }
  return out;
}

}  // namespace

void bind_filters(py::module_& m) {
  m.def("_run_pipeline", &run_pipeline, py::arg("json"), py::arg("name"),
        "vola::run_pipeline on the pipeline's JSON text; `name` names it in errors. Use vola.pipeline.");
  m.def("filter_points", &filter_points, py::arg("points"), py::arg("attributes") = py::dict(),
        py::arg("filters") = std::vector<std::string>{}, py::arg("crs") = "",
        "Runs point filters in order on (N, 3) points and their columns, as `vola translate --filter/--where/--crop`\n"
        "does (docs/FILTERS.md): 'where:EXPR', 'smrf[:cell=1,...]' (classification 2 ground, 1 the rest), 'hag'\n"
        "(adds height_above_ground), 'outlier[:k=8,multiplier=2]', 'voxel:R', 'poisson:R', 'crop:X0,Y0,X1,Y1',\n"
        "'polygon:FILE'. attributes: {name: (N,) array} (e.g. classification, intensity; the dtype is kept).\n"
        "crs: the points' CRS ('EPSG:2992', '2992' or WKT) for smrf's metre parameters (none: metres).\n"
        "Returns {'points': (K, 3), 'attributes': {name: (K,)} with any new columns, 'kept': (K,) uint64 input row\n"
        "of each point left, 'stages': [{spec, points_in, points_out, ground}]}.");
}

}  // namespace vola::python
