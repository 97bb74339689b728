#include "map_test_support.hpp"

#include <algorithm>
#include <cmath>

namespace vola_map_test {

RandomMap random_map(std::uint64_t seed, double voxel_size, std::int64_t span, std::size_t count) {
  std::mt19937_64 rng(seed);
  RandomMap map;
  map.voxel_size = voxel_size;
  std::uniform_int_distribution<std::int64_t> centre(-span, span), near(-6, 6);
  std::uniform_real_distribution<float> hit(0.0f, kClampMax), miss(kClampMin, -0.01f);
  Cell cluster{0, 0, 0};
  for (std::size_t n = 0; n < count; ++n) {
    if (n % 40 == 0) cluster = {centre(rng), centre(rng), centre(rng)};
    const Cell c{cluster[0] + near(rng), cluster[1] + near(rng), cluster[2] + near(rng)};
    if (map.occupied.count(c) || map.free.count(c)) continue;
    const bool occupied = (rng() & 3) != 0;
    const float value = (rng() & 1) ? (occupied ? kClampMax : kClampMin) : (occupied ? hit(rng) : miss(rng));
    (occupied ? map.occupied : map.free)[c] = value;
  }
  return map;
}

vola::Tree tree_of(const std::map<Cell, float>& cells, double voxel_size, bool log_odds) {
  vola::PointCloud cloud;
  vola::PointAttribute column{"log_odds", vola::ValueType::f32, vola::Reduction::last, {}};
  Cell lowest{0, 0, 0};
  if (!cells.empty()) lowest = cells.begin()->first;
  for (const auto& [c, value] : cells) {
    for (int a = 0; a < 3; ++a) lowest[a] = std::min(lowest[a], c[a]);
    for (int a = 0; a < 3; ++a) cloud.xyz.push_back((static_cast<double>(c[a]) + 0.5) * voxel_size);
    column.values.push_back(value);
  }
  if (log_odds) cloud.attributes.push_back(std::move(column));
  vola::BuildOptions options;
  options.quantization = vola::Quantization::grid;
  options.voxel_size = voxel_size;
  options.origin = vola::Point{static_cast<double>(lowest[0]) * voxel_size, static_cast<double>(lowest[1]) * voxel_size,
                               static_cast<double>(lowest[2]) * voxel_size};
  return vola::build(cloud, options);
}

std::map<Cell, float> cells_of(const vola::Tree& tree) {
  const vola::Frame frame = tree.frame();
  Cell base;
  for (int a = 0; a < 3; ++a) base[a] = std::llround(frame.origin[a] / frame.voxel_size);
  const vola::AttributeColumn* column = tree.attributes().find("log_odds");
  std::map<Cell, float> cells;
  std::size_t rank = 0;
  tree.for_each_voxel([&](const vola::Voxel& v) {
    const float value = column ? static_cast<float>(column->get(rank)) : 0.0f;
    cells[{base[0] + v.x, base[1] + v.y, base[2] + v.z}] = value;
    ++rank;
  });
  return cells;
}

}  // namespace vola_map_test
