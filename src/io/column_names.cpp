#include "column_names.hpp"

#include <cctype>
#include <utility>

namespace vola::io {

std::string point_column_name(std::string_view field) {
  std::string lower, key;
  for (const char c : field) {
    const char l = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
    lower += l;
    if (l != '_') key += l;
  }
  static constexpr std::pair<std::string_view, std::string_view> kNames[] = {
      {"returnnumber", "return_number"},
      {"numberofreturns", "number_of_returns"},
      {"scandirectionflag", "scan_direction_flag"},
      {"edgeofflightline", "edge_of_flight_line"},
      {"scananglerank", "scan_angle_rank"},
      {"userdata", "user_data"},
      {"pointsourceid", "point_source_id"},
      {"gpstime", "gps_time"},
      {"r", "red"},
      {"g", "green"},
      {"b", "blue"},
  };
  for (const auto& [spelling, name] : kNames)
    if (key == spelling) return std::string(name);
  return lower;
}

Reduction point_column_reduction(const std::string& column) {
  if (column == "classification" || column == "class" || column == "label" || column == "scalar_classification")
    return Reduction::majority;
  if (column == "number_of_returns") return Reduction::max;
  return Reduction::mean;
}

}  // namespace vola::io
