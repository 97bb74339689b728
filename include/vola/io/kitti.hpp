// KITTI velodyne scans (.bin): little-endian float32 records x y z reflectance, 16
// bytes per point, nothing else in the file.
#pragma once

#include <cstdint>
#include <span>
#include <string>

#include "vola/builder.hpp"
#include "vola/io/input.hpp"

namespace vola::io {

// Every record as a point. With `options.attributes` the reflectance becomes the
// attribute "reflectance" (f32, mean); with `options.payload` each point gets the
// reference's kitti2vola payload: reflectance mapped [-0.2, 1] -> 0..255 in bytes 0, 1
// and 2 (grey RGB). Throws FormatError when the size is not a multiple of 16.
PointCloud parse_kitti(std::span<const std::uint8_t> bytes, const std::string& name, const InputOptions& options = {});
// A .pcd.bin file is read as a nuScenes sweep (is_nuscenes_sweep), any other as KITTI.
PointCloud read_kitti(const std::string& path, const InputOptions& options = {});

// nuScenes (and Lyft) lidar sweeps (`*.pcd.bin`): float32 records x y z intensity ring,
// 20 bytes per point. With `options.attributes` intensity (0..255) becomes "intensity" (f32,
// mean) and the ring index "ring" (u8, majority); with `options.payload` the intensity,
// clamped to 0..255, is the grey of bytes 0, 1 and 2. Throws FormatError when the size is
// not a multiple of 20.
PointCloud parse_nuscenes(std::span<const std::uint8_t> bytes, const std::string& name,
                          const InputOptions& options = {});
// Whether `path` names a nuScenes sweep (ends in .pcd.bin, any case): read with
// parse_nuscenes, not as KITTI.
bool is_nuscenes_sweep(const std::string& path);

// kitti2vola's byte for one reflectance: int(float32(normalize(r, -0.2, 1)) * 255) in
// float32 arithmetic, as its NumPy code computes it.
std::uint8_t kitti_reflectance_byte(float reflectance) noexcept;

}  // namespace vola::io
