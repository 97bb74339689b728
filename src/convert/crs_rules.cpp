#include "vola/crs_rules.hpp"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdio>
#include <string_view>

#include "vola/error.hpp"
#include "vola/filters/units.hpp"
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

namespace {

// A definition, not a name: PROJ also takes CRS names and matches them loosely ("foo"
// became Amersfoort, "wgs" WGS 72, "UTM zone 10N" a conversion), which relabels or
// reprojects a survey into whatever it guessed.
bool is_definition(const std::string& text) {
  // Scanned by hand: std::regex recurses per character, and a WKT may be long.
  const auto word = [](char c) { return std::isalnum(static_cast<unsigned char>(c)) != 0 || c == '_'; };
  const auto space = [](char c) { return std::isspace(static_cast<unsigned char>(c)) != 0; };
  std::string_view t(text);
  while (!t.empty() && space(t.front())) t.remove_prefix(1);
  while (!t.empty() && space(t.back())) t.remove_suffix(1);
  if (t.empty()) return false;
  if (t.front() == '{') return true;                              // PROJJSON
  if (t.find("proj=") != std::string_view::npos) return true;     // PROJ string (+proj=utm +zone=10 ...)
  if (t.size() > 12 && (t.substr(0, 12) == "urn:ogc:def:" || t.substr(0, 12) == "URN:OGC:DEF:")) return true;
  std::size_t i = 0;
  while (i < t.size() && word(t[i])) ++i;
  std::size_t j = i;
  while (j < t.size() && space(t[j])) ++j;
  if (i > 0 && j < t.size() && (t[j] == '[' || t[j] == '(')) return true;  // WKT: PROJCS[, PROJCRS[ ...
  // AUTHORITY:CODE (EPSG:4326, ESRI:102100, IGNF:LAMB93, EPSG:4326+5703).
  if (!std::isalpha(static_cast<unsigned char>(t.front()))) return false;
  const std::size_t colon = t.find(':');
  if (colon == std::string_view::npos || colon + 1 == t.size()) return false;
  for (std::size_t k = 0; k < colon; ++k)
    if (!word(t[k]) && t[k] != '.' && t[k] != '-') return false;
  for (std::size_t k = colon + 1; k < t.size(); ++k)
    if (!word(t[k]) && t[k] != '.' && t[k] != '+' && t[k] != '-') return false;
  return true;
}

}  // namespace

std::string crs_definition_of(const std::string& given) {
  const bool digits = !given.empty() && given.find_first_not_of("0123456789") == std::string::npos;
  if (digits) return "EPSG:" + given;
  if (!is_definition(given)) {
    std::string guess;
    try {
      guess = " (PROJ would guess " + geo::crs_summary(geo::describe_crs(given)) + ")";
    } catch (const Error&) {
    }
    throw InvalidArgument("'" + given.substr(0, 60) +
                          "' is not a CRS definition: give an EPSG code (32610 or EPSG:32610), AUTHORITY:CODE, "
                          "WKT, PROJJSON or a PROJ string (+proj=...); names are not taken" +
                          guess);
  }
  // A PROJ string without +type=crs is an operation to PROJ, not a CRS.
  if (given.find("proj=") != std::string::npos && given.find("type=crs") == std::string::npos)
    return given + " +type=crs";
  return given;
}

std::optional<std::uint32_t> epsg_code_of(const std::string& given) {
  std::string digits = given;
  if (digits.size() > 5 && (digits.compare(0, 5, "EPSG:") == 0 || digits.compare(0, 5, "epsg:") == 0))
    digits = digits.substr(5);
  if (digits.empty() || digits.size() > 9 || digits.find_first_not_of("0123456789") != std::string::npos)
    return std::nullopt;
  return static_cast<std::uint32_t>(std::stoul(digits));
}

