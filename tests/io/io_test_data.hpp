// Helpers of the PLY/PCD/KITTI/NPY/binvox reader tests: the shared data folder, the
// facts EXPECTED.txt records about each file (written by an independent reader), and
// small files the tests and the fuzz seeds build byte by byte.
#pragma once

#include <cstdint>
#include <cstring>
#include <optional>
#include <string>
#include <vector>

#include "test_support.hpp"

namespace vola_io_test {

namespace fs = vola_test::fs;
using Bytes = std::vector<std::uint8_t>;

// $VOLA_SHARED/data.
fs::path data_dir();
// Regular files below `folder` whose name ends with `suffix`, sorted.
std::vector<fs::path> files_ending(const fs::path& folder, const std::string& suffix);

// The line of $VOLA_SHARED/data/EXPECTED.txt about `file_name` (the line starting with
// it, or with "<dir>/<file_name>"); throws std::runtime_error when there is none.
std::string expected_line(const fs::path& data, const std::string& file_name);
// The integer after `key` (e.g. "points=") on the line.
std::optional<std::uint64_t> expected_integer(const std::string& line, const std::string& key);
// The numbers in the bracket after `key` (e.g. "min=" -> "[-0.094  0.037 -0.055]"),
// separated by spaces and/or commas; nullopt when the bracket is not closed (a line cut
// short).
std::optional<std::vector<double>> expected_numbers(const std::string& line, const std::string& key);

// Appends raw little- or big-endian values.
template <class T>
void put(Bytes& out, T value, bool big_endian = false) {
  std::uint8_t raw[sizeof(T)];
  std::memcpy(raw, &value, sizeof(T));
  for (std::size_t i = 0; i < sizeof(T); ++i) out.push_back(raw[big_endian ? sizeof(T) - 1 - i : i]);
}
inline void put_text(Bytes& out, const std::string& text) { out.insert(out.end(), text.begin(), text.end()); }

// A small coloured PLY mesh in each encoding: 5 vertices (float x y z, uchar colours,
// a skipped float "quality"), an "edge" element before the vertices with a list of
// uchar-counted floats, and 4 faces (int-counted vertex_indices when `int_counts`,
// else uchar-counted): a triangle, a quad, a pentagon and a two-corner face, plus a
// per-face list of texture coordinates that must be skipped. Comments and obj_info.
struct PlySample {
  std::vector<std::array<float, 3>> xyz;
  std::vector<std::array<std::uint8_t, 3>> rgb;
  std::vector<std::vector<int>> faces;
};
PlySample ply_sample();
Bytes ply_bytes(const PlySample& sample, const std::string& encoding, bool int_counts);

// The fan triangulation the reader must produce, as vertex index triples.
std::vector<std::array<int, 3>> fan_triangles(const std::vector<std::vector<int>>& faces);

// A .npy file: dtype string such as "<f4", shape, raw data (already in that order).
Bytes npy_bytes(const std::string& dtype, const std::vector<std::uint64_t>& shape, bool fortran_order, const Bytes& data);

}  // namespace vola_io_test

// Skips when $VOLA_SHARED/data is missing, or fails when the environment variable CI is set.
#define VOLA_REQUIRE_DATA(dir_var)                                                              \
  const ::vola_io_test::fs::path dir_var = ::vola_io_test::data_dir();                          \
  if (!::vola_io_test::fs::is_directory(dir_var)) {                                             \
    if (std::getenv("CI")) {                                                                    \
      ADD_FAILURE() << "data folder " << dir_var << " is missing (CI is set; set VOLA_SHARED)"; \
      return;                                                                                   \
    }                                                                                           \
    GTEST_SKIP() << "data folder " << dir_var << " is missing; set VOLA_SHARED to run this";     \
  }
