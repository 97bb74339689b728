// Shared helpers of the test suite: slow reference models written from
// docs FORMAT.md (independent of the library's fast paths), random voxel sets,
// files and the golden folder.
#pragma once

#include <array>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <map>
#include <optional>
#include <random>
#include <set>
#include <string>
#include <utility>
#include <vector>

#include <gtest/gtest.h>

#include "vola/vola.hpp"

namespace vola_test {

namespace fs = std::filesystem;

// A voxel of the reference models; std::array orders lexicographically (x, y, z).
using Xyz = std::array<std::uint32_t, 3>;
using XyzSet = std::set<Xyz>;

inline Xyz to_xyz(const vola::Voxel& v) { return {v.x, v.y, v.z}; }
inline vola::Voxel to_voxel(const Xyz& v) { return {v[0], v[1], v[2]}; }

// ---- Slow reference model (FORMAT.md sections 3-5) ----

// The level-`level` cell of voxel v in a depth-`depth` tree: v >> 2*(D-1-L).
Xyz coarse_cell(const Xyz& v, int level, int depth);
// i_L = ((x>>2k)&3) + 4*((y>>2k)&3) + 16*((z>>2k)&3), k = D-1-L.
unsigned slow_local_index(const Xyz& v, int level, int depth);
// i_0 .. i_level.
std::vector<unsigned> slow_path(const Xyz& v, int level, int depth);
// Occupancy words of a sparse file, level by level: blocks of level L ordered by the
// path of their parent cell, bits = local indices of the occupied level-L cells.
std::vector<std::uint64_t> slow_sparse_words(const XyzSet& voxels, int depth);
// Dense body (no payload): level L is a flat x-fastest bitmap of side 4^(L+1).
std::vector<std::uint64_t> slow_dense_words(const XyzSet& voxels, int depth);
// The level-L cells of a voxel set.
XyzSet slow_cells(const XyzSet& voxels, int level, int depth);
// Voxels sorted in storage order (by path, FORMAT.md section 4), without using keys.
std::vector<Xyz> slow_storage_order(const XyzSet& voxels, int depth);

// ---- Reading a tree back into the reference model ----
std::vector<Xyz> voxel_sequence(const vola::Tree& tree);  // for_each_voxel order
XyzSet voxel_set(const vola::Tree& tree);

// ---- Random voxel sets ----
enum class Shape { empty, single, uniform, clustered, slab, full_block };
const char* shape_name(Shape shape);

struct Scenario {
  std::uint64_t seed = 0;
  int depth = 1;
  Shape shape = Shape::uniform;
  std::vector<Xyz> voxels;  // with duplicates, in random order
  XyzSet unique() const { return XyzSet(voxels.begin(), voxels.end()); }
  std::string describe() const;
};
// Depth cycles through 1..10 with the seed and the shape with seed / 10; the size
// and the voxels are random.
Scenario make_scenario(std::uint64_t seed);
// Seeds whose scenarios have `shape`: every depth 1..10, `repeats` times.
std::vector<std::uint64_t> seeds_for(Shape shape, int repeats);
inline constexpr Shape kAllShapes[] = {Shape::empty, Shape::single, Shape::uniform,
                                       Shape::clustered, Shape::slab, Shape::full_block};
std::vector<Xyz> random_voxels(std::mt19937_64& rng, int depth, Shape shape, std::size_t count);
Xyz random_xyz(std::mt19937_64& rng, int depth);

// ---- Files ----
std::vector<std::uint8_t> read_bytes(const fs::path& path);
void write_bytes(const fs::path& path, const std::vector<std::uint8_t>& bytes);
// `gzip -dc path`; throws std::runtime_error when gzip fails.
std::vector<std::uint8_t> gunzip_file(const fs::path& path);

// A fresh directory removed with its contents at destruction.
class TempDir {
 public:
  TempDir();
  ~TempDir();
  TempDir(const TempDir&) = delete;
  TempDir& operator=(const TempDir&) = delete;
  const fs::path& path() const noexcept { return path_; }
  fs::path operator/(const std::string& name) const { return path_ / name; }

