// The fast paths of thresholding against their obvious forms: the attenuation bin without a
// logarithm against llround(-20 log10(a) / width), and the per-block walk of threshold()
// against binning every reflection that reflections() finds voxel by voxel.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <map>
#include <random>
#include <tuple>
#include <vector>

#include "vola/attributes.hpp"
#include "vola/audio/convolve.hpp"
#include "vola/audio/attenuation_level.hpp"
#include "vola/audio/response.hpp"
#include "vola/builder.hpp"
#include "vola/error.hpp"

namespace {

using namespace vola;
using namespace vola::audio;

// The formula as response.cpp always wrote it (times the inverse width: at an exact tie
// that can round differently from dividing by the width).
std::int64_t formula(double a, double width, std::int64_t offset, std::int64_t count) {
  const auto level = static_cast<std::int64_t>(std::llround(-20.0 * std::log10(a) * (1.0 / width)));
  return std::clamp<std::int64_t>(level + offset, 0, count - 1);
}

TEST(AudioAttenuationLevels, MatchTheFormulaEverywhereAndAtEveryEdge) {
  std::mt19937_64 rng(3);
  for (const double width : {0.1, 0.37, 1.0, 6.0, 0.01}) {
    const auto offset = static_cast<std::int64_t>(std::ceil(60.0 / width));
    const std::int64_t count = offset + static_cast<std::int64_t>(std::ceil(120.0 / width)) + 2;
    const AttenuationLevels levels(width, offset, count);
    auto check = [&](double a) {
      ASSERT_EQ(levels.index(a), formula(a, width, offset, count)) << "amplitude " << a << " width " << width;
      ASSERT_EQ(levels.exact_index(a), formula(a, width, offset, count));
    };
    // Across and beyond the range (clamped at both ends), log-uniform.
    std::uniform_real_distribution<double> db(-200.0, 100.0);
    for (int i = 0; i < 200000; ++i) check(std::pow(10.0, db(rng) / 20.0));
    // On each bin edge and its neighbouring doubles, where a guess is most likely wrong.
    for (std::int64_t level = -offset - 2; level < count - offset + 2; ++level) {
      const double edge = std::pow(10.0, -(static_cast<double>(level) + 0.5) * width / 20.0);
      double a = edge;
      for (int k = 0; k < 4; ++k) a = std::nextafter(a, 0.0);
      for (int k = 0; k < 9; ++k, a = std::nextafter(a, 1e300)) check(a);
      check(edge * (1.0 + 2e-9));
      check(edge * (1.0 - 2e-9));
    }
    check(1e-310);  // subnormal
    check(1e300);
  }
}

TEST(AudioAttenuationLevels, HugeLevelCountsUseTheFormula) {
  const AttenuationLevels levels(1e-6, 60000000, 180000002);
  for (const double a : {1e-3, 0.5, 2.0, 1e-6}) EXPECT_EQ(levels.index(a), formula(a, 1e-6, 60000000, 180000002)) << a;
}

// Random clutter with three materials from a class attribute: one of them per band.
TEST(AudioThresholdFastPath, BinsEqualTheBinnedPerVoxelReflections) {
  std::mt19937_64 rng(11);
  std::vector<Voxel> voxels;
  std::uniform_int_distribution<std::uint32_t> coord(0, 61);
  for (int i = 0; i < 2500; ++i) {
    const std::uint32_t x = coord(rng), y = coord(rng), z = coord(rng);
    for (std::uint32_t d = 0; d < 3; ++d) voxels.push_back({x + d % 2, y + d, z});
  }
  std::sort(voxels.begin(), voxels.end(), [](const Voxel& a, const Voxel& b) { return std::tie(a.x, a.y, a.z) < std::tie(b.x, b.y, b.z); });
  voxels.erase(std::unique(voxels.begin(), voxels.end()), voxels.end());
  Tree tree = build_from_voxels(voxels, 3);
  tree.set_frame(Frame{Quantization::grid, {0, 0, 0}, 0.05});
  AttributeColumn cls("classification", ValueType::u8, Reduction::majority, tree.voxel_count());
  for (std::uint64_t r = 0; r < tree.voxel_count(); ++r) cls.set(static_cast<std::size_t>(r), static_cast<double>(r % 3));
  tree.attributes().add(cls);
  const AcousticScene scene(tree, parse_material_table(R"({"attribute": "classification", "default": 0.3,
      "materials": {"1": 0.7, "2": [0.9, 0.8, 0.7, 0.6, 0.5, 0.4]}})", "m.json"));
  const Point s{0.71, 1.93, 1.22}, l{2.45, 0.38, 2.61};
  ASSERT_FALSE(tree.contains(14, 38, 24));
  ASSERT_FALSE(tree.contains(49, 7, 52));
  for (const bool visibility : {false, true}) {
    ResponseOptions o;
    o.threads = 2;
    o.reflection_window = 0.02;
    o.visibility = visibility;
    const auto offset = static_cast<std::int64_t>(std::ceil(60.0 / o.bin_width_db));
    const std::int64_t count = offset + static_cast<std::int64_t>(std::ceil(-o.floor_db / o.bin_width_db)) + 2;
    std::map<std::tuple<std::uint16_t, std::uint32_t, std::int32_t>, std::uint64_t> expected;
    std::uint64_t reflectors = 0;
    for (const Reflection& r : reflections(scene, s, l, o)) {
      const std::uint16_t kernel = scene.materials().slots()[r.slot].per_band() ? 1 : 0;
      const auto level = static_cast<std::int32_t>(formula(r.amplitude, o.bin_width_db, offset, count) - offset);
      ++expected[{kernel, r.sample, level}];
      ++reflectors;
    }
    const Thresholded t = threshold(scene, s, l, o);
    std::map<std::tuple<std::uint16_t, std::uint32_t, std::int32_t>, std::uint64_t> got;
    for (const Bin& b : t.bins) got[{b.kernel, b.sample, b.level}] += b.count;
    EXPECT_GT(expected.size(), 100u);
    EXPECT_EQ(got, expected) << "visibility " << visibility;
    EXPECT_EQ(t.reflectors, reflectors);
  }

  // make_filter adds each bin in its order into its sample, as the plain loop below: the
  // same sums to the bit. Broadband materials only, so no band filter follows.
  const AcousticScene broadband(tree, scene_material(0.6));
  ResponseOptions o;
  o.reflection_window = 0.03;
  const Thresholded t = threshold(broadband, s, l, o);
  ASSERT_GT(t.bins.size(), 1000u);
  const std::vector<double> ir = make_filter(broadband, t, o);
  std::vector<double> plain(std::size_t{std::max(t.direct_sample, t.bins.back().sample)} + 1, 0.0);
  plain[t.direct_sample] += t.direct_amplitude;
  for (const Bin& b : t.bins) plain[b.sample] += static_cast<double>(b.count) * std::pow(10.0, -b.level * o.bin_width_db / 20.0);
  EXPECT_EQ(ir, plain);
  EXPECT_EQ(make_filter(broadband, t, o), ir) << "the cached level table changed the filter";

  Thresholded shuffled = t;
  std::swap(shuffled.bins.front(), shuffled.bins.back());
  EXPECT_THROW(make_filter(broadband, shuffled, o), InvalidArgument);
  ResponseOptions higher_floor = o;
  higher_floor.floor_db = -20.0;
  EXPECT_THROW(make_filter(broadband, t, higher_floor), InvalidArgument);
  // Too fine a bin width to tabulate: a pow per bin, the same sums.
  ResponseOptions fine = o;
  fine.bin_width_db = 1e-5;
  const Thresholded tf = threshold(broadband, s, l, fine);
  std::vector<double> plain_fine(std::size_t{std::max(tf.direct_sample, tf.bins.back().sample)} + 1, 0.0);
  plain_fine[tf.direct_sample] += tf.direct_amplitude;
  for (const Bin& b : tf.bins) plain_fine[b.sample] += static_cast<double>(b.count) * std::pow(10.0, -b.level * fine.bin_width_db / 20.0);
  EXPECT_EQ(make_filter(broadband, tf, fine), plain_fine);
}

}  // namespace

namespace {

// Worker threads must be done with the output before apply() returns it (a race once:
// the result was moved away while a worker still added its last block).
TEST(AudioConvolveThreads, EveryCallEqualsTheOneThreadResult) {
  std::mt19937_64 rng(5);
  std::normal_distribution<double> noise(0.0, 1.0);
  std::vector<double> x(20000), h(700);
  for (double& v : x) v = noise(rng);
  for (double& v : h) v = noise(rng);
  const vola::audio::Convolver c(h);
  const std::vector<double> one = c.apply(x, 1);
  for (int i = 0; i < 40; ++i) ASSERT_EQ(c.apply(x, 2), one) << "call " << i;
}

}  // namespace
