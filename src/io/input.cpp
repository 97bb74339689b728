#include "vola/io/input.hpp"

#include <algorithm>
#include <cctype>
#include <filesystem>
#include <fstream>
#include <memory>
#include <string_view>

#include "file_bytes.hpp"
#include "vola/error.hpp"
#include "vola/io/binvox.hpp"
#include "vola/io/dem.hpp"
#include "vola/io/e57.hpp"
#include "vola/io/ept.hpp"
#include "vola/io/file_checks.hpp"
#include "vola/io/kitti.hpp"
#include "vola/io/las.hpp"
#include "vola/io/mesh.hpp"
#include "vola/io/npy.hpp"
#include "vola/io/npz.hpp"
#include "vola/io/occupancy_maps.hpp"
#include "vola/io/pcd.hpp"
#include "vola/io/ply.hpp"
#include "vola/io/ptx.hpp"
#include "vola/io/ros_map.hpp"

namespace vola::io {

namespace {

Input read_las_input(const std::string& path, const InputOptions& options) {
  auto reader = std::make_shared<LasReader>(path);
  if (options.copc_level) reader->select_copc_nodes(std::nullopt, options.copc_level);
  Input in;
  in.format = "las";
  // What part of the file was read: said only for COPC, whose nodes outside the level or
  // grid are skipped (a plain file is read whole, but for bytes no record needs).
  if (reader->header().copc) in.bytes_read = [reader] { return reader->bytes_read(); };
  in.epsg = reader->header().epsg;
  in.wkt = reader->header().wkt;
  const LasHeader& header = reader->header();
  in.stated_bounds = Box{{header.min[0], header.min[1], header.min[2]}, {header.max[0], header.max[1], header.max[2]}};
  if (options.stream) {
    in.build = [reader, options](const BuildOptions& build_options, BuildReport* report) {
      return build_las(*reader, build_options, options.attributes, options.payload, report, options.progress);
    };
  } else {
    in.cloud = las_points(*reader, options.attributes, options.payload, options.progress);
  }
  return in;
}

Input read_text_input(const std::string& path, const InputOptions& options) {
  Input in;
  in.format = "text";
  in.cloud = read_text_points(path, options.text, options.progress);
  return in;
}

Input read_npy_input(const std::string& path, const InputOptions& options) {
  if (lower_extension(path) != ".npz") {
    if (!options.grid.empty())
      throw OptionError(
          "grid", "names an array of an .npz archive or a grid of an OpenVDB file; " + path + " is one .npy array");
    return npy_input(read_npy(path), path, options);
  }
  const std::string member = npz_points_member(path, options.grid);
  return npy_input(read_npz_array(path, member), path + ":" + member, options);
}

Input read_pcd_input(const std::string& path, const InputOptions& options) {
  Input in;
  in.format = "pcd";
  in.cloud = read_pcd(path, options, &in.not_finite);
  return in;
}

Input read_kitti_input(const std::string& path, const InputOptions& options) {
  Input in;
  in.format = "kitti";
  in.cloud = read_kitti(path, options);
  return in;
}

// nuScenes and Lyft sweeps whatever their name (Lyft names them plain .bin).
Input read_nuscenes_input(const std::string& path, const InputOptions& options) {
  Input in;
  in.format = "nuscenes";
  in.cloud = parse_nuscenes(read_file_bytes(path), path, options);
  return in;
}

Input read_binvox_input(const std::string& path, const InputOptions&) {
  Input in;
  in.format = "binvox";
  in.grid = read_binvox(path);
  return in;
}

Input read_mesh_input(const std::string& path, const InputOptions&) {
  Input in;
  in.format = "mesh";
  in.triangles = read_mesh_triangles(path);
  return in;
}

Input read_dem_input(const std::string& path, const InputOptions& options) {
  DemRaster dem = read_dem(path, options.progress);
  Input in;
  in.format = "dem";
  in.cloud = std::move(dem.cells);
  in.epsg = dem.epsg;
  in.wkt = std::move(dem.wkt);
  in.terrain = true;
  in.terrain_base = options.dem_base.value_or(dem.minimum);
  in.terrain_surface_only = options.dem_surface_only;
  in.terrain_lattice = dem.lattice;
  in.terrain_cell = dem.cell_size;
  return in;
}

Input read_octomap_input(const std::string& path, const InputOptions& options) {
  Input in;
  in.format = "octomap";
  in.grid = read_octomap(path, options);
  return in;
}

Input read_ros_map_input(const std::string& path, const InputOptions& options) {
  Input in;
  in.format = "rosmap";
  in.grid = read_ros_map(path, options.map_height);
  return in;
}

Input read_vdb_input(const std::string& path, const InputOptions& options) {
  Input in;
  in.format = "vdb";
  in.grid = read_vdb(path, options);
  return in;
}

// Whether the file's first word is ncols or nrows (any case), as ESRI ASCII grids begin.
bool is_esri_ascii_grid(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  char head[64] = {};
  in.read(head, sizeof head);
  std::string_view text(head, static_cast<std::size_t>(in.gcount()));
  if (text.starts_with("\xEF\xBB\xBF")) text.remove_prefix(3);
  while (!text.empty() && std::isspace(static_cast<unsigned char>(text.front()))) text.remove_prefix(1);
  std::string word;
  for (char c : text.substr(0, 6)) word += static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return word.size() == 6 && (word.starts_with("ncols") || word.starts_with("nrows")) &&
         std::isspace(static_cast<unsigned char>(word[5]));
}

std::vector<InputFormat> make_formats() {
  return {
      {"las",
       {".las", ".laz"},
       "ASPRS LAS 1.0-1.4, point formats 0-10, and LAZ (compressed LAS, COPC)",
       read_las_input},
      {"text",
       {".xyz", ".txt", ".csv", ".pts", ".asc", ".xyzn", ".xyzrgb"},
       "points as text columns (x y z ...)",
       read_text_input},
      {"npy",
       {".npy", ".npz"},
       "NumPy (N,3+) point arrays, record arrays or (X,Y,Z) occupancy grids; .npz archives of them",
       read_npy_input},
      {"ply", {".ply"}, "PLY ascii/binary points, vertex colours, faces as a mesh", read_ply},
      {"pcd", {".pcd"}, "PCD .5-0.7 ascii/binary/binary_compressed points", read_pcd_input},
      {"kitti",
       {".bin"},
       "KITTI velodyne float32 x y z reflectance (nuScenes .pcd.bin: x y z intensity ring)",
       read_kitti_input},
      {"nuscenes",
       {},
       "nuScenes and Lyft lidar sweeps, float32 x y z intensity ring, whatever the name (--format nuscenes)",
       read_nuscenes_input},
      {"binvox", {".binvox"}, "binvox occupancy grids", read_binvox_input},
      {"mesh",
       {".stl", ".obj", ".off", ".gltf", ".glb", ".dae", ".3ds"},
       "meshes: STL and OFF (vola), OBJ, glTF, COLLADA, 3DS (Assimp)",
       read_mesh_input},
      {"dem",
       {".tif", ".tiff", ".dem", ".img"},
       "elevation rasters through GDAL (GeoTIFF, ...): cells as columns",
       read_dem_input},
      {"octomap",
       {".bt", ".ot"},
       "OctoMap occupancy maps through liboctomap: occupied cells (.ot: with log-odds)",
       read_octomap_input},
      {"vdb", {".vdb"}, "OpenVDB grids through OpenVDB: the active voxels of one grid", read_vdb_input},
      {"rosmap",
       {".yaml", ".yml"},
       "ROS 2D maps (map_server YAML + PGM): occupied cells as voxel columns (map_height)",
       read_ros_map_input},
      {"ept", {".json"}, "Entwine Point Tiles: the ept.json of a local EPT folder (laszip or binary data)", read_ept},
      {"ptx",
       {".ptx"},
       "Leica PTX scans (text): x y z intensity [r g b] per point, each scan moved by its 4 x 4 matrix",
       read_ptx},
      {"e57",
       {".e57"},
       "ASTM E57 scans (terrestrial scanners): cartesian or spherical points, each scan's pose, colour, intensity",
       read_e57},
  };
}

}  // namespace

const std::vector<InputFormat>& input_formats() {
  static const std::vector<InputFormat> formats = make_formats();
  return formats;
}

namespace {

// "las" for a file beginning "LASF" (LAS, LAZ, COPC), "e57" for "ASTM-E57"; else null.
const char* format_by_magic(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  char magic[8] = {};
  in.read(magic, sizeof magic);
  const std::string_view head(magic, static_cast<std::size_t>(in.gcount()));
  if (head.starts_with("LASF")) return "las";
  if (head.starts_with("ASTM-E57")) return "e57";
  return nullptr;
}

}  // namespace

const InputFormat& find_input_format(const std::string& path, const std::string& name) {
  refuse_non_regular_input(path);  // every reader finds its format here first
  const auto& formats = input_formats();
  std::string known;
  for (const auto& f : formats) known += (known.empty() ? "" : ", ") + f.name;
  if (name != "auto") {
    for (const auto& f : formats)
      if (f.name == name) return f;
    throw OptionError("format", "'" + name + "' is not known (" + known + ")");
  }
  // Formats that say what they are in their first bytes are read as what they are,
  // whatever their name (a LAS file saved as .xyz was read as text: "column 1 'LASF...'
  // is not a number", while vola info read it as LAS).
  if (const char* by_magic = format_by_magic(path))
    for (const auto& f : formats)
      if (f.name == by_magic) return f;
  const std::string ext = lower_extension(path);
  for (const auto& f : formats)
    if (std::find(f.extensions.begin(), f.extensions.end(), ext) != f.extensions.end()) {
      // .asc (and .txt) is also ESRI's ASCII grid, which begins with ncols/nrows: an
      // elevation raster for GDAL, not points.
      if (f.name == "text" && is_esri_ascii_grid(path))
        for (const auto& dem : formats)
          if (dem.name == "dem") return dem;
      return f;
    }
  throw OptionError("format", path + ": cannot tell the format from the extension '" + ext + "'; say which (" + known + ")");
}

Input read_input(const std::string& path, const std::string& format, const InputOptions& options) {
  refuse_unopenable_input(path);
  return find_input_format(path, format).read(path, options);
}

}  // namespace vola::io
