#include "georeference.hpp"

#include <algorithm>
#include <cstdio>
#include <limits>

#include "vola/error.hpp"
#include "vola/geo/crs.hpp"

namespace vola::convert_detail {

namespace {

// The CRS of the result as PROJ reads it (empty when none is known).
std::string result_definition(const ResolvedCrs& crs) {
  return !crs.wkt.empty() ? crs.wkt : crs.epsg ? "EPSG:" + std::to_string(*crs.epsg) : "";
}

// Points voxelised in the CRS's own x and y (not voxel grids or meshes, which keep theirs).
bool voxelises_points(const io::Input& input) { return !input.grid && !input.is_mesh(); }

// How to get cubes from an input in degrees: `target_crs` reprojects points, not a DEM's
// raster, which is warped first.
std::string cubes_advice(const io::Input& input) {
  return input.terrain ? "reproject the raster first (gdalwarp -t_srs with a projected CRS such as UTM)"
                       : "give `target_crs` (a projected CRS such as UTM)";
}

std::string geographic_name(const std::string& definition) {
  try {
    return geo::describe_crs(definition, geo::EpsgLookup::own_id_only).name;
  } catch (const Error&) {
    return definition.substr(0, 60);
  }
}

// The CRS the input is read in: what the options give (`assign_crs` relabels the file),
// else what its file states; as resolve_crs and vola tile decide it.
std::string given_or_stated(const std::string& stated, const std::string& given) {
  return !given.empty() ? crs_definition_of(given) : stated;
}

// The sentence of vola::implausible_degrees (or implausible_geocentric) for the points
// read whole, else for the box the file's header states (a LAS file streams later).
std::string label_doubt(const std::string& definition, const io::Input& input) {
  const PointCloud& cloud = input.cloud;
  Box box;
  if (cloud.xyz.size() < 3) {
    if (!input.stated_bounds) return "";
    box = *input.stated_bounds;
  } else {
    box = {{cloud.xyz[0], cloud.xyz[1], cloud.xyz[2]}, {cloud.xyz[0], cloud.xyz[1], cloud.xyz[2]}};
    for (std::size_t i = 0; i + 2 < cloud.xyz.size(); i += 3)
      for (std::size_t a = 0; a < 3; ++a) {
        box.min[a] = std::min(box.min[a], cloud.xyz[i + a]);
        box.max[a] = std::max(box.max[a], cloud.xyz[i + a]);
      }
  }
  const std::string degrees = vola::implausible_degrees(definition, box.min[0], box.min[1], box.max[0], box.max[1]);
  return !degrees.empty() ? degrees : vola::implausible_geocentric(definition, box);
}

}  // namespace

std::string given_crs(const ConvertOptions& options) {
  return options.epsg ? std::to_string(*options.epsg) : options.assign_crs;
}

ResolvedCrs input_crs(const std::string& path, const ConvertOptions& options, const io::Input& input) {
  const StatedCrs stated{path, input.epsg, input.wkt};
  return resolve_crs(std::span(&stated, 1), given_crs(options));
}

void refuse_geographic_grid(const std::string& path, const ConvertOptions& options, const io::Input& input,
                            const ResolvedCrs& crs, Quantization quantization) {
  if (options.allow_geographic || quantization != Quantization::grid || !voxelises_points(input)) return;
  const std::string result = result_definition(crs);
  if (result.empty() || !is_geographic_crs(result)) return;
  if (!options.target_crs.empty())  // the target's fault, not the file's
    throw OptionError("target_crs", "'" + options.target_crs.substr(0, 60) + "' is " + geographic_name(result) +
                                        ", a geographic CRS: voxels would be degrees of longitude and latitude by " +
                                        "units of height, not cubes; give a projected CRS (such as UTM), or " +
                                        "`allow_geographic` to voxelise in degrees anyway");
  // Coordinates no degree can be: the label, not the CRS, is what to fix.
  if (const std::string doubt = label_doubt(result, input); !doubt.empty())
    throw OptionError("", path + ": " + doubt + " (then `target_crs` reprojects from it, if needed)");
  throw OptionError("", path + " is in " + geographic_name(result) +
                                      ", a geographic CRS: voxels would be degrees of longitude and latitude by " +
                                      "units of height, not cubes; " + cubes_advice(input) +
                                      ", or `allow_geographic` to voxelise in degrees anyway");
}

std::vector<std::string> crs_warnings(const std::string& path, const ConvertOptions& options, const io::Input& input,
                                      const ResolvedCrs& crs) {
  std::vector<std::string> out;
  const std::string given = given_crs(options);
  try {
    const std::string stated = !input.wkt.empty() ? input.wkt : input.epsg ? "EPSG:" + std::to_string(*input.epsg) : "";
    if (!given.empty() && !stated.empty() && relabels_horizontally(stated, crs_definition_of(given)))
      out.push_back(path + " states " + geo::crs_summary(geo::describe_crs(stated)) + "; `assign_crs` " +
                    given.substr(0, 60) + " relabels its coordinates without moving them" +
                    (options.target_crs.empty() ? " (to move them, give `target_crs`)"
                                                : ", and `target_crs` reprojects them from that label, not from the "
                                                  "CRS the file states"));
    if (!options.target_crs.empty() && !given_or_stated(stated, given).empty())
      if (const std::string heights = unconverted_heights(given_or_stated(stated, given), options.target_crs);
          !heights.empty())
        out.push_back(path + ": " + heights);
    const std::string result = result_definition(crs);
    if (!result.empty() && voxelises_points(input))
      if (const std::string mixed = mixed_units(result); !mixed.empty()) out.push_back(mixed);
    if (!result.empty() && voxelises_points(input) && is_geographic_crs(result))
      out.push_back("the CRS (" + geographic_name(result) + ") is geographic: voxels are degrees of longitude and " +
                    "latitude by units of height, not cubes; " + cubes_advice(input) + " for cubes");
  } catch (const Error&) {
    // A CRS PROJ cannot read draws no warning here; the conversion reports it if it matters.
  }
  return out;
}

std::string implausible_label(const std::string& path, const ResolvedCrs& crs, const Box& bounds) {
  const std::string definition = result_definition(crs);
  std::string label = vola::implausible_degrees(definition, bounds.min[0], bounds.min[1], bounds.max[0], bounds.max[1]);
  if (label.empty()) label = vola::implausible_geocentric(definition, bounds);
  return label.empty() ? label : path + ": " + label;
}

void reproject_heights(const geo::Reprojection& reprojection, PointCloud& cloud) {
  for (auto& column : cloud.attributes) {
    if (column.name != "height" || column.values.size() != cloud.size()) continue;
    std::vector<double> at(cloud.xyz);  // (x, y, height): the height moves as a z there would
    for (std::size_t i = 0; i < cloud.size(); ++i) at[3 * i + 2] = column.values[i];
    reprojection.transform(at);
    for (std::size_t i = 0; i < cloud.size(); ++i) column.values[i] = at[3 * i + 2];
  }
}

std::uint32_t header_epsg(const std::optional<std::uint32_t>& known) { return known.value_or(2000); }

ResolvedCrs reproject(const std::string& path, const ConvertOptions& options, io::Input& input) {
  if (input.is_mesh() || input.grid || input.terrain)
    throw OptionError("target_crs", "reprojects points; " + path + " is " + input.format + " input" +
                                        (input.terrain ? ": warp the raster first (gdalwarp -t_srs CRS in.tif out.tif)"
                                                       : ""));
  const ResolvedCrs source = input_crs(path, options, input);
  if (!source.epsg && source.wkt.empty())
    throw OptionError("target_crs", path + " states no CRS to reproject from; name it with `assign_crs`");
  const std::string from = source.wkt.empty() ? "EPSG:" + std::to_string(*source.epsg) : source.wkt;
  const std::string to = crs_definition_of(options.target_crs);
  // PROJ would fail on the first point, naming nothing the user can act on.
  if (const std::string doubt = label_doubt(from, input); !doubt.empty())
    throw OptionError("", path + ": " + doubt + " to reproject from");
  geo::Reprojection reprojection(from, to);
  reproject_heights(reprojection, input.cloud);
  reprojection.transform(input.cloud.xyz);
  ResolvedCrs target;
  target.wkt = geo::crs_wkt(to);
  target.epsg = geo::epsg_from_wkt(target.wkt);
  target.given = true;
  target.stated = true;
  return target;
}

CentreLatLon::CentreLatLon(const std::optional<std::uint32_t>& known, const std::string& wkt) {
  const std::string definition = known || wkt.empty() ? "EPSG:" + std::to_string(header_epsg(known)) : wkt;
  transform_ = std::async(std::launch::async, [definition] { return geo::ToWgs84(definition); });
}

std::optional<std::pair<double, double>> CentreLatLon::lat_lon(const Box& bbox) {
  const Point centre{(bbox.min[0] + bbox.max[0]) / 2.0, (bbox.min[1] + bbox.max[1]) / 2.0,
                     (bbox.min[2] + bbox.max[2]) / 2.0};  // z places a geocentric CRS's points
  const geo::ToWgs84 transform = transform_.get();        // throws for a CRS PROJ does not know
  try {
    const Point lon_lat = transform.transform(centre);
    return std::pair{lon_lat[1], lon_lat[0]};
  } catch (const Error&) {
    return std::nullopt;  // outside the CRS's domain
  }
}

std::optional<std::string> georeference(Tree& tree, const ResolvedCrs& crs, Quantization quantization,
                                        CentreLatLon& centre) {
  Georef& georef = tree.georef();
  georef.epsg = header_epsg(crs.epsg);
  std::optional<std::string> warning;
  try {
    if (const auto lat_lon = centre.lat_lon(georef.bbox)) {
      georef.lat = lat_lon->first;
      georef.lon = lat_lon->second;
    } else {
      // PROJ gives no position there, and the reference toolkit writes what pyproj then
      // returns, +inf for both: the file is still the reference's, byte for byte.
      georef.lat = georef.lon = std::numeric_limits<double>::infinity();
      if (crs.given || crs.stated) {
        char at[96];
        std::snprintf(at, sizeof at, "(%.10g, %.10g)", (georef.bbox.min[0] + georef.bbox.max[0]) / 2,
                      (georef.bbox.min[1] + georef.bbox.max[1]) / 2);
        warning = "the bbox centre " + std::string(at) + " lies outside the domain of " +
                  (crs.epsg ? "EPSG:" + std::to_string(*crs.epsg) : std::string("the CRS")) +
                  ": PROJ gives it no latitude and longitude, so the header's lat/lon are inf, as the reference "
                  "toolkit writes them (is the CRS the points' own?)";
      }
    }
  } catch (const Error&) {
    if (crs.given) throw;
  }
  // A code given for input that states no CRS stays out of a toolkit file, which is then
  // byte-identical to the reference's.
  if (!crs.given || crs.stated || quantization == Quantization::grid) georef.crs_wkt = crs.wkt;
  return warning;
}

}  // namespace vola::convert_detail
