#include "vola/synth/city.hpp"

#include <cmath>
#include <random>
#include <vector>

namespace vola::synth {

namespace {

struct Building {
  double x0, y0, x1, y1, height;
};
struct TreeShape {
  double x, y, trunk_height, crown_radius;
};

double ground_height(double x, double y) { return 0.02 * x + 0.01 * y + 0.3 * std::sin(x / 17.0) * std::cos(y / 23.0); }

// The city's random draws: every point's parts in the order the generator always drew
// them, so that a seed gives the same city.
struct Sampler {
  std::mt19937_64 rng;
  std::uniform_real_distribution<double> unit{0.0, 1.0};
  std::normal_distribution<double> noise{0.0, 0.03};

  CityPoint ground(double size) {
    CityPoint p{};
    p.x = size * unit(rng);
    p.y = size * unit(rng);
    p.z = ground_height(p.x, p.y) + noise(rng);
    p.classification = 2;
    p.intensity = static_cast<std::uint16_t>(300 + 200 * unit(rng));
    return p;
  }

  // The roof or one of the four walls, by area.
  CityPoint building(const Building& b) {
    CityPoint p{};
    const double w = b.x1 - b.x0, d = b.y1 - b.y0;
    const double roof = w * d, walls = 2.0 * (w + d) * b.height;
    const double base = ground_height(b.x0, b.y0);
    if (unit(rng) * (roof + walls) < roof) {
      p.x = b.x0 + w * unit(rng);
      p.y = b.y0 + d * unit(rng);
      p.z = base + b.height + noise(rng);
    } else {
      const double along = 2.0 * (w + d) * unit(rng);
      if (along < w) { p.x = b.x0 + along; p.y = b.y0; }
      else if (along < w + d) { p.x = b.x1; p.y = b.y0 + (along - w); }
      else if (along < 2 * w + d) { p.x = b.x1 - (along - w - d); p.y = b.y1; }
      else { p.x = b.x0; p.y = b.y1 - (along - 2 * w - d); }
      p.x += noise(rng);
      p.y += noise(rng);
      p.z = base + b.height * unit(rng);
    }
    p.classification = 6;
    p.intensity = static_cast<std::uint16_t>(800 + 400 * unit(rng));
    return p;
  }

  // Mostly crown (a noisy sphere shell, leaves), some trunk.
  CityPoint tree(const TreeShape& t) {
    CityPoint p{};
    const double base = ground_height(t.x, t.y);
    if (unit(rng) < 0.1) {
      const double a = 2.0 * M_PI * unit(rng);
      p.x = t.x + 0.2 * std::cos(a);
      p.y = t.y + 0.2 * std::sin(a);
      p.z = base + t.trunk_height * unit(rng);
    } else {
      const double zc = 2.0 * unit(rng) - 1.0, a = 2.0 * M_PI * unit(rng);
      const double r = t.crown_radius * (0.7 + 0.3 * unit(rng)), s = std::sqrt(1.0 - zc * zc);
      p.x = t.x + r * s * std::cos(a);
      p.y = t.y + r * s * std::sin(a);
      p.z = base + t.trunk_height + t.crown_radius + r * zc;
    }
    p.classification = 5;
    p.intensity = static_cast<std::uint16_t>(100 + 300 * unit(rng));
    return p;
  }
};

// Blocks of 40 m with 12 m streets; one building per block, trees along streets.
void lay_out(double size, Sampler& s, std::vector<Building>& buildings, std::vector<TreeShape>& trees) {
  std::mt19937_64& rng = s.rng;
  auto& unit = s.unit;
  const double block = 40.0, street = 12.0;
  for (double bx = street / 2; bx + block <= size; bx += block + street) {
    for (double by = street / 2; by + block <= size; by += block + street) {
      const double w = 15.0 + 20.0 * unit(rng), d = 15.0 + 20.0 * unit(rng);
      const double x0 = bx + (block - w) * unit(rng), y0 = by + (block - d) * unit(rng);
      buildings.push_back({x0, y0, x0 + w, y0 + d, 6.0 + 40.0 * unit(rng)});
      for (double t = 3.0; t < block; t += 8.0 + 4.0 * unit(rng))
        trees.push_back({bx + t, by - street / 2 + 2.0, 3.0 + 2.0 * unit(rng), 2.0 + 2.0 * unit(rng)});
    }
  }
}

}  // namespace

void generate_city(const CityOptions& o, const std::function<void(const CityPoint&)>& emit) {
  Sampler s{std::mt19937_64(o.seed)};
  std::vector<Building> buildings;
  std::vector<TreeShape> trees;
  lay_out(o.size, s, buildings, trees);
  // Surface areas decide how many points each part gets.
  double ground_area = o.size * o.size, building_area = 0.0, tree_area = 0.0;
  for (const auto& b : buildings)
    building_area += (b.x1 - b.x0) * (b.y1 - b.y0) + 2.0 * ((b.x1 - b.x0) + (b.y1 - b.y0)) * b.height;
  for (const auto& t : trees) tree_area += 4.0 * M_PI * t.crown_radius * t.crown_radius;
  const double total = ground_area + building_area + tree_area;
  std::discrete_distribution<int> part({ground_area / total, building_area / total, tree_area / total});
  std::vector<double> building_weights, tree_weights;
  for (const auto& b : buildings)
    building_weights.push_back((b.x1 - b.x0) * (b.y1 - b.y0) + 2.0 * ((b.x1 - b.x0) + (b.y1 - b.y0)) * b.height);
  for (const auto& t : trees) tree_weights.push_back(t.crown_radius * t.crown_radius);
  std::discrete_distribution<std::size_t> pick_building(building_weights.begin(), building_weights.end());
  std::discrete_distribution<std::size_t> pick_tree(tree_weights.begin(), tree_weights.end());

  for (std::uint64_t i = 0; i < o.points; ++i) {
    CityPoint p;
    switch (part(s.rng)) {
      case 0: p = s.ground(o.size); break;
      case 1: p = s.building(buildings[pick_building(s.rng)]); break;
      default: p = s.tree(trees[pick_tree(s.rng)]); break;
    }
    p.x += o.origin[0];
    p.y += o.origin[1];
    p.z += o.origin[2];
    emit(p);
  }
}

}  // namespace vola::synth
