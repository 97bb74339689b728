#include "export_test_support.hpp"

#include <random>
#include <sstream>

namespace vola_export_test {

vola::BuildOptions Grid::options() const {
  vola::BuildOptions o;
  o.quantization = vola::Quantization::grid;
  o.depth = depth;
  o.voxel_size = voxel_size;
  o.origin = origin;
  return o;
}

Grid random_grid(std::uint64_t seed, int depth) {
  static const vola::Point origins[] = {{0, 0, 0}, {315000.25, 234000.5, -12.75}, {-1000.5, 5.0e6, 100}, {0.125, -7, 3}};
  static const double sizes[] = {0.05, 0.25, 1.0, 2.5};
  Grid g;
  g.origin = origins[seed % 4];
  g.voxel_size = sizes[(seed / 4) % 4];
  g.depth = depth;
  return g;
}

vola::PointCloud points_in_voxels(const vola_test::XyzSet& voxels, const Grid& grid, std::uint64_t seed,
                                  bool attributes) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> inside(0.1, 0.9);
  vola::PointCloud cloud;
  using vola::Reduction;
  using vola::ValueType;
  if (attributes) {
    cloud.attributes = {{"red", ValueType::u16, Reduction::mean, {}},
                        {"green", ValueType::u16, Reduction::mean, {}},
                        {"blue", ValueType::u16, Reduction::mean, {}},
                        {"intensity", ValueType::u16, Reduction::mean, {}},
                        {"classification", ValueType::u8, Reduction::majority, {}},
                        {"number_of_returns", ValueType::u8, Reduction::max, {}},
                        {"reflectance", ValueType::f32, Reduction::mean, {}},
                        {"temperature", ValueType::i16, Reduction::min, {}},
                        {"pulse", ValueType::u32, Reduction::last, {}}};
  }
  for (const auto& v : voxels) {
    const int points = 1 + static_cast<int>(rng() % 3);
    for (int p = 0; p < points; ++p) {
      for (int a = 0; a < 3; ++a)
        cloud.xyz.push_back(grid.origin[a] + (static_cast<double>(v[a]) + inside(rng)) * grid.voxel_size);
      if (!attributes) continue;
      auto& at = cloud.attributes;
      at[0].values.push_back(static_cast<double>(rng() % 65536));
      at[1].values.push_back(static_cast<double>(rng() % 65536));
      at[2].values.push_back(static_cast<double>(rng() % 65536));
      at[3].values.push_back(static_cast<double>(rng() % 65536));
      at[4].values.push_back(static_cast<double>(rng() % 20));
      at[5].values.push_back(static_cast<double>(1 + rng() % 5));
      at[6].values.push_back(std::uniform_real_distribution<double>(-1, 1)(rng));
      at[7].values.push_back(static_cast<double>(static_cast<int>(rng() % 2001) - 1000));
      at[8].values.push_back(static_cast<double>(rng() % 4000000000u));
    }
  }
  return cloud;
}

vola::Tree build_on(const vola::PointCloud& cloud, const Grid& grid) {
  vola::BuildReport report;
  vola::Tree tree = vola::build(cloud, grid.options(), &report);
  EXPECT_EQ(report.points_outside, 0u);
  return tree;
}

Sample random_sample(std::uint64_t seed, int depth, bool attributes) {
  std::mt19937_64 rng(seed);
  Sample s;
  s.grid = random_grid(seed, depth);
  // Shapes other than empty, in turn.
  const auto shape = vola_test::kAllShapes[1 + seed % 5];
  const std::size_t count = 1 + rng() % 3000;
  const auto drawn = vola_test::random_voxels(rng, depth, shape, count);
  s.voxels = vola_test::XyzSet(drawn.begin(), drawn.end());
  s.tree = build_on(points_in_voxels(s.voxels, s.grid, seed, attributes), s.grid);
  std::ostringstream d;
  d << "seed " << seed << ", depth " << depth << ", " << vola_test::shape_name(shape) << ", " << s.voxels.size()
    << " voxels, voxel size " << s.grid.voxel_size << ", origin " << s.grid.origin[0] << " " << s.grid.origin[1] << " "
    << s.grid.origin[2];
  s.describe = d.str();
  return s;
}

vola::Tree rebuild(const vola::io::Input& input, const Grid& grid) {
  EXPECT_GT(input.cloud.size(), 0u) << "the reader returned no points";
  return build_on(input.cloud, grid);
}

path data_dir() { return vola_test::golden_dir().parent_path() / "data"; }

}  // namespace vola_export_test
