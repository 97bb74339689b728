#include "vola/io/binvox.hpp"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <fstream>
#include <limits>
#include <optional>
#include <string_view>

#include "file_bytes.hpp"
#include "header_words.hpp"
#include "vola/error.hpp"
#include "vola/output_file.hpp"

namespace vola::io {

namespace {

// binvox writers may put a '+' before numbers.
template <class T>
bool parse_signed_number(std::string_view s, T& value) {
  if (!s.empty() && s.front() == '+') s.remove_prefix(1);
  return parse_number(s, value);
}

// Shortest text that reads back as the same double.
std::string number_text(double v) {
  char buffer[32];
  const auto r = std::to_chars(buffer, buffer + sizeof buffer, v);
  return std::string(buffer, r.ptr);
}

// Run-length pairs (value, count 1..255).
void append_run(std::vector<std::uint8_t>& out, std::uint8_t value, std::uint64_t count) {
  for (; count > 0; count -= std::min<std::uint64_t>(count, 255)) {
    out.push_back(value);
    out.push_back(static_cast<std::uint8_t>(std::min<std::uint64_t>(count, 255)));
  }
}

// Calls f(value, first cell, count) for each run from `at`, checking each against the
// grid's `cells`; returns the number of occupied cells.
template <class F>
std::uint64_t walk_runs(std::span<const std::uint8_t> bytes, std::size_t at, std::uint64_t cells,
                        const std::string& name, F&& f) {
  std::uint64_t index = 0, occupied = 0;
  while (index < cells) {
    if (bytes.size() - at < 2)
      throw FormatError(name, at, "the runs end after " + std::to_string(index) + " of " + std::to_string(cells) +
                                      " cells (truncated file)");
    const std::uint8_t value = bytes[at], count = bytes[at + 1];
    if (value > 1) throw FormatError(name, at, "run value " + std::to_string(value) + " is not 0 or 1");
    if (count > cells - index)
      throw FormatError(name, at + 1, "a run of " + std::to_string(count) + " cells passes the grid's " +
                                          std::to_string(cells) + " cells");
    f(value, index, count);
    if (value) occupied += count;
    index += count;
    at += 2;
  }
  return occupied;
}

}  // namespace

VoxelGrid parse_binvox(std::span<const std::uint8_t> bytes, const std::string& name) {
  const std::string_view text(reinterpret_cast<const char*>(bytes.data()), bytes.size());
  std::optional<std::array<std::uint64_t, 3>> dim;
  Point translate{0, 0, 0};
  double scale = 1.0;
  std::size_t at = 0;
  std::uint64_t line_number = 0;
  for (;;) {
    const std::size_t end = text.find('\n', at);
    ++line_number;
    auto fail = [&](const std::string& cause) -> void {
      throw FormatError(name, at, "header line " + std::to_string(line_number) + ": " + cause);
    };
    if (end == std::string_view::npos) fail("the header ends without a 'data' line (truncated or not a binvox file)");
    std::string_view line = text.substr(at, end - at);
    if (line_number == 1) {
      const auto words = split_words(line);
      if (words.size() != 2 || words[0] != "#binvox") fail("not a binvox file (the first line is not '#binvox VERSION')");
      at = end + 1;
      continue;
    }
    line = line.substr(0, line.find('#'));  // a comment runs to the end of its line
    const auto words = split_words(line);
    if (words.empty()) {
      at = end + 1;
      continue;
    }
    if (words[0] == "dim") {
      std::array<std::uint64_t, 3> d{};
      if (words.size() != 4) fail("expected 'dim A B C'");
      for (std::size_t i = 0; i < 3; ++i)
        if (!parse_signed_number(words[i + 1], d[i]) || d[i] == 0 || d[i] > std::numeric_limits<std::uint32_t>::max())
          fail("dim '" + std::string(words[i + 1]) + "' is not an integer 1..4294967295");
      dim = d;
    } else if (words[0] == "translate") {
      if (words.size() != 4) fail("expected 'translate TX TY TZ'");
      for (std::size_t i = 0; i < 3; ++i)
        if (!parse_signed_number(words[i + 1], translate[i]) || !std::isfinite(translate[i]))
          fail("translate '" + std::string(words[i + 1]) + "' is not a finite number");
    } else if (words[0] == "scale") {
      if (words.size() != 2 || !parse_signed_number(words[1], scale) || !(scale > 0) || !std::isfinite(scale))
        fail("expected 'scale S' with S a positive number");
    } else if (words[0] == "data") {
      if (words.size() != 1) fail("expected 'data' alone on its line");
      at = end + 1;
      break;
    } else {
      fail("unknown header keyword '" + std::string(words[0]) + "'");
    }
    at = end + 1;
  }
  if (!dim) throw FormatError(name, at, "the binvox header has no 'dim' line");
  const auto [a, b, c] = *dim;
  if (a > std::numeric_limits<std::uint64_t>::max() / b || a * b > std::numeric_limits<std::uint64_t>::max() / c)
    throw FormatError(name, at, "dim " + std::to_string(a) + " x " + std::to_string(b) + " x " + std::to_string(c) +
                                    " has more cells than 64 bits count");
  const std::uint64_t cells = a * b * c;

  VoxelGrid grid;
  grid.dims = {static_cast<std::uint32_t>(a), static_cast<std::uint32_t>(c), static_cast<std::uint32_t>(b)};
  grid.origin = translate;
  grid.voxel_size = scale / static_cast<double>(std::max({a, b, c}));
  if (!(grid.voxel_size > 0))  // a denormal scale over a large dim rounds to 0
    throw FormatError(name, at, "scale " + number_text(scale) + " over " + std::to_string(std::max({a, b, c})) +
                                    " cells makes a voxel size of 0");
  // First the runs alone: how many voxels they set, before storing any.
  const std::uint64_t occupied = walk_runs(bytes, at, cells, name, [](std::uint8_t, std::uint64_t, std::uint64_t) {});
  const std::uint64_t limit = kBinvoxVoxelAllowance + kBinvoxVoxelsPerByte * bytes.size();
  if (occupied > limit)
    throw FormatError(name, at, "the runs set " + std::to_string(occupied) + " voxels, more than the " +
                                    std::to_string(limit) + " this reader holds for a file of " +
                                    std::to_string(bytes.size()) + " bytes (kBinvoxVoxelAllowance + " +
                                    std::to_string(kBinvoxVoxelsPerByte) + " per byte)");
  grid.voxels.reserve(static_cast<std::size_t>(occupied));
  // Copies: clang 14 cannot capture structured bindings in a lambda.
  const std::uint64_t bc = b * c, c_side = c;
  walk_runs(bytes, at, cells, name, [&](std::uint8_t value, std::uint64_t first, std::uint64_t count) {
    if (!value) return;
    for (std::uint64_t i = first; i < first + count; ++i) {
      const std::uint64_t x = i / bc, zy = i % bc;
      grid.voxels.push_back({static_cast<std::uint32_t>(x), static_cast<std::uint32_t>(zy % c_side),
                             static_cast<std::uint32_t>(zy / c_side)});
    }
  });
  return grid;
}

VoxelGrid read_binvox(const std::string& path) { return parse_binvox(read_file_bytes(path), path); }

std::vector<std::uint8_t> serialize_binvox(const Tree& tree) {
  std::uint32_t largest = 0;
  tree.for_each_voxel([&](const Voxel& v) { largest = std::max({largest, v.x, v.y, v.z}); });
  const std::uint64_t side = std::uint64_t{largest} + 1;
  if (side > kMaxBinvoxSide)
    throw InvalidArgument("a binvox grid of side " + std::to_string(side) + " (the tree's largest coordinate + 1) exceeds " +
                          std::to_string(kMaxBinvoxSide) + ": binvox stores every cell, the file would hold " +
                          std::to_string(side * side * side) + " cells");
  std::vector<std::uint64_t> indices;
  indices.reserve(static_cast<std::size_t>(tree.voxel_count()));
  tree.for_each_voxel([&](const Voxel& v) { indices.push_back((v.x * side + v.z) * side + v.y); });
  std::sort(indices.begin(), indices.end());

  const Frame frame = tree.frame();
  const std::string side_text = std::to_string(side);
  const std::string header = "#binvox 1\ndim " + side_text + " " + side_text + " " + side_text + "\ntranslate " +
                             number_text(frame.origin[0]) + " " + number_text(frame.origin[1]) + " " +
                             number_text(frame.origin[2]) + "\nscale " +
                             number_text(frame.voxel_size * static_cast<double>(side)) + "\ndata\n";
  std::vector<std::uint8_t> out(header.begin(), header.end());
  std::uint64_t next = 0;  // first cell not yet written
  for (std::size_t i = 0; i < indices.size();) {
    std::size_t j = i + 1;
    while (j < indices.size() && indices[j] == indices[j - 1] + 1) ++j;
    append_run(out, 0, indices[i] - next);
    append_run(out, 1, j - i);
    next = indices[j - 1] + 1;
    i = j;
  }
  append_run(out, 0, side * side * side - next);
  return out;
}

void write_binvox(const Tree& tree, const std::string& path) {
  const auto bytes = serialize_binvox(tree);
  OutputFile out(path);
  out.write(bytes.data(), bytes.size());
  out.commit();
}

}  // namespace vola::io
