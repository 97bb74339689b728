// Internal to the conversion pipeline: the CRS rules, decided once for every front end.
#pragma once

#include <cstdint>
#include <future>
#include <optional>
#include <string>
#include <utility>

#include "vola/convert.hpp"
#include "vola/crs_rules.hpp"
#include "vola/geo/crs.hpp"
#include "vola/io/input.hpp"

namespace vola::convert_detail {

// The input's CRS under the rules of vola/crs_rules.hpp (the code given wins).
ResolvedCrs input_crs(const std::string& path, const ConvertOptions& options, const io::Input& input);

// The code the VOLA header carries: the known one, else the reference's default (2000).
std::uint32_t header_epsg(const std::optional<std::uint32_t>& known);

// The WGS84 (lat, lon) of the bbox centre, as geo::centre_lat_lon gives it. PROJ's
// transformation (its database, a third of a small conversion) is created on another
// thread while the tree is built; lat_lon() waits for it and rethrows its error.
class CentreLatLon {
 public:
  // The CRS the header's lat/lon are computed from: the known code (or the reference's
  // default), else the input's WKT.
  CentreLatLon(const std::optional<std::uint32_t>& known, const io::Input& input);
  std::pair<double, double> lat_lon(const Box& bbox);

 private:
  std::future<geo::ToWgs84> transform_;
};

// The tree's georeference after the build: the header code, the WGS84 lat/lon of the
// bbox centre (through PROJ; 0, 0 when PROJ cannot place a CRS nobody named), and the CRS
// as WKT in the extension whenever it is known, except for a toolkit conversion of
// CRS-less input, which stays byte-identical to the reference's file.
void georeference(Tree& tree, const ResolvedCrs& crs, Quantization quantization, CentreLatLon& centre);

}  // namespace vola::convert_detail
