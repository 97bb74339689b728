#include "vola/crs_rules.hpp"

#include "vola/error.hpp"
#include "vola/geo/crs.hpp"

namespace vola {

namespace {

// How an error names what an input says: its code, else PROJ's name for its WKT.
std::string described(const StatedCrs& s, const std::optional<std::uint32_t>& epsg) {
  if (epsg) return "EPSG:" + std::to_string(*epsg);
  if (s.wkt.empty()) return "nothing";
  try {
    return "\"" + geo::describe_crs(s.wkt).name + "\" (a WKT CRS with no EPSG code)";
  } catch (const Error&) {
    return "a WKT CRS that PROJ cannot read";
  }
}

// What PROJ reads: the stated WKT (the input's own words), else the code.
std::string definition(const StatedCrs& s, const std::optional<std::uint32_t>& epsg) {
  return !s.wkt.empty() ? s.wkt : "EPSG:" + std::to_string(*epsg);
}

// Two inputs name the same CRS: the same code (no PROJ needed), both nothing, or PROJ
// finds their definitions equivalent (two tools spell the same WKT differently).
bool same_meaning(const StatedCrs& a, const std::optional<std::uint32_t>& a_epsg, const StatedCrs& b,
                  const std::optional<std::uint32_t>& b_epsg) {
  const bool a_none = !a_epsg && a.wkt.empty(), b_none = !b_epsg && b.wkt.empty();
  if (a_none || b_none) return a_none == b_none;
  if (a_epsg && b_epsg && *a_epsg == *b_epsg) return true;
  if (a.wkt == b.wkt && !a.wkt.empty()) return true;
  try {
    return geo::same_crs(definition(a, a_epsg), definition(b, b_epsg));
  } catch (const Error&) {
    return false;  // PROJ cannot read one of them: not provably the same
  }
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
    if (!same_meaning(*first, first_epsg, s, epsg))
      throw InvalidArgument("inputs disagree on the CRS: " + first->source + " says " + described(*first, first_epsg) +
                            ", " + s.source + " says " + described(s, epsg) +
                            " (convert them separately, or name one CRS if they really are the same)");
  }
  if (!first) return out;
  out.epsg = first_epsg;
  out.wkt = !first->wkt.empty() ? first->wkt : (first_epsg ? geo::crs_wkt(*first_epsg) : std::string());
  return out;
}

}  // namespace vola
