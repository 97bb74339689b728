// Accounting on the VOLA structure itself: per level blocks and cells, per attribute
// histograms (classification counts with their ASPRS names), volume and footprint in
// the grid's world units, voxel counts inside boxes or polygons.
#pragma once

#include <array>
#include <cstdint>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "vola/frame.hpp"
#include "vola/tree.hpp"

namespace vola::analysis {

// ASPRS standard class names: LAS 1.4's (codes 0-18, "Reserved" for 19-63, "User
// definable" for 64-255), or with `las_minor` below 4 the table of LAS 1.0-1.3, whose
// codes 0-31 differ (8 "Model Key-point", 12 "Overlap Points", 10, 11 and 13-31 reserved).
std::string_view asprs_class_name(int code, int las_minor = 4) noexcept;

struct LevelCensus {
  std::uint64_t blocks = 0;  // 64-bit words of the level
  std::uint64_t cells = 0;   // occupied cells (set bits)
  double fill = 0.0;         // cells / (64 * blocks)
};

// Equal-width bins over [min, max]; the last bin is closed.
struct Histogram {
  double min = 0.0, max = 0.0;
  std::vector<std::uint64_t> counts;
};

struct ClassCount {
  int code = 0;
  std::uint64_t voxels = 0;
};

struct AttributeCensus {
  std::string name;
  std::uint64_t count = 0;          // voxels with a value
  std::uint64_t without_value = 0;  // voxels whose value is NaN (no point of theirs had one)
  double mean = 0.0;                // over the voxels with a value
  Histogram histogram;              // every column, its values (NaN left out)
  std::vector<ClassCount> classes; // the "classification" column: voxels per code, ascending
};

// A region in world coordinates: a box, or a polygon in x, y (any z; even-odd rule).
// A voxel is counted when its centre is inside (box: closed).
struct Region {
  std::string label;
  std::optional<Box> box;
  std::vector<std::array<double, 2>> polygon;
};

struct CensusOptions {
  int bins = 16;  // histogram bins, >= 1
  std::vector<Region> regions;
};

struct Census {
  int depth = 1;
  std::uint64_t voxels = 0;
  std::vector<LevelCensus> levels;  // level 0 = root
  // Known when the file records a GIS grid (grid quantization): then volume =
  // voxels * size^3 and footprint area = columns * size^2 in the CRS's units.
  std::optional<double> voxel_size;
  std::uint64_t columns = 0;  // distinct occupied (x, y) columns
  Histogram heights;          // voxel centre z in world coordinates
  std::vector<AttributeCensus> attributes;
  std::vector<std::uint64_t> region_voxels;  // one per options.regions
  double volume() const { return voxel_size ? static_cast<double>(voxels) * *voxel_size * *voxel_size * *voxel_size : 0; }
  double footprint_area() const { return voxel_size ? static_cast<double>(columns) * *voxel_size * *voxel_size : 0; }
};

// Throws InvalidArgument for bins < 1 or a polygon of fewer than 3 points.
Census take_census(const Tree& tree, const CensusOptions& options = {});

}  // namespace vola::analysis
