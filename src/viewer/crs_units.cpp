#include "crs_units.hpp"

#include <nlohmann/json.hpp>

#include "vola/error.hpp"
#include "vola/geo/crs.hpp"

namespace vola::viewer {

nlohmann::json crs_units(const Georef& georef) {
  nlohmann::json unknown = {{"crs", nullptr}, {"unit", "units"}, {"north", false}};
  const auto definition = geo::crs_definition(georef);
  if (!definition) return unknown;
  try {
    const geo::CrsDescription d = geo::describe_crs(*definition, geo::EpsgLookup::own_id_only);
    if (d.horizontal_unit.empty()) return unknown;
    return {{"crs", d.name}, {"unit", d.horizontal_unit}, {"north", true}};
  } catch (const Error&) {
    return unknown;  // a CRS PROJ cannot read: its unit is not known
  }
}

}  // namespace vola::viewer