 private:
  fs::path path_;
};

// Little-endian field access on raw file bytes.
// (The library only builds on little-endian hosts, so memcpy is the byte order.)
template <class T>
T get_le(const std::vector<std::uint8_t>& bytes, std::size_t offset) {
  T value{};
  std::memcpy(&value, bytes.data() + offset, sizeof(T));
  return value;
}
template <class T>
void put_le(std::vector<std::uint8_t>& bytes, std::size_t offset, T value) {
  std::memcpy(bytes.data() + offset, &value, sizeof(T));
}

// An 80-byte header written field by field from FORMAT.md section 2.
struct RawHeader {
  std::uint32_t header_size = 80;
  std::uint16_t version = 1;
  std::uint8_t mode = 0;
  std::uint8_t depth = 1;
  std::uint32_t nbits = 0;
  std::uint32_t crs = 2000;
  double lat = 0, lon = 0;
  std::array<double, 6> bbox{};
};
std::vector<std::uint8_t> raw_file(const RawHeader& header, const std::vector<std::uint64_t>& words);

// CRC-32C one bit at a time: the slow twin of the library's.
std::uint32_t slow_crc32c(const std::uint8_t* bytes, std::size_t size);
// Rewrites the trailer (length, CRC-32C) of the version-2 extension that starts at `at`
// and ends the file, so that a test that alters one field reaches that field's check.
void reseal_extension(std::vector<std::uint8_t>& bytes, std::size_t at);

// The FormatError `f` throws, or nullopt when it throws none (other exceptions pass).
template <class F>
std::optional<vola::FormatError> format_error_of(F&& f) {
  try {
    f();
  } catch (const vola::FormatError& e) {
    return e;
  }
  return std::nullopt;
}

// ---- Golden folder ----
// $VOLA_SHARED/golden, VOLA_SHARED defaulting to the source tree's ../shared.
fs::path golden_dir();

struct GoldenCase {
  std::string name;
  int depth = 0;
  int mode = 0;
  int nbits = 0;
  std::uint32_t crs = 0;
  std::size_t npoints = 0;
  std::size_t nvoxels = 0;
  std::string vol_file;  // "None" when the reference wrote no file
  std::optional<std::uint64_t> vol_size;
  bool has_file() const { return vol_file != "None"; }
};
// Throws std::runtime_error on a malformed manifest.
std::vector<GoldenCase> read_manifest(const fs::path& golden);
// The reference file's bytes (gunzipped when it is .gz).
std::vector<std::uint8_t> golden_file_bytes(const fs::path& golden, const GoldenCase& c);
// "x y z" lines.
XyzSet read_voxel_list(const fs::path& path);
// "x y z hex" lines of spec_voxels.txt.
std::map<Xyz, std::uint64_t> read_spec_payloads(const fs::path& path);

// The build parameters of a case, from params.json.
struct GoldenParams {
  int depth = 0;
  bool dense = false;
  int nbits = 0;
  std::uint32_t crs = 0;
  vola::Box bbox;
};
GoldenParams read_params(const fs::path& case_dir);
// Number of whitespace-separated columns on the first line of a text file.
int count_columns(const fs::path& path);

}  // namespace vola_test

// Skips the current test when the golden folder is missing, or fails it when the
// environment variable CI is set (a CI run must not pass by testing nothing).
#define VOLA_REQUIRE_GOLDEN(dir_var)                                                              \
  const ::vola_test::fs::path dir_var = ::vola_test::golden_dir();                                \
  if (!::vola_test::fs::is_directory(dir_var)) {                                                  \
    if (std::getenv("CI")) {                                                                      \
      ADD_FAILURE() << "golden folder " << dir_var << " is missing (CI is set; set VOLA_SHARED)"; \
      return;                                                                                     \
    }                                                                                             \
    GTEST_SKIP() << "golden folder " << dir_var << " is missing; set VOLA_SHARED to run this";     \
  }
