// The shared benchmark inputs (../shared/data/bench): NPY int16 arrays of shape (N, 3),
// C order, little-endian. Read here rather than through vola_io so that the benchmarks
// build whether or not the CLI's I/O library is configured.
#pragma once

#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <stdexcept>
#include <string>
#include <vector>

#include "vola/key.hpp"

namespace vola_bench {

struct Points {
  std::vector<std::int16_t> xyz;  // x0 y0 z0 x1 ...
  std::size_t size() const { return xyz.size() / 3; }
  std::vector<vola::Voxel> voxels() const {
    std::vector<vola::Voxel> v(size());
    for (std::size_t i = 0; i < v.size(); ++i)
      v[i] = vola::Voxel{static_cast<std::uint32_t>(xyz[3 * i]), static_cast<std::uint32_t>(xyz[3 * i + 1]),
                         static_cast<std::uint32_t>(xyz[3 * i + 2])};
    return v;
  }
};

// $VOLA_SHARED/data/bench, else ../shared/data/bench (relative to the working directory),
// else the folder given at build time.
inline std::filesystem::path default_data_dir() {
  if (const char* shared = std::getenv("VOLA_SHARED")) return std::filesystem::path(shared) / "data" / "bench";
#ifdef VOLA_SHARED_DEFAULT
  const std::filesystem::path relative = std::filesystem::path("..") / "shared" / "data" / "bench";
  if (std::filesystem::exists(relative)) return relative;
  return std::filesystem::path(VOLA_SHARED_DEFAULT) / "data" / "bench";
#else
  return std::filesystem::path("..") / "shared" / "data" / "bench";
#endif
}

inline Points read_points(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw std::runtime_error("cannot open " + path.string());
  std::vector<char> bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  if (bytes.size() < 10 || std::memcmp(bytes.data(), "\x93NUMPY", 6) != 0)
    throw std::runtime_error(path.string() + ": not an .npy file");
  const int major = static_cast<unsigned char>(bytes[6]);
  std::size_t header_len = 0, at = 0;
  if (major == 1) {
    header_len = static_cast<unsigned char>(bytes[8]) | (static_cast<std::size_t>(static_cast<unsigned char>(bytes[9])) << 8);
    at = 10;
  } else {
    if (bytes.size() < 12) throw std::runtime_error(path.string() + ": truncated header");
    for (int i = 0; i < 4; ++i) header_len |= std::size_t{static_cast<unsigned char>(bytes[8 + i])} << (8 * i);
    at = 12;
  }
  if (at + header_len > bytes.size()) throw std::runtime_error(path.string() + ": truncated header");
  const std::string header(bytes.data() + at, header_len);
  if (header.find("'<i2'") == std::string::npos || header.find("'fortran_order': False") == std::string::npos)
    throw std::runtime_error(path.string() + ": expected little-endian int16 in C order, header " + header);
  const auto shape_at = header.find("'shape': (");
  if (shape_at == std::string::npos) throw std::runtime_error(path.string() + ": no shape");
  std::size_t rows = 0, cols = 0;
  if (std::sscanf(header.c_str() + shape_at, "'shape': (%zu, %zu)", &rows, &cols) != 2 || cols != 3)
    throw std::runtime_error(path.string() + ": expected shape (N, 3), header " + header);
  at += header_len;
  if (bytes.size() - at != rows * 3 * sizeof(std::int16_t))
    throw std::runtime_error(path.string() + ": data size does not match the shape");
  Points p;
  p.xyz.resize(rows * 3);
  std::memcpy(p.xyz.data(), bytes.data() + at, rows * 3 * sizeof(std::int16_t));
  for (const auto c : p.xyz)
    if (c < 0 || c >= 1024) throw std::runtime_error(path.string() + ": coordinate outside [0, 1024)");
  return p;
}

}  // namespace vola_bench
