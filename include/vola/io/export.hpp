// Ways back out of VOLA: a tree written as PLY, XYZ text, LAS, a dense NPY grid or PNG
// images. Every writer takes the tree and an output path, writes through a temporary
// file renamed into place (no half-written file on failure) and throws vola::IoError
// when the system refuses, vola::InvalidArgument when the tree is too large for the
// format. Positions are voxel centres in world coordinates (Tree::quantizer().center),
// voxels in key order, which is also the order of their attribute rows.
//
// A coarser export is the same call on tree.level_of_detail(K).
#pragma once

#include <cstdint>
#include <optional>
#include <string>
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
  std::uint64_t clamped_intensities = 0;  // intensities above LAS's 16 bits, written as 65535
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
// three digits, as the reference reader's --images names them. Refused beyond
// kMaxSliceDepth (1024 images of 1024 x 1024). Returns the number of images.
inline constexpr int kMaxSliceDepth = 5;
std::uint32_t write_png_slices(const Tree& tree, const std::string& directory);

// Top-down height map: per (x, y) column the highest occupied z. bits 16: pixel = z + 1
// (exact), 0 where the column is empty; bits 8: pixel = 1 + round(z * 254 / (S - 1)),
// 0 where empty. Refused beyond kMaxMapDepth (16384 x 16384 pixels).
inline constexpr int kMaxMapDepth = 7;
void write_png_height_map(const Tree& tree, const std::string& path, int bits = 16);

// Top-down occupancy map, the reference reader's --map: a column with any occupied
// voxel at z >= `min_z` is black (0), every other pixel white (255), as occupancy maps
// for path planning draw obstacles. Same size limit as the height map.
void write_png_occupancy_above(const Tree& tree, const std::string& path, std::uint32_t min_z);

}  // namespace vola::io
