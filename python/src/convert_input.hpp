// Any input vola's readers know (include/vola/io/input.hpp) -> a tree, for the Python
// module's vola.convert. Plain C++ (no pybind11), so that it compiles once and fast.
#pragma once

#include <cstdint>
#include <optional>
#include <string>

#include "vola/builder.hpp"
#include "vola/tree.hpp"

namespace vola::python {

struct ConvertOptions {
  std::string format = "auto";
  std::string quantize;  // "grid", "toolkit" or "" (grid when a voxel size is given, else toolkit)
  int depth = 0;
  double voxel_size = 0.0;
  std::optional<std::uint32_t> epsg;  // overrides what the input says
  bool solid = false;                 // meshes: fill the inside
  bool attributes = true;             // keep the per-point attributes the format carries
  std::optional<double> dem_base;
  bool dem_surface_only = false;
};

// Reads `path` and builds its tree the way `vola convert` does: voxel grids one cell per
// voxel unless another grid is asked for, meshes voxelized, DEM cells as columns, points
// quantized. Throws vola::Error naming the file and what was wrong.
Tree convert(const std::string& path, const ConvertOptions& options, BuildReport* report = nullptr);

}  // namespace vola::python
