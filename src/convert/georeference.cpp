#include "georeference.hpp"

#include "vola/error.hpp"
#include "vola/geo/crs.hpp"

namespace vola::convert_detail {

std::optional<std::uint32_t> known_epsg(const ConvertOptions& options, io::Input& input) {
  if (!input.epsg && !input.wkt.empty()) input.epsg = geo::epsg_from_wkt(input.wkt);
  return options.epsg ? options.epsg : input.epsg;
}

std::uint32_t header_epsg(const std::optional<std::uint32_t>& known) { return known.value_or(2000); }

void georeference(Tree& tree, const ConvertOptions& options, const io::Input& input,
                  const std::optional<std::uint32_t>& known, Quantization quantization) {
  Georef& georef = tree.georef();
  georef.epsg = header_epsg(known);
  try {
    const auto [lat, lon] = known || input.wkt.empty() ? geo::centre_lat_lon(georef.epsg, georef.bbox)
                                                       : geo::centre_lat_lon(input.wkt, georef.bbox);
    georef.lat = lat;
    georef.lon = lon;
  } catch (const Error&) {
    if (options.epsg) throw;
  }
  const bool input_has_crs = input.epsg || !input.wkt.empty();
  if (options.epsg && (input_has_crs || quantization == Quantization::grid))
    georef.crs_wkt = geo::crs_wkt(*options.epsg);
  else if (!options.epsg && !input.wkt.empty())
    georef.crs_wkt = input.wkt;
  else if (!options.epsg && input.epsg)
    georef.crs_wkt = geo::crs_wkt(*input.epsg);
}

}  // namespace vola::convert_detail