ResolvedCrs resolve_crs(std::span<const StatedCrs> inputs, const std::string& given) {
  ResolvedCrs out;
  for (const StatedCrs& s : inputs) out.stated = out.stated || s.epsg || !s.wkt.empty();
  if (!given.empty()) {
    // Both throw for a CRS PROJ does not know. A code keeps the WKT its code gives.
    out.epsg = epsg_code_of(given);
    out.wkt = out.epsg ? geo::crs_wkt(*out.epsg) : geo::crs_wkt(crs_definition_of(given));
    if (!out.epsg) out.epsg = geo::epsg_from_wkt(out.wkt);
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
                            " (reproject them into one with --target-crs CRS, convert them separately, or name one CRS with "
                            "--assign-crs if they really are the same)");
  }
  if (!first) return out;
  out.epsg = first_epsg;
  out.wkt = !first->wkt.empty() ? first->wkt : (first_epsg ? geo::crs_wkt(*first_epsg) : std::string());
  return out;
}

bool is_geographic_crs(const std::string& definition) {
  try {
    // The horizontal unit catches a compound CRS on a geographic one (EPSG:4326+5703).
    const geo::CrsDescription d = geo::describe_crs(definition, geo::EpsgLookup::own_id_only);
    return d.kind.rfind("geographic", 0) == 0 || d.horizontal_unit.find("degree") != std::string::npos;
  } catch (const Error&) {
    return false;
  }
}

std::string unconverted_heights(const std::string& source, const std::string& target) {
  try {
    const geo::CrsDescription from = geo::describe_crs(crs_definition_of(source), geo::EpsgLookup::own_id_only);
    const geo::CrsDescription to = geo::describe_crs(crs_definition_of(target), geo::EpsgLookup::own_id_only);
    // A compound source reprojected to a target without a vertical part: PROJ moves x and
    // y and leaves z in the source's vertical unit (Autzen's EPSG:2991+6360 to EPSG:32610
    // kept its heights in US survey feet under a metre CRS).
    if (!from.vertical_name.empty() && to.vertical_name.empty() && !from.vertical_unit.empty() &&
        to.horizontal_unit != "degree" && from.vertical_unit != to.horizontal_unit)
      return "heights (z) stay in " + from.vertical_unit + " (" + from.vertical_name + ") while x and y go to " +
             to.horizontal_unit +
             ": the target has no vertical part to convert them to; give it one (a compound "
             "CRS such as EPSG:32610+5703) to convert them";
    // A source without a vertical part reprojected to a compound target: PROJ leaves z as
    // it is, now labelled with the target's vertical unit (Autzen's feet to
    // EPSG:32610+5703 came out as NAVD88 metres holding feet).
    if (from.vertical_name.empty() && !to.vertical_name.empty() && !to.vertical_unit.empty() &&
        from.horizontal_unit != "degree" && !from.horizontal_unit.empty() && from.horizontal_unit != to.vertical_unit)
      return "heights (z) stay in " + from.horizontal_unit + " though the target says " + to.vertical_unit + " (" +
             to.vertical_name + "): the source has no vertical part for PROJ to convert them from; give it one " +
             "(`assign_crs` with a compound CRS, such as EPSG:2994+6360 for Oregon Lambert feet and NAVD88 feet) " +
             "to convert them";
    // Metres beside a geographic 2D CRS are what such a CRS means (its heights are metres
    // above the ellipsoid), so a metre source going to degrees keeps the right unit.
    if (!from.vertical_name.empty() || !to.vertical_name.empty() || from.horizontal_unit == "degree" ||
        from.horizontal_unit == to.horizontal_unit ||
        (to.horizontal_unit == "degree" && from.horizontal_unit == "metre"))
      return "";
    return "heights (z) stay in " + from.horizontal_unit + " while x and y go to " + to.horizontal_unit +
           ": neither CRS has a vertical axis to convert them by (PROJ and PDAL do the same); give both a "
           "vertical part (a compound CRS such as EPSG:32610+5703) to convert them";
  } catch (const Error&) {
    return "";
  }
}

