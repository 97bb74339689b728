// Internal: the georeferencing every tile and overview of one run carries: the CRS
// (header code and WKT), the bbox of its points, and the header's lat/lon of the bbox
// centre through one PROJ transformation made once per run (a transformation per file
// would cost more than building the file).
#pragma once

#include <cstdint>
#include <mutex>
#include <optional>
#include <string>

#include "vola/geo/crs.hpp"
#include "vola/tree.hpp"

namespace vola::tile::detail {

class TileGeoref {
 public:
  TileGeoref(std::optional<std::uint32_t> epsg, std::string crs_wkt);
  // Thread-safe. A centre PROJ cannot transform leaves lat/lon 0, as vola convert does.
  void apply(Tree& tree, const Box& bbox) const;

 private:
  std::optional<std::uint32_t> epsg_;
  std::string crs_wkt_;
  std::optional<geo::ToWgs84> to_wgs84_;
  mutable std::mutex mutex_;  // a PROJ transformation is not for two threads at once
};

}  // namespace vola::tile::detail
