// binvox voxel grids (Patrick Min's format), read and written. A header of text lines
// ("#binvox 1", then in any order "dim A B C", "translate tx ty tz", "scale s", with
// '#' comments), the line "data", then run-length pairs (value byte, count byte) over
// every cell, with y running fastest, then z, then x:
//   index = x * (B * C) + z * C + y,   x < A, z < B, y < C
// (binvox-rw-py's convention; binvox itself only writes cubes, A = B = C).
#pragma once

#include <cstdint>
#include <span>
#include <string>
#include <vector>

#include "vola/io/input.hpp"
#include "vola/tree.hpp"

namespace vola::io {

// The most occupied cells parse_binvox holds for a file of n bytes (12 bytes each):
// kBinvoxVoxelAllowance + kBinvoxVoxelsPerByte * n. A run pair of two bytes stands for
// up to 255 cells, so without a bound an 8.4 MB file expanded to 12.6 GB of voxels; the
// allowance holds a fully solid 256^3 grid (16.7 M voxels) whatever its file size.
inline constexpr std::uint64_t kBinvoxVoxelAllowance = std::uint64_t{1} << 25;
inline constexpr std::uint64_t kBinvoxVoxelsPerByte = 8;

// Occupied cells with origin = translate and voxel size = scale / max(A, B, C) (scale
// is the world length of the grid's longest side). Throws FormatError with the file
// name and byte offset on anything malformed, and when the runs set more cells than
// the bound above (the runs are checked and counted before any voxel is stored).
VoxelGrid parse_binvox(std::span<const std::uint8_t> bytes, const std::string& name);
VoxelGrid read_binvox(const std::string& path);

// The tree's voxels as a cube of side max(coordinate) + 1 with translate = the frame's
// origin and scale = voxel size * side, so that reading it back gives the same voxels
// in the same place. Throws InvalidArgument when the side exceeds kMaxBinvoxSide
// (binvox is dense: the file grows with side^3 however few voxels there are).
inline constexpr std::uint32_t kMaxBinvoxSide = 4096;
std::vector<std::uint8_t> serialize_binvox(const Tree& tree);
void write_binvox(const Tree& tree, const std::string& path);

}  // namespace vola::io
