// The entry points of the reader plugins libvola_gdal.so (elevation rasters through
// GDAL) and libvola_assimp.so (meshes through Assimp); see src/plugin/plugin.hpp for why
// they are plugins.
#pragma once

#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include "../plugin/plugin.hpp"
#include "vola/io/dem.hpp"
#include "vola/io/input.hpp"

namespace vola::io {

using vola::plugin::PluginFailure;

namespace plugin {

// Entry points, looked up by these names (extern "C", so unmangled).
using ReadDemEntry = void (*)(const std::string& path, const std::function<void(std::uint64_t, std::uint64_t)>& progress,
                              DemRaster& out, PluginFailure& failure);
using ReadMeshEntry = void (*)(const std::string& path, std::vector<Triangle>& out, PluginFailure& failure);
inline constexpr const char* kReadDemSymbol = "vola_plugin_read_dem";
inline constexpr const char* kReadMeshSymbol = "vola_plugin_read_mesh";

}  // namespace plugin
}  // namespace vola::io
