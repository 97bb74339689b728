#include "vola/crs_rules.hpp"

#include "vola/error.hpp"
#include "vola/geo/crs.hpp"

namespace vola {

namespace {

std::string described(const std::optional<std::uint32_t>& epsg, const std::string& wkt) {
  if (epsg) return "EPSG:" + std::to_string(*epsg);
  return wkt.empty() ? "nothing" : "a WKT CRS";
}

}  // namespace

ResolvedCrs resolve_crs(std::span<const StatedCrs> inputs, std::optional<std::uint32_t> given) {
  ResolvedCrs out;
  for (const StatedCrs& s : inputs) out.stated = out.stated || s.epsg || !s.wkt.empty();
  if (given) {
    out.epsg = given;
    out.wkt = geo::crs_wkt(*given);  // throws for a code PROJ does not know
    out.given = true;
    return out;
  }
  const StatedCrs* first = nullptr;
  std::optional<std::uint32_t> first_epsg;
  for (const StatedCrs& s : inputs) {
    std::optional<std::uint32_t> epsg = s.epsg;
    if (!epsg && !s.wkt.empty()) epsg = geo::epsg_from_wkt(s.wkt);
    if (!first) {
      first = &s;
      first_epsg = epsg;
      continue;
    }
    const bool same = epsg && first_epsg ? *epsg == *first_epsg : !epsg && !first_epsg && s.wkt == first->wkt;
    if (!same)
      throw InvalidArgument("inputs disagree on the CRS: " + first->source + " says " +
                            described(first_epsg, first->wkt) + ", " + s.source + " says " +
                            (epsg ? described(epsg, s.wkt) : s.wkt.empty() ? "nothing" : "another WKT CRS") +
                            " (convert them separately, or name one CRS if they really are the same)");
  }
  if (!first) return out;
  out.epsg = first_epsg;
  out.wkt = !first->wkt.empty() ? first->wkt : (first_epsg ? geo::crs_wkt(*first_epsg) : std::string());
  return out;
}

}  // namespace vola
