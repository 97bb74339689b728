// Ways back out of VOLA: a tree written as PLY, XYZ text, LAS, a dense NPY grid, PNG
// images or GeoTIFF rasters. Every writer takes the tree and an output path, writes through a temporary
// file renamed into place (no half-written file on failure) and throws vola::IoError
// when the system refuses, vola::InvalidArgument when the tree is too large for the
// format. Positions are voxel centres in world coordinates (Tree::quantizer().center),
// voxels in key order, which is also the order of their attribute rows.
//
// A coarser export is the same call on tree.level_of_detail(K).
#pragma once

#include <array>
#include <cstdint>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "vola/builder.hpp"
#include "vola/tree.hpp"

namespace vola::io {

// ---- PLY ----
struct PlyOptions {
  bool ascii = false;  // default: binary_little_endian
  // false: one vertex per voxel centre with every attribute column as a vertex
  //        property. u16 red/green/blue become uchar, as viewers expect: value / 256,
  //        or the value itself when no colour exceeds 255 (8-bit colours in 16-bit
  //        fields, as in many LAS files).
  // true:  the voxels' outer surface as a quad mesh: one square face per voxel side
  //        that no occupied voxel covers, corners shared between faces, faces
  //        counter-clockwise seen from outside, attribute columns as face properties.
  bool cubes = false;
};
struct PlyReport {
  std::uint64_t vertices = 0;
  std::uint64_t faces = 0;
};
PlyReport write_ply(const Tree& tree, const std::string& path, const PlyOptions& options = {});

// ---- XYZ text ----
// "x y z [attribute values...]" per voxel centre, shortest text that reads back as the
// same double; a first line "# x y z NAME..." names the columns.
void write_xyz(const Tree& tree, const std::string& path);
// The same as CSV, with PDAL's writers.text header ("X","Y","Z","Intensity",...), which
// vola's text reader, PDAL, pandas and spreadsheets read by name.
void write_csv(const Tree& tree, const std::string& path);

// ---- LAS ----
// LAS 1.4, point format 7 when the tree has red, green and blue columns, else 6. The
// scale is a power of ten at most 1/1000 of a voxel (coarser only when the grid
// would overflow 32-bit integers), the offset the grid origin, so every centre is
// exact to well below a voxel. Columns: red/green/blue (u8 columns widened by 257),
// intensity, classification and number_of_returns go to the standard fields (rounded
// and clamped to their ranges, counted in the report for intensity); every other column,
// "height" included, becomes an extra-bytes field (LAS 1.4 "LASF_Spec" 4) of
// the column's type. The CRS goes into an OGC WKT record ("LASF_Projection" 2112, WKT
// bit set): the tree's WKT, else its EPSG code's, converted to WKT1 through PROJ.
struct LasReport {
  std::uint8_t point_format = 6;
  double scale = 0.0;
  bool has_crs = false;                  // false: the tree's CRS is unknown
  std::vector<std::string> extra_bytes;  // columns written as extra-bytes fields
  std::uint64_t clamped_intensities = 0;  // intensities outside LAS's 0..65535, clamped to it
  // Standard fields given values they cannot hold (a classification of 300, a NaN
  // intensity): one sentence each, "classification: 2 values outside LAS's 0..255 were
  // clamped to it", for the front ends to warn with.
  std::vector<std::string> unfit_values;
};
// A path ending in .laz gets the same records LASzip-compressed (vola/io/laz.hpp:
// compressor 3, point format 6 or 7).
LasReport write_las(const Tree& tree, const std::string& path);
// Points (not voxels) as LAS/LAZ 1.4 format 6 or 7, in order: the columns named as LAS
// fields (intensity, return_number, number_of_returns, classification, user_data,
// point_source_id, gps_time, red/green/blue) go into them, the others into extra bytes;
// scale the finest power of ten that keeps the extent in 32-bit integers, offset the
// minimum; the CRS (WKT, else the code) as WKT1.
LasReport write_las(const PointCloud& cloud, const std::string& path, const std::optional<std::uint32_t>& epsg = {},
                    const std::string& wkt = {});

// ---- NPY dense grid ----
// A uint8 array of 0/1, shape (S, S, S) for S = tree.side(), indexed [x, y, z] (C order:
// z varies fastest). S^3 bytes: refused beyond kMaxNpyDepth (4^5 = 1024, 1 GiB).
inline constexpr int kMaxNpyDepth = 5;
void write_npy_grid(const Tree& tree, const std::string& path);

// ---- PNG images (libpng) ----
// Image orientation for every PNG: column = x, row = S - 1 - y (north up, as a map).
//
// One 8-bit grayscale image per z slice, occupied voxels white (255), the rest black,
// named depth<D>-<z>.png in `directory` (created if missing), z zero-padded to at least
// three digits, as the reference reader's --images names them; with `world_files`, each
// beside its world file (write_world_file below). Refused beyond kMaxSliceDepth (1024
// images of 1024 x 1024). Returns the number of images.
inline constexpr int kMaxSliceDepth = 5;
std::uint32_t write_png_slices(const Tree& tree, const std::string& directory, bool world_files = false);

// Top-down height map: per (x, y) column the highest occupied z. bits 16: pixel = z + 1
// (exact), 0 where the column is empty; bits 8: pixel = 1 + round(z * 254 / (S - 1)),
// 0 where empty. The values are voxel indices, not elevations (write_geotiff below
// writes elevations). Refused beyond kMaxMapDepth (16384 x 16384 pixels).
inline constexpr int kMaxMapDepth = 7;
void write_png_height_map(const Tree& tree, const std::string& path, int bits = 16);

// Top-down occupancy map, the reference reader's --map: a column with any occupied
// voxel at z >= `min_z` is black (0), every other pixel white (255), as occupancy maps
// for path planning draw obstacles. Same size limit as the height map.
void write_png_occupancy_above(const Tree& tree, const std::string& path, std::uint32_t min_z);

// The world file of a top-down image of the whole grid (the maps, each slice): the
// image's name with its extension replaced by `.pgw` (a.png -> a.pgw), six lines
// A D B E C F as Esri and GDAL read them: pixel size x, 0, 0, -(pixel size y), and x, y
// of the centre of the top-left pixel, from tree.frame() (pixel (c, r) = voxel column
// (c, S - 1 - r)). Returns the world file's path. It places the pixels only: the CRS is
// not in it, and the pixel values stay voxel units.
std::string world_file_path(const std::string& image_path);
std::string write_world_file(const Tree& tree, const std::string& image_path);

// ---- GeoTIFF rasters (through GDAL, in the gdal plugin) ----
// A 2-D product of the voxels, one value per cell of a north-up grid of square cells in
// the tree's world units, as a single-band Float32 cloud-optimised GeoTIFF (GDAL's COG
// driver: 512 x 512 tiles, DEFLATE with the floating-point predictor, overviews by
// averaging when the raster exceeds a tile). Each voxel column (x, y) belongs to the one
// cell holding its centre; cells align with the grid origin (tree.frame()), so with the
// default resolution (the voxel size) cell = voxel column.
//
//   dsm        max over the cell's voxels of `height` when the tree has that column (a
//              voxel's mean point z, from LAS), else of the voxel's top face
//              (origin z + (k + 1) * voxel size)
//   dtm        min over the cell's ground voxels (`classification` 2, when the tree has
//              that column and any voxel of class 2; else over all its voxels) of
//              `height` if present, else of the voxel's bottom face (origin z + k * voxel)
//   intensity  mean `intensity` of the top voxel of each voxel column in the cell (what
//              is seen from above); needs the column
//   density    occupied voxels in the cell / cell area (voxels per square world unit)
//   count      occupied voxels in the cell
//
// Cells without a voxel (dtm: without a ground voxel) hold kRasterNodata, which the file
// declares as its nodata value. The raster is cropped to the cells that hold a voxel
// (before the dtm's ground filter); the CRS is the tree's WKT, else its EPSG code (none
// when it has neither).
enum class RasterProduct : std::uint8_t { dsm, dtm, intensity, density, count };
// "dsm" -> RasterProduct::dsm..., nullopt for another name.
std::optional<RasterProduct> raster_product(std::string_view name);
constexpr const char* raster_product_name(RasterProduct product) noexcept {
  switch (product) {
    case RasterProduct::dsm: return "dsm";
    case RasterProduct::dtm: return "dtm";
    case RasterProduct::intensity: return "intensity";
    case RasterProduct::density: return "density";
    case RasterProduct::count: return "count";
  }
  return "?";
}

inline constexpr float kRasterNodata = -9999.0f;
// width * height beyond this (1 GiB of Float32) is refused: choose a coarser resolution.
inline constexpr std::uint64_t kMaxRasterCells = std::uint64_t{1} << 28;

struct RasterOptions {
  RasterProduct product = RasterProduct::dsm;
  // Cell edge in world (CRS) units; 0: the voxel size. Not below the voxel size (a finer
  // grid holds no more than the voxels say).
  double resolution = 0.0;
};

struct Raster {
  RasterProduct product = RasterProduct::dsm;
  std::uint64_t width = 0, height = 0;
  // GDAL's geotransform: cell (column c, row r) has its top-left corner at
  // (gt[0] + c * gt[1], gt[3] + r * gt[5]); gt[2] = gt[4] = 0, gt[5] = -gt[1].
  std::array<double, 6> geotransform{};
  std::vector<float> values;  // width * height, row 0 the northernmost
  std::uint64_t cells_with_data = 0;
  std::string rule;  // what a value is, in words (which column or face, which voxels)
};
// The raster, computed in memory. Throws InvalidArgument for an empty tree, a missing
// intensity column, a resolution below the voxel size or a raster above kMaxRasterCells.
Raster make_raster(const Tree& tree, const RasterOptions& options);

struct RasterReport {
  std::uint64_t width = 0, height = 0;
  double resolution = 0.0;
  std::uint64_t cells_with_data = 0;
  std::string rule;
  bool has_crs = false;
};
// make_raster, then the GeoTIFF written through the gdal plugin (in memory, then to
// `path` through a temporary renamed into place).
RasterReport write_geotiff(const Tree& tree, const std::string& path, const RasterOptions& options);

}  // namespace vola::io
