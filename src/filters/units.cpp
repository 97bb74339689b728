#include "vola/filters/units.hpp"

#include "vola/error.hpp"
#include "vola/geo/crs.hpp"

namespace vola::filters {

std::optional<double> metres_per_unit(const std::string& unit) {
  if (unit == "metre" || unit == "meter" || unit == "m") return 1.0;
  if (unit == "foot" || unit == "international foot" || unit == "ft") return 0.3048;
  if (unit == "US survey foot" || unit == "US survey foot (1893)") return 1200.0 / 3937.0;
  if (unit == "kilometre" || unit == "kilometer") return 1000.0;
  if (unit == "centimetre" || unit == "centimeter") return 0.01;
  if (unit == "millimetre" || unit == "millimeter") return 0.001;
  if (unit == "Clarke's foot") return 0.3047972654;
  if (unit == "British foot (Sears 1922)") return 0.30479947153867626;
  return std::nullopt;
}

Units units_of_crs(const std::optional<std::uint32_t>& epsg, const std::string& wkt_given) {
  // An empty WKT record (some writers leave one) says nothing.
  const bool blank = wkt_given.find_first_not_of(std::string(" \t\r\n\0", 5)) == std::string::npos;
  const std::string wkt = blank ? std::string() : wkt_given;
  if (wkt.empty() && !epsg) return {};
  geo::CrsDescription crs;
  try {
    crs = geo::describe_crs(wkt.empty() ? "EPSG:" + std::to_string(*epsg) : wkt, geo::EpsgLookup::own_id_only);
  } catch (const Error&) {
    // A WKT record PROJ cannot read (pdal_warsaw_small.las holds "''") states no CRS.
    if (!epsg || wkt.empty()) return {};
    crs = geo::describe_crs("EPSG:" + std::to_string(*epsg), geo::EpsgLookup::own_id_only);
  }
  const auto horizontal = metres_per_unit(crs.horizontal_unit);
  if (!horizontal)
    throw OptionError(
        "", "smrf: the points' CRS (" + crs.name + ") has coordinates in " +
                (crs.horizontal_unit.empty() ? std::string("no length unit") : crs.horizontal_unit) +
                ", not a length, and SMRF's cell, window and thresholds are metres; filters run before any "
                "reprojection, so reproject the points with another tool first (PDAL's "
                "filters.reprojection), or, if the label is wrong, relabel them (vola convert's `assign_crs`; "
                "translate and pipeline keep the file's CRS)");
  Units units;
  units.horizontal = *horizontal;
  units.vertical = *horizontal;
  if (!crs.vertical_unit.empty())
    if (const auto vertical = metres_per_unit(crs.vertical_unit)) units.vertical = *vertical;
  return units;
}

}  // namespace vola::filters
