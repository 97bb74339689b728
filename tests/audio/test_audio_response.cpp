// Impulse responses against physics written here independently: the image-source method
// (Allen and Berkley 1979) for the direct sound and first-order wall reflections of a
// shoebox room of voxel walls; monotony when the listener moves away from a wall;
// symmetric set-ups; threshold() against a slow model written from response.hpp's
// description; determinism over thread counts.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <map>
#include <numbers>
#include <set>
#include <tuple>

#include "audio_test_support.hpp"
#include "vola/audio/response.hpp"
#include "vola/builder.hpp"
#include "vola/error.hpp"

namespace {

using namespace vola;
using namespace vola::audio;
using vola_audio_test::Shoebox;
using vola_audio_test::shoebox_tree;

constexpr double kVoxel = 1.0 / 32.0;  // binary: grid coordinates are exact
constexpr double kC = 343.0;
constexpr double kRate = 48000.0;

Point world(double gx, double gy, double gz) { return {gx * kVoxel, gy * kVoxel, gz * kVoxel}; }

double dist(const Point& a, const Point& b) {
  return std::sqrt((a[0] - b[0]) * (a[0] - b[0]) + (a[1] - b[1]) * (a[1] - b[1]) + (a[2] - b[2]) * (a[2] - b[2]));
}

// Allen & Berkley: the first-order image of source s in the wall plane `axis` = p is s
// mirrored in that plane; the reflection arrives after |image - listener| / c.
double image_source_sample(const Point& s, const Point& l, int axis, double plane) {
  Point image = s;
  image[axis] = 2.0 * plane - s[axis];
  return dist(image, l) / kC * kRate;
}

ResponseOptions options(unsigned threads = 1) {
  ResponseOptions o;
  o.sample_rate = kRate;
  o.speed_of_sound = kC;
  o.reflection_window = 0.05;
  o.threads = threads;
  return o;
}

const Shoebox kRoom{{10, 12, 8}, {200, 150, 100}};

TEST(AudioResponse, DirectAndFirstOrderWallReflectionsMatchImageSources) {
  const Tree tree = shoebox_tree(kRoom, kVoxel);
  const AcousticScene scene(tree, scene_material(0.8));
  const Point s = world(60.3, 50.7, 40.2), l = world(130.6, 90.1, 61.9);
  const Thresholded t = threshold(scene, s, l, options());
  EXPECT_FALSE(t.direct_blocked);
  EXPECT_LE(std::abs(t.direct_sample - dist(s, l) / kC * kRate), 0.5 + 1e-9);
  EXPECT_DOUBLE_EQ(t.direct_amplitude, 1.0 / dist(s, l));

  // The earliest arrival through each wall's inner face.
  const std::vector<Reflection> paths = reflections(scene, s, l, options());
  ASSERT_FALSE(paths.empty());
  for (int axis = 0; axis < 3; ++axis)
    for (int side = 0; side < 2; ++side) {
      const double plane = (side == 0 ? kRoom.lo[axis] + 1.0 : static_cast<double>(kRoom.hi[axis])) * kVoxel;
      std::uint32_t earliest = UINT32_MAX;
      for (const Reflection& r : paths)
        if (r.point[axis] == plane) earliest = std::min(earliest, r.sample);
      ASSERT_NE(earliest, UINT32_MAX) << "no reflection from wall " << axis << "/" << side;
      const double expected = image_source_sample(s, l, axis, plane);
      EXPECT_LE(std::abs(earliest - expected), 1.0) << "wall axis " << axis << " side " << side << ": arrival sample "
                                                    << earliest << ", image source " << expected;
    }
  // No path arrives before the direct sound or the earliest image.
  for (const Reflection& r : paths) EXPECT_GT(r.sample, t.direct_sample);
}

TEST(AudioResponse, SingleWallResponseStartsAtTheImageSourceDelay) {
  Shoebox wall = kRoom;
  for (bool& w : wall.walls) w = false;
  wall.walls[0] = true;  // only the wall at x = 10 (inner face x = 11)
  const Tree tree = shoebox_tree(wall, kVoxel);
  const AcousticScene scene(tree, scene_material(1.0));
  const Point s = world(40.5, 70.2, 50.8), l = world(90.1, 60.4, 55.5);
  const Thresholded t = threshold(scene, s, l, options());
  const std::vector<double> ir = make_filter(scene, t, options());
  std::size_t first = t.direct_sample + 1;
  while (first < ir.size() && ir[first] == 0.0) ++first;
  ASSERT_LT(first, ir.size());
  EXPECT_LE(std::abs(static_cast<double>(first) - image_source_sample(s, l, 0, 11 * kVoxel)), 1.0);
  EXPECT_DOUBLE_EQ(ir[t.direct_sample], 1.0 / dist(s, l));
}

// The reflection of the x = 11 wall in a scene of that wall only: (earliest sample, sum of
// the response over the kEarly samples from it).
constexpr std::size_t kEarly = 48;  // 1 ms at 48 kHz
std::pair<std::size_t, double> wall_reflection(const Point& s, const Point& l) {
  Shoebox wall = kRoom;
  for (bool& w : wall.walls) w = false;
  wall.walls[0] = true;
  static const Tree tree = shoebox_tree(wall, kVoxel);
  const AcousticScene scene(tree, scene_material(0.9));
  const Thresholded t = threshold(scene, s, l, options());
  const std::vector<double> ir = make_filter(scene, t, options());
  std::size_t first = t.direct_sample + 1;
  while (first < ir.size() && ir[first] == 0.0) ++first;
  double sum = 0.0;
  for (std::size_t i = first; i < std::min(ir.size(), first + kEarly); ++i) sum += ir[i];
  return {first, sum};
}

TEST(AudioResponse, ListenerMovedAwayFromAWallHearsItLaterAndWeaker) {
  const Point s = world(40, 70, 50);
  std::pair<std::size_t, double> previous{0, 1e300};
  for (const double x : {30.0, 60.0, 90.0, 150.0}) {
    const auto [sample, level] = wall_reflection(s, world(x, 120, 50));
    EXPECT_GT(sample, previous.first) << "listener at x = " << x;
    EXPECT_LT(level, previous.second) << "listener at x = " << x;
    EXPECT_GT(level, 0.0);
    previous = {sample, level};
  }
}

TEST(AudioResponse, SymmetricSetUpsGiveIdenticalResponses) {
  // Walls at voxels x = 10 and x = 202: x -> 213 - x maps the room onto itself.
  Shoebox box{{10, 12, 8}, {202, 150, 100}};
  const Tree tree = shoebox_tree(box, kVoxel);
  const AcousticScene scene(tree, scene_material(0.7));
  const double mirror = 10.0 + 202.0 + 1.0;  // x -> mirror - x maps the room onto itself
  const Point s = world(60.25, 50.5, 40.75), l = world(130.5, 90.25, 61.5);
  const Point ms = world(mirror - 60.25, 50.5, 40.75), ml = world(mirror - 130.5, 90.25, 61.5);
  const Thresholded a = threshold(scene, s, l, options());
  const Thresholded mirrored = threshold(scene, ms, ml, options());
  const Thresholded swapped = threshold(scene, l, s, options());
  EXPECT_GT(a.bins.size(), 100u);
  EXPECT_EQ(a.bins, mirrored.bins);
  EXPECT_EQ(a.bins, swapped.bins);
  EXPECT_EQ(a.direct_sample, mirrored.direct_sample);
  EXPECT_EQ(make_filter(scene, a, options()), make_filter(scene, mirrored, options()));
  EXPECT_EQ(make_filter(scene, a, options()), make_filter(scene, swapped, options()));
}

TEST(AudioResponse, ThreadCountDoesNotChangeTheResponse) {
  const Tree tree = shoebox_tree(kRoom, kVoxel);
  const AcousticScene scene(tree, scene_material(0.6));
  const Point s = world(60.3, 50.7, 40.2), l = world(130.6, 90.1, 61.9);
  const Thresholded one = threshold(scene, s, l, options(1));
  for (const unsigned threads : {2u, 3u, 8u}) {
    const Thresholded many = threshold(scene, s, l, options(threads));
    EXPECT_EQ(one.bins, many.bins) << threads << " threads";
    EXPECT_EQ(one.reflectors, many.reflectors);
  }
}

// The model of response.hpp, written out on a std::set of voxels.
std::map<std::tuple<std::uint32_t, std::int32_t>, std::uint64_t> slow_bins(const std::set<std::array<std::uint32_t, 3>>& voxels,
                                                                          const Point& s, const Point& l, double voxel,
                                                                          double coefficient, const ResponseOptions& o,
                                                                          std::uint32_t last_sample) {
  std::map<std::tuple<std::uint32_t, std::int32_t>, std::uint64_t> bins;
  const Point sg{s[0] / voxel, s[1] / voxel, s[2] / voxel}, lg{l[0] / voxel, l[1] / voxel, l[2] / voxel};
  for (const auto& v : voxels) {
    Point p{v[0] + 0.5, v[1] + 0.5, v[2] + 0.5};
    bool reflects = false;
    for (int a = 0; a < 3; ++a) {
      auto below = v, above = v;
      below[a] -= 1;  // wraps at 0: never in the set
      above[a] += 1;
      if (!voxels.count(below) && sg[a] < v[a] && lg[a] < v[a]) {
        p[a] = v[a];
        reflects = true;
      } else if (!voxels.count(above) && sg[a] > v[a] + 1.0 && lg[a] > v[a] + 1.0) {
        p[a] = v[a] + 1.0;
        reflects = true;
      }
    }
    if (!reflects) continue;
    const double r1 = dist(sg, p) * voxel, r2 = dist(p, lg) * voxel;
    const double sample = std::nearbyint((r1 + r2) / o.speed_of_sound * o.sample_rate);
    if (sample > last_sample) continue;
    const double amplitude = coefficient * std::sqrt(voxel * voxel / std::numbers::pi) / (r1 * r2);
    const auto level = static_cast<std::int32_t>(std::llround(-20.0 * std::log10(amplitude) / o.bin_width_db));
    ++bins[{static_cast<std::uint32_t>(sample), level}];
  }
  return bins;
}

TEST(AudioResponse, BinsMatchASlowModelOnRandomClutter) {
  std::mt19937_64 rng(7);
  std::set<std::array<std::uint32_t, 3>> set;
  std::vector<Voxel> voxels;
  std::uniform_int_distribution<std::uint32_t> coord(0, 63);
  for (int i = 0; i < 3000; ++i) {
    // Small boxes: faces, edges, holes and voxels on the grid's border.
    const std::uint32_t x = coord(rng), y = coord(rng), z = coord(rng);
    for (std::uint32_t dz = 0; dz < 2; ++dz)
      for (std::uint32_t dy = 0; dy < 3; ++dy)
        if (x < 64 && y + dy < 64 && z + dz < 64 && set.insert({x, y + dy, z + dz}).second) voxels.push_back({x, y + dy, z + dz});
  }
  const double voxel = 0.0625;
  Tree tree = build_from_voxels(voxels, 3);
  tree.set_frame(Frame{Quantization::grid, {0, 0, 0}, voxel});
  const AcousticScene scene(tree, scene_material(0.85));
  ResponseOptions o = options(2);
  o.reflection_window = 0.01;
  // Points in empty voxels.
  Point s{}, l{};
  for (Point* p : {&s, &l})
    do {
      *p = {std::uniform_real_distribution<double>(0, 4)(rng), std::uniform_real_distribution<double>(0, 4)(rng),
            std::uniform_real_distribution<double>(0, 4)(rng)};
    } while (set.count({static_cast<std::uint32_t>((*p)[0] / voxel), static_cast<std::uint32_t>((*p)[1] / voxel),
                        static_cast<std::uint32_t>((*p)[2] / voxel)}));
  const Thresholded t = threshold(scene, s, l, o);
  const auto last = static_cast<std::uint32_t>(std::ceil((dist(s, l) / o.speed_of_sound + o.reflection_window) * o.sample_rate));
  const auto expected = slow_bins(set, s, l, voxel, 0.85, o, last);
  std::map<std::tuple<std::uint32_t, std::int32_t>, std::uint64_t> got;
  for (const Bin& b : t.bins) {
    EXPECT_EQ(b.kernel, 0);
    got[{b.sample, b.level}] += b.count;
  }
  EXPECT_GT(expected.size(), 50u);
  EXPECT_EQ(got, expected);

  // make_filter: each bin adds count * 10^(-level * width / 20) at its sample.
  const std::vector<double> ir = make_filter(scene, t, o);
  std::vector<double> slow(ir.size(), 0.0);
  slow[t.direct_sample] += t.direct_amplitude;
  for (const auto& [key, count] : expected)
    slow[std::get<0>(key)] += static_cast<double>(count) * std::pow(10.0, -std::get<1>(key) * o.bin_width_db / 20.0);
  ASSERT_EQ(ir.size(), slow.size());
  for (std::size_t i = 0; i < ir.size(); ++i) EXPECT_NEAR(ir[i], slow[i], 1e-12 * (1.0 + std::abs(slow[i]))) << i;
}

TEST(AudioResponse, PerBandMaterialsAddNoPreEcho) {
  // The floor (z = 8) reflects per band; nothing may sound before the direct sound or
  // before the floor's image-source arrival.
  std::vector<Voxel> voxels;
  for (std::uint32_t y = 0; y < 64; ++y)
    for (std::uint32_t x = 0; x < 64; ++x) voxels.push_back({x, y, 8});
  Tree tree = build_from_voxels(voxels, 3);
  tree.set_frame(Frame{Quantization::grid, {0, 0, 0}, kVoxel});
  AttributeColumn cls("classification", ValueType::u8, Reduction::majority, voxels.size());
  for (std::size_t i = 0; i < voxels.size(); ++i) cls.set(i, 5);
  tree.attributes().add(cls);
  const MaterialTable table =
      parse_material_table(R"({"attribute": "classification", "materials": {"5": [0.9, 0.8, 0.7, 0.5, 0.4, 0.3]}})", "m.json");
  const AcousticScene scene(tree, table);
  const Point s = world(20, 30, 20), l = world(45, 30, 25);
  const Thresholded t = threshold(scene, s, l, options());
  ASSERT_FALSE(t.bins.empty());
  for (const Bin& b : t.bins) EXPECT_EQ(b.kernel, 1);
  const std::vector<double> ir = make_filter(scene, t, options());
  const double floor_arrival = image_source_sample(s, l, 2, 9 * kVoxel);
  for (std::size_t i = 0; i < ir.size(); ++i) {
    if (i == t.direct_sample) {
      EXPECT_DOUBLE_EQ(ir[i], 1.0 / dist(s, l));
    } else if (static_cast<double>(i) < floor_arrival - 1.0) {
      EXPECT_EQ(ir[i], 0.0) << "sound at sample " << i << " before the floor's arrival " << floor_arrival;
    }
  }
  double after = 0.0;
  for (std::size_t i = t.direct_sample + 1; i < ir.size(); ++i) after += std::abs(ir[i]);
  EXPECT_GT(after, 0.0);
}

TEST(AudioResponse, BlockedLineOfSightSilencesTheDirectSound) {
  Shoebox box = kRoom;
  const Tree room = shoebox_tree(box, kVoxel);
  const AcousticScene scene(room, scene_material(0.5));
  // Source inside, listener outside the closed room: the wall is in between.
  const Thresholded t = threshold(scene, world(60, 50, 40), world(230, 50, 40), options());
  EXPECT_TRUE(t.direct_blocked);
  EXPECT_EQ(t.direct_amplitude, 0.0);
}

TEST(AudioResponse, VisibilityKeepsOnlyReflectorsSeenFromBothEnds) {
  // A room split by a full partition at x = 100: with visibility, no reflector beyond the
  // partition contributes; the partition's own face does.
  std::vector<Voxel> voxels;
  for (std::uint32_t z = 0; z < 64; ++z)
    for (std::uint32_t y = 0; y < 64; ++y) {
      voxels.push_back({20, y, z});
      voxels.push_back({40, y, z});
    }
  Tree tree = build_from_voxels(voxels, 3);
  tree.set_frame(Frame{Quantization::grid, {0, 0, 0}, kVoxel});
  const AcousticScene scene(tree, scene_material(1.0));
  ResponseOptions o = options();
  o.reflection_window = 0.02;
  const Point s = world(5, 30, 30), l = world(10, 20, 35);
  const auto all = reflections(scene, s, l, o);
  o.visibility = true;
  const auto visible = reflections(scene, s, l, o);
  bool far_wall = false;
  for (const auto& r : all) far_wall = far_wall || r.voxel.voxel.x == 40;
  EXPECT_TRUE(far_wall) << "without visibility the far wall's face x = 40 faces both ends";
  EXPECT_FALSE(visible.empty());
  for (const auto& r : visible) EXPECT_EQ(r.voxel.voxel.x, 20u);
}

TEST(AudioResponse, BadInputsGiveClearErrors) {
  const Tree tree = shoebox_tree(kRoom, kVoxel);
  const AcousticScene scene(tree, scene_material(0.5));
  const Point inside_wall = world(10.5, 50, 50);
  try {
    threshold(scene, inside_wall, world(60, 60, 60), options());
    FAIL() << "a source inside a wall was accepted";
  } catch (const InvalidArgument& e) {
    EXPECT_NE(std::string(e.what()).find("the source"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("inside occupied voxel (10, 50, 50)"), std::string::npos) << e.what();
  }
  EXPECT_THROW(threshold(scene, world(60, 60, 60), inside_wall, options()), InvalidArgument);
  EXPECT_THROW(threshold(scene, world(60, 60, 60), world(60, 60, 60), options()), InvalidArgument);
  EXPECT_THROW(threshold(scene, {NAN, 1, 1}, world(60, 60, 60), options()), InvalidArgument);
  // Outside the grid (256 voxels of 1/32 m: 8 m) nothing is known about the surroundings.
  try {
    threshold(scene, world(60, 60, 60), {8.5, 1, 1}, options());
    FAIL() << "a listener outside the grid was accepted";
  } catch (const InvalidArgument& e) {
    EXPECT_NE(std::string(e.what()).find("the listener (8.5, 1, 1) is outside the scene's grid, from (0, 0, 0) to (8, 8, 8)"),
              std::string::npos)
        << e.what();
  }
  EXPECT_THROW(threshold(scene, {-0.01, 1, 1}, world(60, 60, 60), options()), InvalidArgument);
  ResponseOptions bad = options();
  bad.bin_width_db = 0;
  EXPECT_THROW(threshold(scene, world(50, 50, 50), world(60, 60, 60), bad), InvalidArgument);
  bad = options();
  bad.speed_of_sound = -1;
  EXPECT_THROW(threshold(scene, world(50, 50, 50), world(60, 60, 60), bad), InvalidArgument);
  bad = options();
  bad.sample_rate = 10;
  EXPECT_THROW(threshold(scene, world(50, 50, 50), world(60, 60, 60), bad), InvalidArgument);
  EXPECT_THROW(scene_material(1.5), InvalidArgument);
}

}  // namespace