bool relabels_horizontally(const std::string& stated, const std::string& assigned) {
  if (geo::same_crs(stated, assigned)) return false;
  const geo::CrsDescription a = geo::describe_crs(assigned);
  return a.vertical_name.empty() || !a.epsg || !geo::same_crs(stated, "EPSG:" + std::to_string(*a.epsg));
}

std::string mixed_units(const std::string& definition) {
  try {
    const geo::CrsDescription d = geo::describe_crs(crs_definition_of(definition), geo::EpsgLookup::own_id_only);
    if (d.vertical_name.empty() || d.vertical_unit.empty() || d.horizontal_unit.empty() ||
        d.vertical_unit == d.horizontal_unit || d.horizontal_unit == "degree")
      return "";
    return "the CRS's heights are in " + d.vertical_unit + " (" + d.vertical_name + ") and x and y in " +
           d.horizontal_unit + ": a voxel is as many " + d.horizontal_unit + " across as " + d.vertical_unit +
           " high, not a cube; reproject to a CRS in one unit (a compound CRS such as EPSG:32610+5703) for cubes";
  } catch (const Error&) {
    return "";
  }
}

std::string implausible_degrees(const std::string& definition, double min_x, double min_y, double max_x, double max_y) {
  if (definition.empty() || !is_geographic_crs(definition)) return "";
  if (!(std::max(std::abs(min_x), std::abs(max_x)) > 180.0 || std::max(std::abs(min_y), std::abs(max_y)) > 90.0))
    return "";
  std::string name = definition.substr(0, 60);
  try {
    name = geo::describe_crs(definition, geo::EpsgLookup::own_id_only).name;
  } catch (const Error&) {
    // The definition's first characters name it well enough.
  }
  char reach[96];
  std::snprintf(reach, sizeof reach, "x reaches %.10g and y %.10g", max_x, max_y);
  return std::string(reach) + ", beyond any longitude and latitude, under " + name +
         ": the CRS label is likely wrong (metres of a projected CRS?); give the right one with `assign_crs`";
}

std::string implausible_geocentric(const std::string& definition, const Box& box) {
  if (definition.empty()) return "";
  geo::CrsDescription d;
  try {
    d = geo::describe_crs(definition, geo::EpsgLookup::own_id_only);
  } catch (const Error&) {
    return "";
  }
  if (d.kind != "geocentric") return "";
  // GDAL's reading of geocentric keys without a unit key says "unknown" (factor 1): metres.
  const double metres =
      d.horizontal_unit == "unknown" ? 1.0 : filters::metres_per_unit(d.horizontal_unit).value_or(0.0);
  if (!(metres > 0)) return "";
  // The box's nearest point to the earth's centre and its farthest corner, in km.
  double near2 = 0, far2 = 0;
  for (int a = 0; a < 3; ++a) {
    const double lo = box.min[a] * metres, hi = box.max[a] * metres;
    const double nearest = lo > 0 ? lo : hi < 0 ? hi : 0.0;
    near2 += nearest * nearest;
    far2 += std::max(lo * lo, hi * hi);
  }
  const double near_km = std::sqrt(near2) / 1000.0, far_km = std::sqrt(far2) / 1000.0;
  // The earth's radius is 6357-6378 km; the deepest trench and the highest flights lie
  // within 20 km of it. A box wholly inside 6200 km or wholly beyond 6500 km holds no
  // earth-centred point (a continent-wide survey's box reaches the shell: its centre lies
  // deep inside the earth, its corners do not).
  if (!std::isfinite(near_km) || !std::isfinite(far_km) || (far_km >= 6200.0 && near_km <= 6500.0)) return "";
  char where[128];
  if (far_km < 6200.0)
    std::snprintf(where, sizeof where, "the points lie at most %.0f km from the earth's centre", far_km);
  else
    std::snprintf(where, sizeof where, "the points lie at least %.0f km from the earth's centre", near_km);
  return std::string(where) + ", not near its surface (about 6370 km), under " + d.name +
         ", a geocentric CRS: the CRS label is likely wrong (metres of a projected CRS?); give the right one with "
         "`assign_crs`";
}

}  // namespace vola
