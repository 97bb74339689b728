#include "fuzz_seeds.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <iterator>
#include <stdexcept>

#include "vola/vola.hpp"

namespace vola_fuzz {

namespace {

vola::PointCloud cube_cloud(int points, double scale) {
  vola::PointCloud cloud;
  std::uint64_t state = 12345;
  auto next = [&] {
    state = state * 6364136223846793005ull + 1442695040888963407ull;
    return static_cast<double>(state >> 11) / static_cast<double>(1ull << 53);
  };
  for (int i = 0; i < points; ++i)
    for (int a = 0; a < 3; ++a) cloud.xyz.push_back(next() * scale);
  for (int i = 0; i < points; ++i) cloud.payload.push_back(static_cast<std::uint64_t>(i) * 0x0101010101ull);
  return cloud;
}

std::vector<std::uint8_t> read_all(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw std::runtime_error("cannot open " + path.string());
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

std::vector<std::uint8_t> gunzip(const std::filesystem::path& path) {
  const std::string command = "gzip -dc -- '" + path.string() + "'";
  std::FILE* pipe = ::popen(command.c_str(), "r");
  if (!pipe) throw std::runtime_error("cannot run " + command);
  std::vector<std::uint8_t> out;
  char buffer[1 << 16];
  std::size_t got;
  while ((got = std::fread(buffer, 1, sizeof buffer, pipe)) > 0) out.insert(out.end(), buffer, buffer + got);
  if (::pclose(pipe) != 0) throw std::runtime_error(command + " failed");
  return out;
}

}  // namespace

std::vector<Seed> synthetic_seeds() {
  std::vector<Seed> seeds;
  const vola::PointCloud cloud = cube_cloud(300, 10.0);

  // Grid frame (extension with a frame record), sparse and dense.
  const vola::BuildOptions grid{.quantization = vola::Quantization::grid, .depth = 3, .voxel_size = 0.25,
                                .origin = vola::Point{0, 0, 0}};
  const vola::Tree grid_tree = vola::build(cloud, grid);
  seeds.push_back({"grid_sparse", vola::serialize(grid_tree)});
  seeds.push_back({"grid_dense", vola::serialize(grid_tree, {.layout = vola::Layout::dense})});

  // Attribute columns of every type, and a CRS WKT record.
  vola::PointCloud with_attributes = cube_cloud(100, 5.0);
  for (int t = 0; t < 10; ++t) {
    vola::PointAttribute a{std::string("a") + std::to_string(t), static_cast<vola::ValueType>(t),
                           static_cast<vola::Reduction>(t % 5), {}};
    for (std::size_t i = 0; i < with_attributes.size(); ++i) a.values.push_back(static_cast<double>(i % 7));
    with_attributes.attributes.push_back(std::move(a));
  }
  vola::Tree attribute_tree = vola::build(with_attributes, {.depth = 2});
  attribute_tree.georef().crs_wkt = "LOCAL_CS[\"fuzz\"]";
  seeds.push_back({"attributes", vola::serialize(attribute_tree)});

  // Payload words, sparse and dense.
  const vola::Tree payload_tree = vola::build(cloud, {.depth = 2, .payload = true});
  seeds.push_back({"payload_sparse", vola::serialize(payload_tree)});
  seeds.push_back({"payload_dense", vola::serialize(payload_tree, {.layout = vola::Layout::dense})});

  // Compressed levels (version 2) with compressed attribute columns.
  if (vola::compression_available()) {
    seeds.push_back({"compressed", vola::serialize(vola::build(cloud, {.depth = 4}), {.compress = true})});
    seeds.push_back({"compressed_attributes", vola::serialize(attribute_tree, {.compress = true})});
    seeds.push_back({"compressed_payload", vola::serialize(payload_tree, {.compress = true})});
    // The occupancy coded by mixed models (levels flags 4, --compress-max).
    seeds.push_back({"compressed_mixed", vola::serialize(vola::build(cloud, {.depth = 4}),
                                                         {.compress = true, .mix_occupancy_models = true})});
    seeds.push_back({"compressed_mixed_payload",
                     vola::serialize(payload_tree, {.compress = true, .mix_occupancy_models = true})});
    // Heights in centimetres (quantized floats, attribute encoding 3), a smooth integer
    // column (delta planes, encoding 2) and one that follows it (delta planes against it,
    // encoding 4).
    vola::PointCloud surveyed = cube_cloud(2000, 20.0);
    vola::PointAttribute height{"height", vola::ValueType::f32, vola::Reduction::last, {}};
    vola::PointAttribute smooth{"smooth", vola::ValueType::u16, vola::Reduction::last, {}};
    vola::PointAttribute follower{"follower", vola::ValueType::u16, vola::Reduction::last, {}};
    for (std::size_t i = 0; i < surveyed.size(); ++i) {
      surveyed.xyz[3 * i + 2] = std::round(surveyed.xyz[3 * i + 2] * 100.0) / 100.0;
      height.values.push_back(surveyed.xyz[3 * i + 2]);
      smooth.values.push_back(static_cast<double>(1000 + i % 13));
      follower.values.push_back(smooth.values.back() + static_cast<double>(i % 3));
    }
    surveyed.attributes = {height, smooth, follower};
    seeds.push_back({"compressed_predicted", vola::serialize(vola::build(surveyed, {.quantization = vola::Quantization::grid,
                                                                               .depth = 4, .voxel_size = 0.5,
                                                                               .origin = vola::Point{-1, -1, -1}}),
                                                             {.compress = true})});
  }

  // Depth extremes and full words.
  seeds.push_back({"empty_depth1", vola::serialize(vola::Tree())});
  const std::vector<vola::Voxel> corner = {{0, 0, 0}, {(1u << 20) - 1, (1u << 20) - 1, (1u << 20) - 1}};
  seeds.push_back({"depth10", vola::serialize(vola::build_from_voxels(corner, 10))});
  std::vector<vola::Voxel> block;
  for (std::uint32_t z = 0; z < 8; ++z)
    for (std::uint32_t y = 0; y < 8; ++y)
      for (std::uint32_t x = 0; x < 8; ++x) block.push_back({x, y, z});
  seeds.push_back({"full_block", vola::serialize(vola::build_from_voxels(block, 3))});
  return seeds;
}

std::vector<Seed> golden_seeds(const std::filesystem::path& golden) {
  std::vector<Seed> seeds;
  for (const auto& entry : std::filesystem::recursive_directory_iterator(golden)) {
    if (!entry.is_regular_file()) continue;
    const std::string name = entry.path().filename().string();
    auto ends_with = [&](const std::string& suffix) {
      return name.size() >= suffix.size() && name.compare(name.size() - suffix.size(), suffix.size(), suffix) == 0;
    };
    const std::string label = entry.path().parent_path().filename().string() + "_" + name;
    if (ends_with(".vol") || ends_with(".dvol")) seeds.push_back({label, read_all(entry.path())});
    else if (ends_with(".dvol.gz") || ends_with(".vol.gz")) seeds.push_back({label, gunzip(entry.path())});
  }
  std::sort(seeds.begin(), seeds.end(), [](const Seed& a, const Seed& b) { return a.name < b.name; });
  return seeds;
}

}  // namespace vola_fuzz
