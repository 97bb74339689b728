// read_dem and read_mesh_triangles: the GDAL and Assimp plugins' entry points, called
// through the plugin loader (src/plugin/plugin.hpp says why they are plugins).
#include <algorithm>
#include <cctype>
#include <filesystem>

#include "file_bytes.hpp"
#include "mesh_files.hpp"
#include "reader_plugin.hpp"
#include "vola/io/dem.hpp"
#include "vola/io/mesh.hpp"

namespace vola::io {

DemRaster read_dem(const std::string& path, const std::function<void(std::uint64_t, std::uint64_t)>& progress) {
  const auto entry = reinterpret_cast<plugin::ReadDemEntry>(
      vola::plugin::plugin_symbol("gdal", plugin::kReadDemSymbol, path + ": reading it"));
  DemRaster dem;
  PluginFailure failure;
  entry(path, progress, dem, failure);
  vola::plugin::throw_failure(failure);
  return dem;
}

std::vector<Triangle> read_mesh_triangles(const std::string& path) {
  // OFF and STL are read natively (mesh_files.hpp says why), the rest through Assimp.
  std::string ext = std::filesystem::path(path).extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  if (ext == ".off") return parse_off(read_file_bytes(path), path);
  if (ext == ".stl") return parse_stl(read_file_bytes(path), path);
  const auto entry = reinterpret_cast<plugin::ReadMeshEntry>(
      vola::plugin::plugin_symbol("assimp", plugin::kReadMeshSymbol, path + ": reading it"));
  std::vector<Triangle> triangles;
  PluginFailure failure;
  entry(path, triangles, failure);
  vola::plugin::throw_failure(failure);
  return triangles;
}

}  // namespace vola::io
