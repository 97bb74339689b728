#include "vola/io/export_format.hpp"

#include <algorithm>
#include <cctype>
#include <filesystem>

#include "vola/error.hpp"
#include "vola/io/input.hpp"

namespace vola::io {

namespace {

std::string format_from_extension(const std::string& path) {
  const std::string ext = lower_extension(path);
  if (ext == ".ply") return "ply";
  if (ext == ".xyz" || ext == ".txt") return "xyz";
  if (ext == ".csv") return "csv";
  if (ext == ".las" || ext == ".laz") return "las";
  if (ext == ".binvox") return "binvox";
  if (ext == ".npy") return "npy";
  if (ext == ".png") return "png";
  if (ext == ".tif" || ext == ".tiff") return "tif";
  if (ext == ".bt" || ext == ".ot") return "octomap";
  if (ext == ".vdb") return "vdb";
  if (ext == ".yaml" || ext == ".yml") return "rosmap";
  throw OptionError("format", path + ": cannot tell the format from the extension '" + ext +
                                  "'; say `format` (ply, xyz, csv, las, binvox, npy, png, tif, octomap, vdb, rosmap)");
}

}  // namespace

std::string resolve_export_format(const ExportRequest& r) {
  const int images = int{r.slices} + int{r.map} + int{r.occupancy_above};
  if (images > 1) throw OptionError("slices", "`slices`, `map` and `occupancy_above` are different images: give one");
  if (images && r.raster)
    throw OptionError("raster", "`raster` writes a GeoTIFF, `slices`, `map` and `occupancy_above` PNG images: give one");
  const bool automatic = r.format == "auto";
  std::string format = r.format;
  if (automatic) format = images ? "png" : r.raster ? "tif" : format_from_extension(r.output);
  if (images && format != "png")
    throw OptionError("format", "`slices`, `map` and `occupancy_above` write PNG, not " + format);
  if (r.raster && format != "tif") throw OptionError("format", "`raster` writes a GeoTIFF, not " + format);
  const std::string ext = lower_extension(r.output);
  // A map is a PNG of voxel units: under another name (a.tif) it would pass for what it
  // is not.
  if ((r.map || r.occupancy_above) && automatic && ext != ".png")
    throw OptionError("map", r.output + ": `map` and `occupancy_above` write PNG images (voxel units, with a .pgw "
                                        "world file): name it .png" +
                                 std::string(ext == ".tif" || ext == ".tiff"
                                                 ? "; for a GeoTIFF of elevations use `raster` dsm (or dtm, "
                                                   "intensity, density, count)"
                                                 : ""));
  if (r.raster && automatic && ext != ".tif" && ext != ".tiff")
    throw OptionError("raster", "writes a GeoTIFF: name the output .tif, not " + r.output);
  if (format == "png" && !images)
    throw OptionError("format", "PNG export needs `slices` (the output is a folder), `map` or `occupancy_above` Z");
  if (format == "tif" && !r.raster)
    throw OptionError("raster", "GeoTIFF export needs `raster` dsm, dtm, intensity, density or count");
  if (r.resolution && !r.raster) throw OptionError("resolution", "`resolution` applies to `raster`");
  if ((r.ascii || r.cubes) && format != "ply") throw OptionError("ascii", "`ascii` and `cubes` apply to PLY export");
  if (r.bits && !r.map) throw OptionError("bits", "`bits` applies to `map`");
  if (r.free && format != "octomap" && format != "vdb" && format != "rosmap")
    throw OptionError("free", "`free` applies to .bt, .ot, .vdb and ROS (.yaml) maps");
  if (r.band && format != "rosmap") throw OptionError("band", "`band` applies to a ROS map (.yaml)");
  if (format == "rosmap" && !r.band)
    throw OptionError("band",
                      "a ROS map needs the height band a robot sweeps, ZMIN:ZMAX in the file's units (voxels "
                      "whose centres lie in it are obstacles), e.g. `band` 0.2:1.8 above a floor at z = 0");
  return format;
}

}  // namespace vola::io
