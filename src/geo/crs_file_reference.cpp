// Pure text, no PROJ: compiled into vola_geo and into the GDAL plugin (which checks every
// CRS it hands GDAL). Scanned by hand, not with std::regex, whose matcher recurses per
// character and may overflow the stack on a long hostile value.
#include <algorithm>
#include <array>
#include <cctype>
#include <string>
#include <string_view>

#include "vola/geo/crs.hpp"

namespace vola::geo {

namespace {

// The parameters of PROJ's operations that name files: init files, and grids
// (hgridshift/vgridshift/gridshift +grids, the datum shifts' +nadgrids and +geoidgrids,
// deformation's +xy_grids/+z_grids, tinshift's +file, defmodel's +model).
constexpr std::array<std::string_view, 3> kFileParameters = {"init", "file", "model"};
constexpr std::array<std::string_view, 5> kGridParameters = {"nadgrids", "geoidgrids", "grids", "xy_grids",
                                                             "z_grids"};

bool is_space(char c) { return std::isspace(static_cast<unsigned char>(c)) != 0; }

// "@null" (PROJ's built-in null grid) in every place of a comma-separated grid list.
bool only_null_grids(std::string_view list) {
  for (std::size_t start = 0; start <= list.size();) {
    const std::size_t comma = std::min(list.find(',', start), list.size());
    if (list.substr(start, comma - start) != "@null") return false;
    start = comma + 1;
  }
  return true;
}

}  // namespace

std::string crs_file_reference(const std::string& crs_text) {
  const std::string_view text(crs_text);
  for (std::size_t plus = text.find('+'); plus != std::string_view::npos; plus = text.find('+', plus + 1)) {
    std::size_t at = plus + 1;
    while (at < text.size() && (std::isalnum(static_cast<unsigned char>(text[at])) || text[at] == '_')) ++at;
    std::string name(text.substr(plus + 1, at - plus - 1));
    std::transform(name.begin(), name.end(), name.begin(), [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
    const bool file = std::find(kFileParameters.begin(), kFileParameters.end(), name) != kFileParameters.end();
    const bool grid = std::find(kGridParameters.begin(), kGridParameters.end(), name) != kGridParameters.end();
    if (!file && !grid) continue;
    while (at < text.size() && is_space(text[at])) ++at;
    if (at == text.size() || text[at] != '=') continue;
    ++at;
    while (at < text.size() && is_space(text[at])) ++at;
    std::size_t end = at;
    while (end < text.size() && !is_space(text[end]) && text[end] != '"' && text[end] != ']') ++end;
    if (file || !only_null_grids(text.substr(at, end - at))) return std::string(text.substr(plus, end - plus));
  }
  return {};
}

}  // namespace vola::geo
