// The entry points of libvola_proj.so, vola's coordinate reference systems through PROJ
// (src/plugin/plugin.hpp says why it is a plugin): crs.cpp forwards vola/geo/crs.hpp to
// them. Each reports errors through its PluginFailure.
#pragma once

#include <cstddef>
#include <cstdint>
#include <optional>
#include <string>
#include <utility>

#include "../plugin/plugin.hpp"
#include "vola/frame.hpp"
#include "vola/geo/crs.hpp"

namespace vola::geo::plugin {

using vola::plugin::PluginFailure;

struct ProjEntries {
  void (*centre_lat_lon)(const std::string& crs, const Box& bbox, std::pair<double, double>& out, PluginFailure& failure);
  void (*crs_wkt)(std::uint32_t epsg, std::string& out, PluginFailure& failure);
  void (*epsg_from_wkt)(const std::string& wkt, std::optional<std::uint32_t>& out, PluginFailure& failure);
  void (*crs_wkt1)(const std::string& definition, std::string& out, PluginFailure& failure);
  // A transformation to WGS84 longitude/latitude: opened, used from any number of calls,
  // closed. `state` is the plugin's own.
  void (*to_wgs84_open)(const std::string& definition, void*& state, PluginFailure& failure);
  void (*to_wgs84_transform)(const void* state, const Point& in, Point& out, PluginFailure& failure);
  void (*to_wgs84_close)(void* state);
  void (*same_crs)(const std::string& a, const std::string& b, bool& out, PluginFailure& failure);
  void (*describe_crs)(const std::string& definition, EpsgLookup lookup, CrsDescription& out,
                       PluginFailure& failure);
  // A transformation between two CRSs (x = easting/longitude in and out), for one thread
  // at a time: opened, used for many batches of x y z triples in place, closed.
  void (*reprojection_open)(const std::string& from, const std::string& to, void*& state, PluginFailure& failure);
  void (*reprojection_transform)(void* state, double* xyz, std::size_t points, PluginFailure& failure);
  void (*reprojection_close)(void* state);
  void (*crs_wkt_of)(const std::string& definition, std::string& out, PluginFailure& failure);
  void (*keyed_projected_crs)(std::uint32_t epsg, std::uint32_t linear_unit, std::uint32_t vertical_unit,
                              std::string& out, PluginFailure& failure);
};

using ProjEntriesEntry = const ProjEntries* (*)();
inline constexpr const char* kProjEntriesSymbol = "vola_plugin_proj_entries";

}  // namespace vola::geo::plugin
