#include "georeference.hpp"

#include "vola/error.hpp"
#include "vola/geo/crs.hpp"

namespace vola::convert_detail {

std::optional<std::uint32_t> known_epsg(const ConvertOptions& options, io::Input& input) {
  if (!input.epsg && !input.wkt.empty()) input.epsg = geo::epsg_from_wkt(input.wkt);
  return options.epsg ? options.epsg : input.epsg;
}

std::uint32_t header_epsg(const std::optional<std::uint32_t>& known) { return known.value_or(2000); }

CentreLatLon::CentreLatLon(const std::optional<std::uint32_t>& known, const io::Input& input) {
  const std::string definition =
      known || input.wkt.empty() ? "EPSG:" + std::to_string(header_epsg(known)) : input.wkt;
  transform_ = std::async(std::launch::async, [definition] { return geo::ToWgs84(definition); });
}

std::pair<double, double> CentreLatLon::lat_lon(const Box& bbox) {
  const Point centre{(bbox.min[0] + bbox.max[0]) / 2.0, (bbox.min[1] + bbox.max[1]) / 2.0, 0.0};
  const Point lon_lat = transform_.get().transform(centre);
  return {lon_lat[1], lon_lat[0]};
}

void georeference(Tree& tree, const ConvertOptions& options, const io::Input& input,
                  const std::optional<std::uint32_t>& known, Quantization quantization, CentreLatLon& centre) {
  Georef& georef = tree.georef();
  georef.epsg = header_epsg(known);
  try {
    const auto [lat, lon] = centre.lat_lon(georef.bbox);
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
