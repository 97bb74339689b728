// Fuzz entry point of the Entwine Point Tiles reader (src/io/ept.cpp): an EPT dataset is
// a folder, so the input is its files one after another, each ended by kEptPartEnd:
// ept.json, ept-hierarchy/0-0-0-0.json, ept-hierarchy/1-0-0-0.json (a subtree file), then
// the data of nodes 0-0-0-0 and 1-0-0-0 (written as both .bin and .laz, so either
// dataType finds them). They are written to a scratch folder of this process and read
// whole, by level and by region. Only vola::Error may escape; a read cloud has one
// value per point in every column, and a level or region never reads more points.
#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <span>
#include <string>
#include <string_view>

#include "fuzz_ept_parts.hpp"
#include "fuzz_seeds.hpp"
#include "scratch_file.hpp"
#include "vola/error.hpp"
#include "vola/io/ept.hpp"

namespace {

namespace fs = std::filesystem;
using vola_fuzz::check;

// The scratch dataset folder of this process, emptied for each input.
const fs::path& dataset_folder() {
  static const fs::path folder = vola_fuzz::scratch_folder("ept");
  return folder;
}

// The number of points read, checking that every column has one value per point.
std::uint64_t points_read(const vola::io::Input& in) {
  check(in.cloud.xyz.size() % 3 == 0);
  for (const auto& a : in.cloud.attributes) check(a.values.size() == in.cloud.size());
  return in.cloud.size();
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const fs::path root = dataset_folder();
  std::error_code ignored;
  fs::remove_all(root, ignored);
  fs::create_directories(root / "ept-hierarchy");
  fs::create_directories(root / "ept-data");
  const auto parts = vola_fuzz::split_ept_parts(std::string_view(reinterpret_cast<const char*>(data), size));
  const fs::path files[] = {root / "ept.json", root / "ept-hierarchy" / "0-0-0-0.json",
                            root / "ept-hierarchy" / "1-0-0-0.json"};
  for (std::size_t i = 0; i < parts.size(); ++i) {
    if (i < 3) {
      vola_fuzz::write_scratch(files[i], parts[i]);
    } else if (i < 5) {
      const std::string key = i == 3 ? "0-0-0-0" : "1-0-0-0";
      vola_fuzz::write_scratch(root / "ept-data" / (key + ".bin"), parts[i]);
      vola_fuzz::write_scratch(root / "ept-data" / (key + ".laz"), parts[i]);
    }
  }
  const std::string ept = (root / "ept.json").string();
  try {
    const vola::io::EptDataset dataset = vola::io::ept_dataset(ept);
    for (const auto& node : vola::io::ept_nodes(ept)) {
      const auto cube = vola::io::ept_node_bounds(dataset, node);
      (void)cube;
    }
    const std::uint64_t all = points_read(vola::io::read_ept(ept, {}));
    vola::io::InputOptions options;
    options.copc_level = 0;
    check(points_read(vola::io::read_ept(ept, options)) <= all);
    options.copc_level.reset();
    options.region = vola::Box{{0, 0, 0}, {1, 1, 1}};
    check(points_read(vola::io::read_ept(ept, options)) <= all);
    ++vola_fuzz::stats().parsed;
  } catch (const vola::Error&) {
    ++vola_fuzz::stats().refused;
  }
  return 0;
}
