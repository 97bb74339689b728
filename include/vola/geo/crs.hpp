// Coordinate reference systems through PROJ: the header's lat/lon of the bbox centre
// (as the reference computes it) and the CRS as WKT for our extension.
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <utility>

#include "vola/frame.hpp"

namespace vola::geo {

// WGS84 (lat, lon) of the bbox centre ((minx+maxx)/2, (miny+maxy)/2) given in
// EPSG:`epsg`, with x = easting/longitude (PROJ's always_xy). Throws vola::Error for
// a code PROJ does not know or a point it cannot transform.
std::pair<double, double> centre_lat_lon(std::uint32_t epsg, const Box& bbox);
// The same for a CRS given as WKT (or any definition PROJ accepts).
std::pair<double, double> centre_lat_lon(const std::string& crs, const Box& bbox);

// The CRS as WKT2 (2019), or throws vola::Error for an unknown code.
std::string crs_wkt(std::uint32_t epsg);

// The EPSG code of a CRS given as WKT (the horizontal part of a compound CRS), from
// its own identifier or, failing that, PROJ's identification with confidence >= 70%.
std::optional<std::uint32_t> epsg_from_wkt(const std::string& wkt);

}  // namespace vola::geo
