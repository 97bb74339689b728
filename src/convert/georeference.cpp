#include "georeference.hpp"

#include "vola/error.hpp"
#include "vola/geo/crs.hpp"

namespace vola::convert_detail {

ResolvedCrs input_crs(const std::string& path, const ConvertOptions& options, const io::Input& input) {
  const StatedCrs stated{path, input.epsg, input.wkt};
  return resolve_crs(std::span(&stated, 1), options.epsg);
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

void georeference(Tree& tree, const ResolvedCrs& crs, Quantization quantization, CentreLatLon& centre) {
  Georef& georef = tree.georef();
  georef.epsg = header_epsg(crs.epsg);
  try {
    const auto [lat, lon] = centre.lat_lon(georef.bbox);
    georef.lat = lat;
    georef.lon = lon;
  } catch (const Error&) {
    if (crs.given) throw;
  }
  // A code given for input that states no CRS stays out of a toolkit file, which is then
  // byte-identical to the reference's.
  if (!crs.given || crs.stated || quantization == Quantization::grid) georef.crs_wkt = crs.wkt;
}

}  // namespace vola::convert_detail
