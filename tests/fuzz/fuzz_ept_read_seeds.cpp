// Seeds for fuzz_ept_read: EPT datasets made here in the entry point's layout (ept.json,
// the root hierarchy, a subtree file, two nodes' data): binary nodes of scaled integer and
// float coordinates with attributes, and laszip nodes that are the shared data folder's
// Entwine tile (PDAL's 1.2-with-color 0-0-0-0.laz, beside golden/) as Entwine lays them
// out. Linked into fuzz_ept_read_replay in place of fuzz_seeds.cpp.
#include <cstring>
#include <fstream>
#include <iterator>
#include <string>

#include "fuzz_ept_parts.hpp"
#include "fuzz_seeds.hpp"

namespace vola_fuzz {
namespace {

namespace fs = std::filesystem;

std::string ept_json(const std::string& type, int points, const std::string& schema) {
  return "{\"bounds\": [0, 0, 0, 8, 8, 8], \"boundsConforming\": [0, 0, 0, 8, 8, 8], \"dataType\": \"" + type +
         "\", \"hierarchyType\": \"json\", \"points\": " + std::to_string(points) + ", \"schema\": " + schema +
         ", \"span\": 128, \"srs\": {\"authority\": \"EPSG\", \"horizontal\": \"32610\", \"wkt\": \"\"}, "
         "\"version\": \"1.0.0\"}";
}

template <class T>
void put(std::string& out, T value) {
  char bytes[sizeof value];
  std::memcpy(bytes, &value, sizeof value);
  out.append(bytes, sizeof value);
}

// Records of the binary schema below: X, Y scaled int32, Z float64, Intensity u16,
// Classification u8.
std::string records(int n, int first) {
  std::string r;
  for (int i = 0; i < n; ++i) {
    put<std::int32_t>(r, 100 * (first + i));
    put<std::int32_t>(r, 50 * (first + i));
    put<double>(r, 0.5 * (first + i));
    put<std::uint16_t>(r, static_cast<std::uint16_t>(1000 + i));
    r.push_back(static_cast<char>(2 + i % 4));
  }
  return r;
}

}  // namespace

std::vector<Seed> synthetic_seeds() {
  const std::string schema =
      "[{\"name\": \"X\", \"size\": 4, \"type\": \"signed\", \"scale\": 0.01, \"offset\": 0},"
      " {\"name\": \"Y\", \"size\": 4, \"type\": \"signed\", \"scale\": 0.01},"
      " {\"name\": \"Z\", \"size\": 8, \"type\": \"float\"},"
      " {\"name\": \"Intensity\", \"size\": 2, \"type\": \"unsigned\"},"
      " {\"name\": \"Classification\", \"size\": 1, \"type\": \"unsigned\"}]";
  const std::string floats =
      "[{\"name\": \"X\", \"size\": 4, \"type\": \"float\"}, {\"name\": \"Y\", \"size\": 4, \"type\": \"float\"},"
      " {\"name\": \"Z\", \"size\": 4, \"type\": \"float\"}, {\"name\": \"GpsTime\", \"size\": 8, \"type\": "
      "\"float\"}]";
  std::string float_records;
  for (int i = 0; i < 3; ++i) {
    for (int a = 0; a < 3; ++a) put<float>(float_records, 1.5f * static_cast<float>(i + a));
    put<double>(float_records, 1e5 + i);
  }
  auto seed = [](const std::string& name, const std::vector<std::string>& parts) {
    const std::string joined = join_ept_parts(parts);
    return Seed{name, std::vector<std::uint8_t>(joined.begin(), joined.end())};
  };
  return {
      seed("binary_subtree.ept", {ept_json("binary", 5, schema), "{\"0-0-0-0\": 3, \"1-0-0-0\": -1}",
                                  "{\"1-0-0-0\": 2, \"2-1-0-1\": 0}", records(3, 0), records(2, 3)}),
      seed("binary_root_only.ept", {ept_json("binary", 3, floats), "{\"0-0-0-0\": 3}", "{}", float_records}),
      seed("zstandard.ept", {ept_json("zstandard", 1, schema), "{\"0-0-0-0\": 1}", "{}", records(1, 0)}),
  };
}

// The shared Entwine tile as the laszip data of a one-node dataset and of a two-node one
// (the same tile twice, the second behind a subtree file).
std::vector<Seed> golden_seeds(const fs::path& golden) {
  std::vector<Seed> seeds;
  const auto folder = shared_data(golden, "laz");
  if (folder.empty()) return seeds;
  const fs::path tile = folder / "pdal_ept_1.2-with-color_0-0-0-0.laz";
  std::ifstream in(tile, std::ios::binary);
  if (!in) throw std::runtime_error("cannot read " + tile.string());
  const std::string laz{std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
  const int n = 1065;  // the tile's points (EXPECTED.txt)
  auto seed = [](const std::string& name, const std::vector<std::string>& parts) {
    const std::string joined = join_ept_parts(parts);
    return Seed{name, std::vector<std::uint8_t>(joined.begin(), joined.end())};
  };
  seeds.push_back(seed("laszip_one_node.ept",
                       {ept_json("laszip", n, "[]"), "{\"0-0-0-0\": " + std::to_string(n) + "}", "{}", laz}));
  seeds.push_back(seed("laszip_subtree.ept",
                       {ept_json("laszip", 2 * n, "[]"), "{\"0-0-0-0\": " + std::to_string(n) + ", \"1-0-0-0\": -1}",
                        "{\"1-0-0-0\": " + std::to_string(n) + "}", laz, laz}));
  return seeds;
}

}  // namespace vola_fuzz
