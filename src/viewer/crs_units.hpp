// The unit of length and the north of a CRS, for the page's scale bar and north arrow:
// what PROJ (vola::geo::describe_crs) says of the CRS a file or tile index states.
#pragma once

#include <nlohmann/json_fwd.hpp>

#include "vola/frame.hpp"

namespace vola::viewer {

// {"crs": name or null, "unit": "metre" | "foot" | "US survey foot" | ... | "units",
//  "north": whether the grid's +y points north}. "units" and no north when the georef
// states no CRS or PROJ cannot read it: the page then claims nothing it does not know.
// +y is north on a projected CRS (easting, northing) and on a geographic one (longitude,
// latitude: vola puts x = easting/longitude).
nlohmann::json crs_units(const Georef& georef);

}  // namespace vola::viewer
