// ROS 2D maps (map_server / nav2_map_server: a YAML file naming a PGM image) as voxel
// columns. The YAML is read here, not through yaml-cpp: a map's YAML is seven flat keys,
// and Debian 12's yaml-cpp (0.7) recurses on nesting without a limit, so a hostile file of
// nested brackets would overflow the stack. Anything but flat keys is refused.
#include "vola/io/ros_map.hpp"

#include <algorithm>
#include <cctype>
#include <charconv>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>
#include <string>
#include <string_view>
#include <vector>

#include "vola/error.hpp"
#include "vola/io/input.hpp"
#include "vola/io/png_decode.hpp"

namespace vola::io {

namespace {

constexpr std::uint64_t kMaxYamlBytes = std::uint64_t{1} << 20;
constexpr std::uint64_t kMaxRosMapCells = std::uint64_t{1} << 28;  // 16384 x 16384
constexpr std::uint64_t kPgmHeaderBytes = 65536;
constexpr std::uint64_t kMaxRosMapVoxels = std::uint64_t{1} << 28;

std::string ros_yaml_slurp(const std::string& path, std::uint64_t limit, const std::string& what) {
  std::error_code error;
  if (!std::filesystem::is_regular_file(path, error)) throw IoError(path + ": " + what + " is not a regular file");
  const std::uint64_t size = std::filesystem::file_size(path, error);
  if (error) throw IoError(path + ": cannot read " + what);
  if (size > limit)
    throw FormatError(path, std::nullopt,
                      what + " of " + std::to_string(size) + " bytes (a map's YAML is a few lines)");
  std::ifstream in(path, std::ios::binary);
  std::string text(size, '\0');
  if (!in.read(text.data(), static_cast<std::streamsize>(size))) throw IoError(path + ": cannot read " + what);
  return text;
}

std::string_view ros_yaml_trimmed(std::string_view s) {
  while (!s.empty() && std::isspace(static_cast<unsigned char>(s.front()))) s.remove_prefix(1);
  while (!s.empty() && std::isspace(static_cast<unsigned char>(s.back()))) s.remove_suffix(1);
  return s;
}

// A value without its quotes ('...' or "..."), and without a comment after it.
std::string ros_yaml_scalar(std::string_view v) {
  v = ros_yaml_trimmed(v);
  if (v.size() >= 2 && (v.front() == '"' || v.front() == '\'')) {
    const std::size_t close = v.find(v.front(), 1);
    if (close != std::string_view::npos) return std::string(v.substr(1, close - 1));
  }
  const std::size_t comment = v.find(" #");
  return std::string(ros_yaml_trimmed(v.substr(0, comment)));
}

// Flat `key: value` lines; a list value in brackets ([a, b, c]) or as "- item" lines under
// its key. Byte offsets name the line of an error.
struct RosYaml {
  std::map<std::string, std::vector<std::string>> values;
  std::map<std::string, std::size_t> at;
};

// A document written as one flow mapping ({image: map.pgm, resolution: 0.05, ...}, what
// some tools and yaml.dump(default_flow_style=True) write) as block lines: the braces
// become spaces and the commas between keys line breaks, so every byte keeps its offset.
// Empty when the document is not one.
std::string flow_mapping_as_lines(const std::string& text) {
  const std::size_t open = text.find_first_not_of(" \t\r\n");
  const std::size_t close = text.find_last_not_of(" \t\r\n");
  if (open == std::string::npos || text[open] != '{' || text[close] != '}') return {};
  std::string lines = text;
  lines[open] = lines[close] = ' ';
  int depth = 0;  // inside [ ] a comma separates list items, not keys
  for (std::size_t i = open + 1; i < close; ++i) {
    if (lines[i] == '[')
      ++depth;
    else if (lines[i] == ']')
      --depth;
    else if (lines[i] == '\n')
      lines[i] = ' ';  // a flow mapping may wrap anywhere
    else if (lines[i] == ',' && depth == 0)
      lines[i] = '\n';
  }
  return lines;
}

// `flow`: the lines come from flow_mapping_as_lines, whose keys follow a space.
RosYaml parse_ros_yaml_lines(const std::string& path, const std::string& text, bool flow) {
  RosYaml out;
  std::string list_key;  // the key whose "- item" lines follow
  std::size_t start = 0;
  while (start < text.size()) {
    std::size_t end = text.find('\n', start);
    if (end == std::string::npos) end = text.size();
    const std::string_view raw(text.data() + start, end - start);
    const std::size_t line_at = start;
    start = end + 1;
    const std::string_view line = ros_yaml_trimmed(raw);
    if (line.empty() || line.front() == '#' || line == "---" || line == "...") continue;
    const bool indented = !flow && std::isspace(static_cast<unsigned char>(raw.front()));
    if (line.front() == '-' && (line.size() == 1 || line[1] == ' ')) {
      if (list_key.empty()) throw FormatError(path, line_at, "a list item outside a key's list");
      out.values[list_key].push_back(ros_yaml_scalar(line.substr(1)));
      continue;
    }
    if (indented)
      throw FormatError(path, line_at,
                        "an indented line: a map_server YAML holds flat keys (image, resolution, origin, ...)");
    const std::size_t colon = line.find(':');
    if (colon == std::string_view::npos)
      throw FormatError(path, line_at, "expected 'key: value', found '" + std::string(line) + "'");
    const std::string key(ros_yaml_trimmed(line.substr(0, colon)));
    std::string_view value = ros_yaml_trimmed(line.substr(colon + 1));
    if (out.values.count(key)) throw FormatError(path, line_at, "the key '" + key + "' is given twice");
    out.at[key] = line_at;
    std::vector<std::string>& items = out.values[key];
    list_key.clear();
    if (value.empty() || value.front() == '#') {
      list_key = key;  // "- item" lines may follow
    } else if (value.front() == '[') {
      const std::size_t close = value.find(']');
      if (close == std::string_view::npos)
        throw FormatError(path, line_at, "the list of '" + key + "' has no closing ]");
      std::string_view inside = value.substr(1, close - 1);
      if (inside.find_first_of("[{") != std::string_view::npos)
        throw FormatError(path, line_at, "a nested list under '" + key + "': a map_server YAML holds numbers there");
      while (!ros_yaml_trimmed(inside).empty()) {
        const std::size_t comma = inside.find(',');
        items.push_back(ros_yaml_scalar(inside.substr(0, comma)));
        if (comma == std::string_view::npos) break;
        inside.remove_prefix(comma + 1);
      }
    } else if (value.front() == '{') {
      throw FormatError(path, line_at, "a mapping under '" + key + "': a map_server YAML holds flat keys");
    } else {
      items.push_back(ros_yaml_scalar(value));
    }
  }
  return out;
}

RosYaml parse_ros_yaml(const std::string& path, const std::string& text) {
  if (const std::string lines = flow_mapping_as_lines(text); !lines.empty())
    return parse_ros_yaml_lines(path, lines, true);
  return parse_ros_yaml_lines(path, text, false);
}

double ros_yaml_number(const RosYaml& yaml, const std::string& path, const std::string& key, std::size_t index,
                       std::optional<double> fallback) {
  const auto it = yaml.values.find(key);
  if (it == yaml.values.end()) {
    if (fallback) return *fallback;
    throw FormatError(path, std::nullopt, "no '" + key + "' (map_server's YAML names image, resolution and origin)");
  }
  if (index >= it->second.size())
    throw FormatError(path, yaml.at.at(key), "'" + key + "' needs " + std::to_string(index + 1) + " values");
  const std::string& text = it->second[index];
  double value = 0.0;
  const auto [end, error] = std::from_chars(text.data(), text.data() + text.size(), value);
  if (error != std::errc() || end != text.data() + text.size() || !std::isfinite(value))
    throw FormatError(path, yaml.at.at(key), "'" + key + "' is not a finite number: '" + text + "'");
  return value;
}

// The map image: binary (P5, 8 or 16 bits) or text (P2) PGM, as map_saver writes it, or a PNG.
struct RosMapImage {
  std::uint32_t width = 0, height = 0;
  unsigned maxval = 255;
  std::vector<std::uint16_t> pixels;  // row 0 the top
};

// A PNG map (map_saver --fmt png), as map_server reads one: colour channels averaged,
// alpha left out. Its size is checked from the header chunk before libpng decodes it.
RosMapImage read_ros_png(const std::string& path, const std::string& head) {
  const auto be32 = [&](std::size_t at) {
    std::uint32_t v = 0;
    for (std::size_t i = 0; i < 4; ++i) v = v << 8 | static_cast<unsigned char>(head[at + i]);
    return v;
  };
  if (head.compare(12, 4, "IHDR") != 0) throw FormatError(path, 12, "PNG: the first chunk is not IHDR");
  const std::uint64_t cells = std::uint64_t{be32(16)} * be32(20);
  if (cells > kMaxRosMapCells)
    throw FormatError(path, 16,
                      "a map of " + std::to_string(be32(16)) + " x " + std::to_string(be32(20)) +
                          " cells is more than " + std::to_string(kMaxRosMapCells));
  const DecodedPng png = decode_png(path);
  RosMapImage image;
  image.width = png.width;
  image.height = png.height;
  image.maxval = png.bit_depth == 16 ? 65535 : 255;
  const std::size_t sample_bytes = png.bit_depth == 16 ? 2 : 1;
  const auto channels = static_cast<std::size_t>(png.channels);
  const std::size_t averaged = channels >= 3 ? 3 : 1;  // grey (+ alpha): the grey; colour (+ alpha): R, G, B
  image.pixels.resize(std::size_t{png.width} * png.height);
  for (std::size_t i = 0; i < image.pixels.size(); ++i) {
    const std::uint8_t* p = png.bytes.data() + i * channels * sample_bytes;
    unsigned sum = 0;
    for (std::size_t c = 0; c < averaged; ++c) sum += sample_bytes == 2 ? unsigned{p[2 * c]} << 8 | p[2 * c + 1] : p[c];
    image.pixels[i] = static_cast<std::uint16_t>(sum / averaged);
  }
  return image;
}

RosMapImage read_ros_image(const std::string& path) {
  std::error_code error;
  const std::uint64_t size =
      std::filesystem::is_regular_file(path, error) ? std::filesystem::file_size(path, error) : 0;
  if (error || !std::filesystem::is_regular_file(path, error))
    throw IoError(path + ": the map's image is not a readable file");
  // The header from the first bytes; the samples only once the file is known to hold them
  // (a YAML may name any file: a large one is not read whole to find it is no PGM).
  std::ifstream in(path, std::ios::binary);
  std::string bytes(std::min<std::uint64_t>(size, kPgmHeaderBytes), '\0');
  if (!in.read(bytes.data(), static_cast<std::streamsize>(bytes.size())))
    throw IoError(path + ": cannot read the map's image");
  const auto read_rest = [&](std::uint64_t total) {
    const std::size_t had = bytes.size();
    bytes.resize(total);
    if (total > had && !in.read(bytes.data() + had, static_cast<std::streamsize>(total - had)))
      throw IoError(path + ": cannot read the map's image");
  };
  std::size_t at = 0;
  const auto skip_space = [&] {
    for (;;) {
      while (at < bytes.size() && std::isspace(static_cast<unsigned char>(bytes[at]))) ++at;
      if (at < bytes.size() && bytes[at] == '#') {
        while (at < bytes.size() && bytes[at] != '\n') ++at;
        continue;
      }
      return;
    }
  };
  const auto header_number = [&](const char* what) {
    skip_space();
    const std::size_t begin = at;
    std::uint64_t value = 0;
    while (at < bytes.size() && std::isdigit(static_cast<unsigned char>(bytes[at])) && at - begin < 10)
      value = value * 10 + static_cast<unsigned>(bytes[at++] - '0');
    if (at == begin || value == 0 || value > 0xFFFFFFFFu)
      throw FormatError(path, begin, std::string("PGM: expected the ") + what);
    return value;
  };
  if (bytes.size() >= 24 && bytes.compare(0, 8, "\x89PNG\r\n\x1a\n") == 0) return read_ros_png(path, bytes);
  if (bytes.size() < 2 || bytes[0] != 'P' || (bytes[1] != '5' && bytes[1] != '2'))
    throw FormatError(path, 0, "not a PGM (P5 or P2) or PNG image: vola reads map_server maps saved as PGM or PNG");
  const bool binary = bytes[1] == '5';
  at = 2;
  RosMapImage image;
  image.width = static_cast<std::uint32_t>(header_number("width"));
  image.height = static_cast<std::uint32_t>(header_number("height"));
  const std::uint64_t maxval = header_number("maxval");
  if (maxval > 65535) throw FormatError(path, at, "PGM: maxval " + std::to_string(maxval) + " is above 65535");
  image.maxval = static_cast<unsigned>(maxval);
  const std::uint64_t cells = std::uint64_t{image.width} * image.height;
  if (cells > kMaxRosMapCells)
    throw FormatError(path, std::nullopt,
                      "a map of " + std::to_string(image.width) + " x " + std::to_string(image.height) +
                          " cells is more than " + std::to_string(kMaxRosMapCells));
  const unsigned sample_bytes = image.maxval > 255 ? 2 : 1;
  if (at >= bytes.size() && size > bytes.size())
    throw FormatError(path, at, "PGM: a header longer than " + std::to_string(kPgmHeaderBytes) + " bytes");
  if (binary) {
    ++at;  // the one whitespace after maxval
    if (at > size || (size - at) / sample_bytes < cells)
      throw FormatError(path, at,
                        "PGM: truncated: " + std::to_string(image.width) + " x " + std::to_string(image.height) +
                            " samples need " + std::to_string(cells * sample_bytes) + " bytes after the header");
    read_rest(at + cells * sample_bytes);
    image.pixels.resize(cells);
    const auto* data = reinterpret_cast<const unsigned char*>(bytes.data()) + at;
    for (std::uint64_t i = 0; i < cells; ++i)
      image.pixels[i] = sample_bytes == 2 ? static_cast<std::uint16_t>(data[2 * i] << 8 | data[2 * i + 1]) : data[i];
  } else {
    if ((size - at) / 2 < cells)  // every sample takes a digit and a separator
      throw FormatError(path, at, "PGM: truncated: fewer than " + std::to_string(cells) + " samples");
    if (size - at > 8 * cells + kPgmHeaderBytes)  // at most 5 digits and separators a sample
      throw FormatError(path, at,
                        "PGM: " + std::to_string(size - at) + " bytes of text for " + std::to_string(cells) +
                            " samples: not a map_server image");
    read_rest(size);
    image.pixels.resize(cells);
    for (std::uint64_t i = 0; i < cells; ++i) {
      skip_space();
      const std::size_t begin = at;
      unsigned value = 0;
      while (at < bytes.size() && std::isdigit(static_cast<unsigned char>(bytes[at])) && at - begin < 6)
        value = value * 10 + static_cast<unsigned>(bytes[at++] - '0');
      if (at == begin) throw FormatError(path, begin, "PGM: sample " + std::to_string(i) + " is missing");
      // A sample above maxval (or a run of digits cut after six, whose rest read as the
      // next sample: a phantom obstacle) is damage, not a value to clamp.
      if (value > image.maxval || (at < bytes.size() && std::isdigit(static_cast<unsigned char>(bytes[at]))))
        throw FormatError(
            path, begin,
            "PGM: sample " + std::to_string(i) + " is above the header's maxval " + std::to_string(image.maxval));
      image.pixels[i] = static_cast<std::uint16_t>(value);
    }
    skip_space();
    if (at != size)
      throw FormatError(
          path, at,
          "PGM: more samples than the header's " + std::to_string(image.width) + " x " + std::to_string(image.height));
  }
  for (std::uint16_t& p : image.pixels) p = std::min<std::uint16_t>(p, static_cast<std::uint16_t>(image.maxval));
  return image;
}

}  // namespace

VoxelGrid read_ros_map(const std::string& yaml_path, double height) {
  const std::string text = ros_yaml_slurp(yaml_path, kMaxYamlBytes, "a map YAML");
  const RosYaml yaml = parse_ros_yaml(yaml_path, text);
  const auto image_key = yaml.values.find("image");
  if (image_key == yaml.values.end() || image_key->second.size() != 1 || image_key->second[0].empty())
    throw FormatError(yaml_path, std::nullopt, "no 'image' naming the map's PGM: not a map_server YAML");
  const double resolution = ros_yaml_number(yaml, yaml_path, "resolution", 0, std::nullopt);
  if (!(resolution > 0.0)) throw FormatError(yaml_path, yaml.at.at("resolution"), "'resolution' must be above 0");
  const double origin_x = ros_yaml_number(yaml, yaml_path, "origin", 0, std::nullopt);
  const double origin_y = ros_yaml_number(yaml, yaml_path, "origin", 1, std::nullopt);
  const double yaw =
      yaml.values.at("origin").size() > 2 ? ros_yaml_number(yaml, yaml_path, "origin", 2, std::nullopt) : 0.0;
  if (yaw != 0.0)
    throw FormatError(yaml_path, yaml.at.at("origin"),
                      "the map is turned by yaw " + ros_yaml_scalar(yaml.values.at("origin")[2]) +
                          " rad; vola reads maps with yaw 0 (most of ROS ignores yaw too): set it to 0 if the grid's "
                          "axes are the world's");
  const bool negate = ros_yaml_number(yaml, yaml_path, "negate", 0, 0.0) != 0.0;
  const double occupied_thresh = ros_yaml_number(yaml, yaml_path, "occupied_thresh", 0, 0.65);
  const auto mode = yaml.values.find("mode");
  const std::string mode_name = mode == yaml.values.end() || mode->second.empty() ? "trinary" : mode->second[0];
  if (mode_name != "trinary" && mode_name != "scale" && mode_name != "raw")
    throw FormatError(yaml_path, yaml.at.at("mode"),
                      "mode '" + mode_name + "' is not one of map_server's: trinary, scale, raw");
  if (!std::isfinite(height) || height < 0.0) throw OptionError("map_height", "must be 0 or more (file units)");

  std::filesystem::path image_path = image_key->second[0];
  if (image_path.is_relative()) image_path = std::filesystem::path(yaml_path).parent_path() / image_path;
  const RosMapImage image = read_ros_image(image_path.string());

  // map_server's rule: occupancy p = (255 - v) / 255 (v / 255 when negated), occupied when
  // p > occupied_thresh; raw mode takes v as the occupancy in percent (0-100; above 100,
  // such as 255, unknown).
  const double full = image.maxval;
  const auto occupied = [&](std::uint16_t v) {
    if (mode_name == "raw") return v <= 100 && v / 100.0 > occupied_thresh;
    const double p = negate ? v / full : (full - v) / full;
    return p > occupied_thresh;
  };
  VoxelGrid grid;
  const std::uint32_t layers =
      height > 0.0 ? static_cast<std::uint32_t>(std::max(1.0, std::ceil(height / resolution - 1e-9))) : 1;
  if (layers > (1u << 20))
    throw OptionError("map_height", "is more than 2^20 cells of " + ros_yaml_scalar(yaml.values.at("resolution")[0]));
  grid.dims = {image.width, image.height, layers};
  grid.origin = {origin_x, origin_y, 0.0};
  grid.voxel_size = resolution;
  grid.fixed_voxel_size = true;
  const std::uint64_t cells =
      static_cast<std::uint64_t>(std::count_if(image.pixels.begin(), image.pixels.end(), occupied));
  if (cells * layers > kMaxRosMapVoxels)
    throw OptionError("map_height", std::to_string(cells) + " occupied cells " + std::to_string(layers) +
                                        " voxels high are more than " + std::to_string(kMaxRosMapVoxels) + " voxels");
  grid.voxels.reserve(cells * layers);
  for (std::uint32_t row = 0; row < image.height; ++row)
    for (std::uint32_t col = 0; col < image.width; ++col)
      if (occupied(image.pixels[std::size_t{row} * image.width + col]))
        for (std::uint32_t k = 0; k < layers; ++k) grid.voxels.push_back({col, image.height - 1 - row, k});
  // A map with no occupied cell (a robot's first map, an empty room) is read as an empty
  // grid, as an empty binvox is: `vola info` reports 0 occupied cells.
  return grid;
}

}  // namespace vola::io
