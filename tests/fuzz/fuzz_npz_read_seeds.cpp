// Seeds for fuzz_npz_read: archives written here with libzip from the shared data
// folder's ModelNet10 set (beside golden/): its first two 32^3 grids and labels
// (deflated, as numpy.savez_compressed writes), one grid pooled to 8^3 (stored, as
// numpy.savez writes), plus the whole set for the replay (too large for libFuzzer's
// inputs); and archives made here: a bool grid with int32 labels, a float grid, an
// archive without labels, one with two splits. Linked into fuzz_npz_read_replay in place
// of fuzz_seeds.cpp.
#include <unistd.h>
#include <zip.h>

#include <algorithm>
#include <cstring>
#include <fstream>
#include <iterator>
#include <stdexcept>
#include <string>

#include "fuzz_seeds.hpp"
#include "vola/learn/npz.hpp"

namespace vola_fuzz {
namespace {

namespace fs = std::filesystem;
using Bytes = std::vector<std::uint8_t>;

struct Member {
  std::string name;
  Bytes npy;
};

// A version 1.0 .npy: the header dict padded with spaces to a multiple of 64 bytes. A
// structured dtype's descr is a list ("[('x', '<f4'), ...]"), written unquoted.
Bytes npy(const std::string& descr, const std::vector<std::uint64_t>& shape, const Bytes& values) {
  std::string dims;
  for (auto s : shape) dims += std::to_string(s) + ",";
  if (shape.size() > 1) dims.pop_back();
  const std::string quoted = descr.starts_with("[") ? descr : "'" + descr + "'";
  std::string header = "{'descr': " + quoted + ", 'fortran_order': False, 'shape': (" + dims + "), }";
  while ((10 + header.size() + 1) % 64) header += ' ';
  header += '\n';
  Bytes b{0x93, 'N', 'U', 'M', 'P', 'Y', 1, 0, static_cast<std::uint8_t>(header.size() & 0xff),
          static_cast<std::uint8_t>(header.size() >> 8)};
  b.reserve(b.size() + header.size() + values.size());  // (and GCC 12 then sees no -Warray-bounds)
  b.insert(b.end(), header.begin(), header.end());
  b.insert(b.end(), values.begin(), values.end());
  return b;
}

Bytes archive(const std::vector<Member>& members, bool deflate) {
  const auto path = fs::temp_directory_path() / ("vola_fuzz_npz_seed_" + std::to_string(::getpid()) + ".npz");
  int error = 0;
  zip_t* z = zip_open(path.c_str(), ZIP_CREATE | ZIP_TRUNCATE, &error);
  if (!z) throw std::runtime_error("zip_open failed for " + path.string());
  for (const auto& m : members) {
    zip_source_t* source = zip_source_buffer(z, m.npy.data(), m.npy.size(), 0);
    const zip_int64_t index = zip_file_add(z, (m.name + ".npy").c_str(), source, ZIP_FL_OVERWRITE);
    if (index < 0) throw std::runtime_error("zip_file_add failed");
    zip_set_file_compression(z, static_cast<zip_uint64_t>(index), deflate ? ZIP_CM_DEFLATE : ZIP_CM_STORE, 0);
  }
  if (zip_close(z) != 0) throw std::runtime_error("zip_close failed");
  std::ifstream in(path, std::ios::binary);
  Bytes b{std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
  fs::remove(path);
  return b;
}

template <class T>
Bytes raw(const std::vector<T>& v) {
  Bytes b(v.size() * sizeof(T));
  std::memcpy(b.data(), v.data(), b.size());
  return b;
}

}  // namespace

std::vector<Seed> synthetic_seeds() {
  Bytes bool_grid(2 * 64);
  for (std::size_t i = 0; i < bool_grid.size(); ++i) bool_grid[i] = (i * 7) % 5 == 0;
  std::vector<float> float_grid(4 * 4 * 4);
  for (std::size_t i = 0; i < float_grid.size(); ++i) float_grid[i] = i % 3 == 0 ? 1.0f : 0.0f;
  const Bytes labels2 = raw(std::vector<std::int32_t>{3, 9});
  // Point files: pyntcloud's records beside a mesh, numpy.savez's lone arr_0.
  Bytes records;
  for (int i = 0; i < 3; ++i) {
    const Bytes xyz = raw(std::vector<float>{0.5f * static_cast<float>(i), 1.0f, -2.0f});
    records.insert(records.end(), xyz.begin(), xyz.end());
    records.push_back(static_cast<std::uint8_t>(80 * i));
  }
  const std::string point_descr = "[('x', '<f4'), ('y', '<f4'), ('z', '<f4'), ('red', '|u1')]";
  return {
      {"pyntcloud_points.npz",
       archive({{"points", npy(point_descr, {3}, records)}, {"mesh", npy("<i4", {2}, labels2)}}, true)},
      {"savez_arr_0.npz", archive({{"arr_0", npy("<f8", {2, 3}, raw(std::vector<double>{1, 2, 3, 4, 5, 6}))}}, false)},
      {"bool_int32.npz",
       archive({{"X_train", npy("|b1", {2, 4, 4, 4}, bool_grid)}, {"y_train", npy("<i4", {2}, labels2)}}, true)},
      {"float_stored.npz", archive({{"X_test", npy("<f4", {1, 4, 4, 4}, raw(float_grid))},
                                    {"y_test", npy("<i8", {1}, raw(std::vector<std::int64_t>{0}))}},
                                   false)},
      {"no_labels.npz", archive({{"X_train", npy("|u1", {2, 4, 4, 4}, bool_grid)}}, true)},
      {"two_splits.npz", archive({{"X_train", npy("|u1", {2, 4, 4, 4}, bool_grid)},
                                  {"y_train", npy("<i4", {2}, labels2)},
                                  {"X_test", npy("|u1", {2, 4, 4, 4}, bool_grid)},
                                  {"y_test", npy(">i2", {2}, Bytes{0, 1, 0, 2})}},
                                 false)},
  };
}

// modelnet/*.npz: the first grids and labels of each X_<split> / y_<split>, re-archived;
// the archive itself too.
std::vector<Seed> golden_seeds(const fs::path& golden) {
  std::vector<Seed> seeds;
  const auto folder = shared_data(golden, "modelnet");
  if (folder.empty()) return seeds;
  for (const auto& entry : fs::directory_iterator(folder)) {
    if (!entry.is_regular_file() || entry.path().extension() != ".npz") continue;
    const std::string path = entry.path().string(), stem = entry.path().stem().string();
    const vola::learn::LabelledGrids grids = vola::learn::read_labelled_grids(path);
    const std::size_t n = std::min<std::size_t>(2, grids.size());
    const auto side = static_cast<std::uint64_t>(grids.side);
    Bytes cells(grids.cells.begin(), grids.cells.begin() + static_cast<std::ptrdiff_t>(n * grids.cells_per_grid()));
    std::vector<std::int64_t> labels(grids.labels.begin(), grids.labels.begin() + static_cast<std::ptrdiff_t>(n));
    seeds.push_back({"first2_" + stem + ".npz",
                     archive({{"X_" + grids.split, npy("|u1", {n, side, side, side}, cells)},
                              {"y_" + grids.split, npy("<i8", {n}, raw(labels))}},
                             true)});
    // Grid 0 pooled to 8^3: a cell is 1 when any of its (side / 8)^3 cells is.
    const std::uint64_t f = side / 8;
    Bytes pooled(512, 0);
    for (std::uint64_t x = 0; x < side; ++x)
      for (std::uint64_t y = 0; y < side; ++y)
        for (std::uint64_t z = 0; z < side; ++z)
          if (grids.cells[(x * side + y) * side + z]) pooled[((x / f) * 8 + y / f) * 8 + z / f] = 1;
    seeds.push_back({"pooled_" + stem + ".npz",
                     archive({{"X_" + grids.split, npy("|u1", {1, 8, 8, 8}, pooled)},
                              {"y_" + grids.split, npy("<i8", {1}, raw(std::vector<std::int64_t>{labels.at(0)}))}},
                             false)});
    std::ifstream in(entry.path(), std::ios::binary);
    seeds.push_back({stem + ".npz", Bytes{std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()}});
  }
  std::sort(seeds.begin(), seeds.end(), [](const Seed& a, const Seed& b) { return a.name < b.name; });
  return seeds;
}

}  // namespace vola_fuzz
