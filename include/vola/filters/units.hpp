// The length units of a point cloud's coordinates, so that filters whose parameters are
// metres (the ground filter's cell, window and thresholds) work on surveys in feet.
#pragma once

#include <cstdint>
#include <optional>
#include <string>

namespace vola::filters {

struct Units {
  double horizontal = 1.0;  // metres per x/y unit
  double vertical = 1.0;    // metres per z unit
};

// Metres per unit of a PROJ unit name ("metre", "foot", "US survey foot", ...); nothing
// for an angle or a unit it does not know.
std::optional<double> metres_per_unit(const std::string& unit_name);

// The units of a CRS (an EPSG code or a WKT; the WKT wins), through PROJ: its horizontal
// unit, and its vertical one when it is compound, else the horizontal one (LAS stores z
// in the unit of x and y). No CRS at all, or a WKT PROJ cannot read and no code: metres. Throws InvalidArgument for a geographic
// CRS (degrees cannot be metres: reproject first) and for a unit it does not know.
Units units_of_crs(const std::optional<std::uint32_t>& epsg, const std::string& wkt);

}  // namespace vola::filters
