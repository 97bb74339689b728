#include "tile_georef.hpp"

#include <limits>

#include "vola/error.hpp"

namespace vola::tile::detail {

TileGeoref::TileGeoref(std::optional<std::uint32_t> epsg, std::string crs_wkt)
    : epsg_(epsg), crs_wkt_(std::move(crs_wkt)) {
  if (!epsg_ && crs_wkt_.empty()) return;  // no CRS: nothing to place
  try {
    to_wgs84_.emplace(epsg_ ? "EPSG:" + std::to_string(*epsg_) : crs_wkt_);
  } catch (const Error&) {  // a CRS PROJ cannot place: lat/lon stay 0
  }
}

void TileGeoref::apply(Tree& tree, const Box& bbox) const {
  Georef& g = tree.georef();
  g.epsg = epsg_.value_or(geo::kUnsetEpsg);
  g.crs_wkt = crs_wkt_;
  g.bbox = bbox;
  if (!to_wgs84_) return;
  const Point centre{(bbox.min[0] + bbox.max[0]) / 2.0, (bbox.min[1] + bbox.max[1]) / 2.0,
                     (bbox.min[2] + bbox.max[2]) / 2.0};  // z places a geocentric CRS's points
  try {
    const std::lock_guard lock(mutex_);
    const Point lon_lat = to_wgs84_->transform(centre);
    g.lat = lon_lat[1];
    g.lon = lon_lat[0];
  } catch (const Error&) {
    // Outside the CRS's domain: no position, written as vola convert (and the reference
    // toolkit) write it, +inf, rather than a tile placed at (0, 0).
    g.lat = g.lon = std::numeric_limits<double>::infinity();
  }
}

}  // namespace vola::tile::detail
