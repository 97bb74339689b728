// read_dem and read_mesh_triangles: the GDAL and Assimp plugins' entry points, called
// through reader_plugin (see reader_plugin.hpp for why they are plugins).
#include "reader_plugin.hpp"
#include "vola/io/dem.hpp"
#include "vola/io/mesh.hpp"

namespace vola::io {

DemRaster read_dem(const std::string& path, const std::function<void(std::uint64_t, std::uint64_t)>& progress) {
  const auto entry = reinterpret_cast<plugin::ReadDemEntry>(plugin::plugin_symbol("gdal", plugin::kReadDemSymbol, path));
  DemRaster dem;
  plugin::PluginFailure failure;
  entry(path, progress, dem, failure);
  plugin::throw_failure(failure);
  return dem;
}

std::vector<Triangle> read_mesh_triangles(const std::string& path) {
  const auto entry =
      reinterpret_cast<plugin::ReadMeshEntry>(plugin::plugin_symbol("assimp", plugin::kReadMeshSymbol, path));
  std::vector<Triangle> triangles;
  plugin::PluginFailure failure;
  entry(path, triangles, failure);
  plugin::throw_failure(failure);
  return triangles;
}

}  // namespace vola::io
