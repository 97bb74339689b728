#include "vola/io/ros_map.hpp"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <filesystem>
#include <limits>
#include <string>
#include <vector>

#include "vola/error.hpp"
#include "vola/output_file.hpp"

namespace vola::io {

namespace {

// map_saver's pixel values (trinary mode, negate 0).
constexpr std::uint8_t kOccupiedPixel = 0, kFreePixel = 254, kUnknownPixel = 205;
// A cell's evidence, as bits.
constexpr std::uint8_t kOccupiedInBand = 1, kFreeInBand = 2, kOccupiedBelow = 4;
constexpr std::uint64_t kMaxCells = std::uint64_t{1} << 28;  // 16384 x 16384, as the reader takes

// The shortest text that reads back as `value`, spelled as YAML 1.1 spells a float (a
// point in it: PyYAML read "5e+05", what the shortest form of 500000 is, as a string).
std::string ros_map_number(double value) {
  char digits[400];
  const bool plain = value == 0 || (std::abs(value) >= 1e-4 && std::abs(value) < 1e15);
  const auto result = plain ? std::to_chars(digits, digits + sizeof digits, value, std::chars_format::fixed)
                            : std::to_chars(digits, digits + sizeof digits, value, std::chars_format::scientific);
  std::string text(digits, result.ptr);
  if (!std::isfinite(value) || text.find('.') != std::string::npos) return text;
  const auto exponent = text.find('e');
  text.insert(exponent == std::string::npos ? text.size() : exponent, ".0");
  return text;
}

// The voxel layers k in [lowest, highest] (the map's) whose centres
// origin + (k + 0.5) * size lie in [z_min, z_max].
struct Layers {
  std::int64_t first = 0, last = -1;
};

Layers band_layers(const Frame& frame, const RosMapOptions& options, std::int64_t lowest, std::int64_t highest) {
  const double z_min = options.z_min, z_max = options.z_max;
  if (!std::isfinite(z_min) || !std::isfinite(z_max))
    throw OptionError("band",
                      "needs two finite heights ZMIN:ZMAX, not " + ros_map_number(z_min) + ":" + ros_map_number(z_max));
  if (z_min > z_max)
    throw OptionError("band", "is upside down: " + ros_map_number(z_min) + " is above " + ros_map_number(z_max));
  const auto centre = [&](std::int64_t k) {
    return frame.origin[2] + (static_cast<double>(k) + 0.5) * frame.voxel_size;
  };
  Layers layers{lowest, highest};
  while (layers.first <= highest && centre(layers.first) < z_min) ++layers.first;
  while (layers.last >= lowest && centre(layers.last) > z_max) --layers.last;
  if (layers.first > layers.last)
    throw OptionError("band", ros_map_number(z_min) + ":" + ros_map_number(z_max) +
                                  " holds no voxel centre of the map: its layers are " +
                                  ros_map_number(frame.voxel_size) +
                                  " apart, centred from z = " + ros_map_number(centre(lowest)) + " to " +
                                  ros_map_number(centre(highest)) + " (a band in another unit?)");
  return layers;
}

}  // namespace

RosMapReport write_ros_map(const MapVoxels& voxels, const std::string& yaml_path, const RosMapOptions& options) {
  voxels.check();
  const Frame& frame = voxels.frame;
  if (voxels.occupied.empty() && voxels.free.empty())
    throw InvalidArgument(yaml_path + ": the map holds no voxel to draw");

  // The columns that hold any voxel: the image's extent.
  std::uint32_t x0 = std::numeric_limits<std::uint32_t>::max(), y0 = x0, z0 = x0, x1 = 0, y1 = 0, z1 = 0;
  for (const auto* list : {&voxels.occupied, &voxels.free})
    for (const Voxel& v : *list) {
      x0 = std::min(x0, v.x), y0 = std::min(y0, v.y), z0 = std::min(z0, v.z);
      x1 = std::max(x1, v.x), y1 = std::max(y1, v.y), z1 = std::max(z1, v.z);
    }
  const Layers layers = band_layers(frame, options, z0, z1);
  const std::uint64_t width = std::uint64_t{x1} - x0 + 1, height = std::uint64_t{y1} - y0 + 1;
  if (width * height > kMaxCells)
    throw InvalidArgument(yaml_path + ": a map of " + std::to_string(width) + " x " + std::to_string(height) +
                          " cells is more than " + std::to_string(kMaxCells) + "; export a coarser level (depth K)");

  std::vector<std::uint8_t> evidence(width * height, 0);
  const auto cell = [&](const Voxel& v) -> std::uint8_t& { return evidence[(v.x - x0) + width * (v.y - y0)]; };
  for (const Voxel& v : voxels.occupied) {
    const std::int64_t z = v.z;
    cell(v) |= z < layers.first ? kOccupiedBelow : z <= layers.last ? kOccupiedInBand : 0;
  }
  for (const Voxel& v : voxels.free) {
    const std::int64_t z = v.z;
    if (z >= layers.first && z <= layers.last) cell(v) |= kFreeInBand;
  }
  const bool free_from_ground = voxels.free.empty();

  RosMapReport report;
  report.image = std::filesystem::path(yaml_path).replace_extension(".pgm").string();
  report.width = static_cast<std::uint32_t>(width);
  report.height = static_cast<std::uint32_t>(height);
  report.resolution = frame.voxel_size;
  report.origin = {frame.origin[0] + x0 * frame.voxel_size, frame.origin[1] + y0 * frame.voxel_size};
  report.free_from_ground = free_from_ground;
  const std::uint8_t free_evidence = free_from_ground ? kOccupiedBelow : kFreeInBand;

  std::string pgm = "P5\n" + std::to_string(width) + " " + std::to_string(height) + "\n255\n";
  const std::size_t header = pgm.size();
  pgm.resize(header + width * height);
  for (std::uint64_t row = 0; row < height; ++row) {  // row 0 is the top: the largest y
    const std::uint8_t* in = evidence.data() + width * (height - 1 - row);
    char* out = pgm.data() + header + width * row;
    for (std::uint64_t x = 0; x < width; ++x) {
      std::uint8_t pixel = kUnknownPixel;
      if (in[x] & kOccupiedInBand)
        pixel = kOccupiedPixel, ++report.occupied;
      else if (in[x] & free_evidence)
        pixel = kFreePixel, ++report.free;
      else
        ++report.unknown;
      out[x] = static_cast<char>(pixel);
    }
  }
  OutputFile image(report.image);
  image.write(pgm);

  const std::string yaml = "image: " + std::filesystem::path(report.image).filename().string() +
                           "\nmode: trinary\nresolution: " + ros_map_number(report.resolution) + "\norigin: [" +
                           ros_map_number(report.origin[0]) + ", " + ros_map_number(report.origin[1]) +
                           ", 0.0]\nnegate: 0\noccupied_thresh: 0.65\nfree_thresh: 0.196\n";
  OutputFile text(yaml_path);
  text.write(yaml);
  image.commit();
  text.commit();
  return report;
}

}  // namespace vola::io
