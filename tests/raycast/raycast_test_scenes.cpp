#include "raycast_test_scenes.hpp"

#include <cmath>

#include "io_test_data.hpp"
#include "vola/builder.hpp"
#include "vola/io/input.hpp"

namespace raycast_test {

using vola::raycast::Ray;

vola::Tree random_tree(std::uint64_t seed, int depth) {
  std::mt19937_64 rng(seed);
  constexpr vola_test::Shape kShapes[] = {vola_test::Shape::uniform, vola_test::Shape::clustered,
                                          vola_test::Shape::slab};
  const vola_test::Shape shape = kShapes[seed % 3];
  const std::size_t count = 1 + rng() % (std::size_t{1} << (2 * depth + 2));
  std::vector<vola::Voxel> voxels;
  for (const auto& v : vola_test::random_voxels(rng, depth, shape, count)) voxels.push_back(vola_test::to_voxel(v));
  return vola::build_from_voxels(voxels, depth);
}

std::optional<vola::Tree> autzen_tree(const std::string& file_name, int depth) {
  const auto path = vola_io_test::data_dir() / "las" / file_name;
  if (!vola_test::fs::exists(path)) return std::nullopt;
  const vola::io::Input input = vola::io::read_input(path.string(), "auto", {});
  vola::BuildOptions options;
  options.quantization = vola::Quantization::grid;
  options.depth = depth;
  return vola::build(input.cloud, options);
}

std::vector<Ray> mixed_rays(const vola::Tree& tree, std::size_t count, std::mt19937_64& rng) {
  const double side = tree.side();
  std::uniform_real_distribution<double> around(-0.5 * side, 1.5 * side);
  std::uniform_real_distribution<double> unit(-1.0, 1.0);
  std::uniform_real_distribution<double> fraction(0.0, 1.0);
  std::uniform_int_distribution<int> small(-2, 2);
  std::uniform_int_distribution<std::int64_t> plane(-2, static_cast<std::int64_t>(side) + 2);
  std::vector<vola::Voxel> occupied;
  tree.for_each_voxel([&](const vola::Voxel& v) {
    if (occupied.size() < 4096) occupied.push_back(v);
  });

  std::vector<Ray> rays;
  rays.reserve(count);
  while (rays.size() < count) {
    Ray r;
    switch (rays.size() % 4) {
      case 0:  // anywhere, any direction
        r.origin = {around(rng), around(rng), around(rng)};
        r.direction = {unit(rng), unit(rng), unit(rng)};
        break;
      case 1: {  // along an axis, from a plane, edge, corner or anywhere
        const int axis = static_cast<int>(rng() % 3);
        for (int a = 0; a < 3; ++a) {
          const auto p = static_cast<double>(plane(rng));
          r.origin[a] = rng() % 2 ? p : p + fraction(rng);
          r.direction[a] = 0.0;
        }
        r.direction[axis] = rng() % 2 ? 1.0 : -1.0;
        break;
      }
      case 2: {  // integer origin and integer direction: exact edge and corner crossings
        for (int a = 0; a < 3; ++a) {
          r.origin[a] = static_cast<double>(plane(rng)) + (rng() % 4 == 0 ? 0.5 : 0.0);
          r.direction[a] = small(rng);
        }
        if (r.direction == vola::Point{0, 0, 0}) r.direction = {1, 1, 1};
        break;
      }
      default: {  // from inside (or on the boundary of) an occupied voxel
        if (occupied.empty()) continue;
        const vola::Voxel v = occupied[rng() % occupied.size()];
        const bool on_corner = rng() % 3 == 0;
        r.origin = {v.x + (on_corner ? 0.0 : fraction(rng)), v.y + (on_corner ? 0.0 : fraction(rng)),
                    v.z + (on_corner ? 0.0 : fraction(rng))};
        r.direction = {unit(rng), unit(rng), unit(rng)};
        break;
      }
    }
    if (rng() % 5 == 0) r.t_max = fraction(rng) * side;  // a ray that stops early
    rays.push_back(r);
  }
  return rays;
}

}  // namespace raycast_test
