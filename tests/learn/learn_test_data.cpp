#include "learn_test_data.hpp"

#include <zip.h>

#include <cstring>
#include <random>
#include <stdexcept>

namespace vola_learn_test {

void write_npz(const std::string& path, const std::vector<std::pair<std::string, Bytes>>& members) {
  int code = 0;
  zip_t* archive = zip_open(path.c_str(), ZIP_CREATE | ZIP_TRUNCATE, &code);
  if (!archive) throw std::runtime_error("cannot create " + path);
  for (const auto& [name, bytes] : members) {
    // libzip reads the buffer at zip_close: hand it a copy it frees.
    void* copy = std::malloc(bytes.size() ? bytes.size() : 1);
    std::memcpy(copy, bytes.data(), bytes.size());
    zip_source_t* source = zip_source_buffer(archive, copy, bytes.size(), 1);
    if (!source || zip_file_add(archive, (name + ".npy").c_str(), source, ZIP_FL_OVERWRITE) < 0)
      throw std::runtime_error("cannot add " + name + " to " + path);
  }
  if (zip_close(archive) != 0) throw std::runtime_error("cannot write " + path);
}

Bytes grids_npy(const std::vector<std::vector<std::uint8_t>>& grids, int side, const std::string& dtype) {
  Bytes data;
  const int size = dtype == "|u1" ? 1 : 4;
  for (const auto& grid : grids)
    for (std::uint8_t cell : grid) {
      if (size == 1) {
        data.push_back(cell);
      } else {
        const std::int32_t value = cell;
        vola_io_test::put(data, value);
      }
    }
  const std::uint64_t s = std::uint64_t(side);
  return vola_io_test::npy_bytes(dtype, {grids.size(), s, s, s}, false, data);
}

Bytes labels_npy(const std::vector<std::int64_t>& labels) {
  Bytes data;
  for (std::int64_t label : labels) vola_io_test::put(data, label);
  return vola_io_test::npy_bytes("<i8", {labels.size()}, false, data);
}

std::vector<std::uint8_t> shape_grid(int shape, std::uint64_t seed) {
  constexpr int side = 32;
  std::mt19937_64 random(seed);
  const int jitter = int(random() % 5) - 2;
  std::vector<std::uint8_t> grid(std::size_t(side) * side * side, 0);
  const auto set = [&](int x, int y, int z) {
    x += jitter;
    y -= jitter;
    if (x >= 0 && y >= 0 && z >= 0 && x < side && y < side && z < side) grid[(std::size_t(x) * side + y) * side + z] = 1;
  };
  // Shape k: a box whose width, depth and height depend on k, hollow for odd k.
  const int w = 6 + 2 * (shape % 5), d = 20 - 2 * (shape % 5), h = 4 + 3 * shape;
  const bool hollow = shape % 2 == 1;
  for (int x = 16 - w / 2; x < 16 + w / 2; ++x)
    for (int y = 16 - d / 2; y < 16 + d / 2; ++y)
      for (int z = 2; z < 2 + h && z < side; ++z) {
        const bool edge = x == 16 - w / 2 || x == 16 + w / 2 - 1 || y == 16 - d / 2 || y == 16 + d / 2 - 1;
        if (!hollow || edge) set(x, y, z);
      }
  return grid;
}

std::string committed_model_path() { return std::string(VOLA_SOURCE_MODELS) + "/modelnet10-small.pt"; }

}  // namespace vola_learn_test
