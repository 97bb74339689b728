// Building from points: toolkit quantization against the formula of FORMAT.md
// section 6 written out slowly, grid quantization, argument checks, radix sort.
#include <algorithm>
#include <cmath>
#include <limits>
#include <numeric>
#include <iterator>
#include <random>

#include <gtest/gtest.h>

#include "test_support.hpp"
#include "vola/builder.hpp"

namespace vola_test {
namespace {

// round half to even, without relying on the rounding mode.
double round_half_even(double x) {
  const double f = std::floor(x);
  const double diff = x - f;
  if (diff < 0.5) return f;
  if (diff > 0.5) return f + 1;
  return std::fmod(f, 2.0) == 0.0 ? f : f + 1;
}

// FORMAT.md 6, step by step in float64.
Xyz slow_toolkit_voxel(const vola::Point& p, const vola::Box& bbox, int depth) {
  double lmax = 0;
  for (int a = 0; a < 3; ++a) lmax = std::max(lmax, bbox.max[a] - bbox.min[a]);
  const double steps = static_cast<double>(vola::side_of(depth)) - 1.0;
  Xyz v{};
  for (int a = 0; a < 3; ++a) {
    if (lmax == 0.0) continue;  // the reference's 0/0 lands in voxel 0 (README: single_point)
    const double m = bbox.min[a];
    const double den = (m + lmax) - m;
    const double n = std::clamp((p[a] - m) / den, 0.0, 1.0);
    v[a] = static_cast<std::uint32_t>(round_half_even(steps * n));
  }
  return v;
}

vola::PointCloud cloud_of(const std::vector<vola::Point>& points) {
  vola::PointCloud cloud;
  for (const auto& p : points) cloud.xyz.insert(cloud.xyz.end(), p.begin(), p.end());
  return cloud;
}

TEST(BuildToolkit, VoxelsFollowTheReferenceFormulaOnRandomClouds) {
  for (std::uint64_t seed = 0; seed < 40; ++seed) {
    std::mt19937_64 rng(seed);
    const int depth = 1 + static_cast<int>(seed % 10);
    SCOPED_TRACE("seed " + std::to_string(seed) + " depth " + std::to_string(depth));
    // Boxes with offsets like projected coordinates and very uneven sides.
    std::uniform_real_distribution<double> offset(-1e6, 1e6), extent(1e-3, 1e3);
    vola::Point lo, hi;
    for (int a = 0; a < 3; ++a) {
      lo[a] = seed % 3 == 0 ? 0.0 : offset(rng);
      hi[a] = lo[a] + extent(rng);
    }
    std::vector<vola::Point> points = {lo, hi};
    for (int i = 0; i < 2000; ++i) {
      vola::Point p;
      for (int a = 0; a < 3; ++a) p[a] = std::uniform_real_distribution<double>(lo[a], hi[a])(rng);
      points.push_back(p);
    }
    const vola::PointCloud cloud = cloud_of(points);
    vola::BuildReport report;
    const vola::Tree tree = vola::build(cloud, {.quantization = vola::Quantization::toolkit, .depth = depth}, &report);
    const vola::Box bbox = cloud.bounds();
    XyzSet expected;
    for (const auto& p : points) expected.insert(slow_toolkit_voxel(p, bbox, depth));
    EXPECT_EQ(voxel_set(tree), expected);
    EXPECT_EQ(report.points_in, points.size());
    EXPECT_EQ(report.points_outside, 0u);
    EXPECT_EQ(report.voxels, expected.size());
    EXPECT_EQ(tree.georef().bbox, bbox);
    EXPECT_EQ(tree.depth(), depth);
    // The longest axis spans 0..S-1 exactly.
    std::uint32_t top = 0;
    for (const Xyz& v : expected) top = std::max({top, v[0], v[1], v[2]});
    EXPECT_EQ(top, vola::side_of(depth) - 1);
  }
}

TEST(BuildToolkit, HalfwayPointsRoundToEven) {
  // bbox [0, S-1]^3 maps coordinate c to voxel round_half_even(c).
  const int depth = 2;
  std::vector<vola::Point> points = {{0, 0, 0}, {15, 15, 15}};
  for (double c = 0.5; c < 15; c += 1.0) points.push_back({c, 0, 0});
  const vola::Tree tree = vola::build(cloud_of(points), {.depth = depth});
  XyzSet expected = {{0, 0, 0}, {15, 15, 15}};
  for (double c = 0.5; c < 15; c += 1.0)
    expected.insert({static_cast<std::uint32_t>(round_half_even(c)), 0, 0});
  EXPECT_EQ(voxel_set(tree), expected);
  EXPECT_FALSE(tree.contains(1, 0, 0));  // 0.5 -> 0 and 1.5 -> 2: nothing rounds to 1
}

TEST(BuildToolkit, PointsOutsideAFixedBboxAreClamped) {
  const vola::Box box{{0, 0, 0}, {15, 15, 15}};
  const std::vector<vola::Point> points = {{-3, 7, 20}, {100, -100, 3}, {7, 7, 7}};
  vola::BuildReport report;
  const vola::Tree tree = vola::build(cloud_of(points), {.depth = 2, .bbox = box}, &report);
  EXPECT_EQ(voxel_set(tree), (XyzSet{{0, 7, 15}, {15, 0, 3}, {7, 7, 7}}));
  EXPECT_EQ(report.points_outside, 0u);
  EXPECT_EQ(tree.georef().bbox, box);
}

TEST(BuildToolkit, ZeroExtentPutsEveryPointInVoxelZero) {
  const vola::Tree tree = vola::build(cloud_of({{1, 2, 3}, {1, 2, 3}}), {.depth = 4});
  EXPECT_EQ(voxel_set(tree), (XyzSet{{0, 0, 0}}));
  EXPECT_EQ(tree.quantizer().center({0, 0, 0}), (vola::Point{1, 2, 3}));  // the one point
}

// A tree built from voxels has no bbox to quantize by: its voxels are one unit apart, the
// same in frame() (info, components) and quantizer() (coords, census, world queries),
// which put every voxel at one point before.
TEST(BuildFromVoxels, VoxelsLieOneUnitApartEverywhere) {
  const std::vector<vola::Voxel> voxels{{0, 0, 0}, {5, 5, 5}, {15, 2, 9}};
  const vola::Tree tree = vola::build_from_voxels(voxels, 2);
  const vola::Frame frame = tree.frame();
  for (const vola::Voxel& v : voxels) {
    const vola::Point c = tree.quantizer().center(v);
    EXPECT_EQ(c, (vola::Point{frame.origin[0] + (v.x + 0.5) * frame.voxel_size,
                              frame.origin[1] + (v.y + 0.5) * frame.voxel_size,
                              frame.origin[2] + (v.z + 0.5) * frame.voxel_size}));
    vola::Voxel back{};
    ASSERT_TRUE(tree.quantizer().to_voxel(c, back));
    EXPECT_EQ(back, v);
  }
}

TEST(BuildToolkit, AxisWhoseScaleRoundsToZeroLandsInVoxelZero) {
  // z = 1e20 with Lmax = 1: (1e20 + 1) - 1e20 == 0, so the reference computes 0/0 = NaN
  // on z and lands in voxel 0 (README: single_point). Casting that NaN to an integer
  // was undefined behaviour (UBSan: "-nan is outside the range of representable
  // values"); without a sanitizer it happened to give 0 on x86-64.
  const vola::Tree tree = vola::build(cloud_of({{0, 0, 1e20}, {1, 1, 1e20}, {0.5, 1, 1e20}}), {.depth = 2});
  EXPECT_EQ(voxel_set(tree), (XyzSet{{0, 0, 0}, {15, 15, 0}, {8, 15, 0}}));
}

TEST(BuildToolkit, NonFinitePointsAreSkippedAndCounted) {
  const double inf = std::numeric_limits<double>::infinity();
  const double nan = std::numeric_limits<double>::quiet_NaN();
  const vola::PointCloud cloud = cloud_of({{0, 0, 0}, {nan, 1, 1}, {3, 3, 3}, {1, inf, 1}});
  EXPECT_EQ(cloud.bounds(), (vola::Box{{0, 0, 0}, {3, 3, 3}}));
  vola::BuildReport report;
  const vola::Tree tree = vola::build(cloud, {.depth = 1}, &report);
  EXPECT_EQ(report.points_in, 4u);
  EXPECT_EQ(report.points_outside, 2u);
  EXPECT_EQ(voxel_set(tree), (XyzSet{{0, 0, 0}, {3, 3, 3}}));
}

TEST(BuildToolkit, EmptyCloudGivesAnEmptyTree) {
  const vola::Tree tree = vola::build(vola::PointCloud{}, {.depth = 3});
  EXPECT_TRUE(tree.empty());
  EXPECT_EQ(tree.depth(), 3);
  EXPECT_EQ(tree.words().size(), 1u);
}

TEST(BuildToolkit, VoxelCentresQuantizeBackToTheirVoxel) {
  const vola::Box box{{-10, 5, 100}, {30, 15, 120}};
  for (int depth = 1; depth <= 10; ++depth) {
    const vola::Quantizer q = vola::Quantizer::toolkit(box, depth);
    std::mt19937_64 rng(depth);
    for (int i = 0; i < 1000; ++i) {
      // Shorter axes reach only round((S-1) * extent / Lmax).
      Xyz v = random_xyz(rng, depth);
      v[1] = static_cast<std::uint32_t>(v[1] / 4);
      v[2] = static_cast<std::uint32_t>(v[2] / 2);
      vola::Voxel out;
      ASSERT_TRUE(q.to_voxel(q.center(to_voxel(v)), out));
      ASSERT_EQ(to_xyz(out), v) << "depth " << depth;
    }
  }
}

TEST(BuildGrid, VoxelsAreFloorOfOffsetOverSize) {
  std::mt19937_64 rng(7);
  const vola::Point origin{-100.0, 50.0, 0.0};
  const double size = 0.25;
  const int depth = 5;  // 1024 voxels of 0.25 per axis: 256 units from the origin
  std::vector<vola::Point> points;
  for (int i = 0; i < 5000; ++i) {
    vola::Point p;
    for (int a = 0; a < 3; ++a) p[a] = origin[a] + std::uniform_real_distribution<double>(0.0, 255.99)(rng);
    points.push_back(p);
  }
  vola::BuildReport report;
  const vola::Tree tree =
      vola::build(cloud_of(points),
                  {.quantization = vola::Quantization::grid, .depth = depth, .voxel_size = size, .origin = origin},
                  &report);
  XyzSet expected;
  for (const auto& p : points) {
    Xyz v;
    for (int a = 0; a < 3; ++a) v[a] = static_cast<std::uint32_t>(std::floor((p[a] - origin[a]) / size));
    expected.insert(v);
  }
  EXPECT_EQ(voxel_set(tree), expected);
  EXPECT_EQ(report.points_outside, 0u);
  ASSERT_TRUE(tree.stored_frame().has_value());
  EXPECT_EQ(*tree.stored_frame(), (vola::Frame{vola::Quantization::grid, origin, size}));
}

// A grid the options fix must hold the points: what lies outside it would be dropped
// without a word (a user's --voxel-size with a --depth too small dropped 27% of a survey).
TEST(BuildGrid, AGridThatDoesNotHoldThePointsIsRefused) {
  const std::vector<vola::Point> points = {{0.5, 0.5, 0.5}, {300.0, 10.0, 10.0}};
  const auto message_of = [&](const vola::BuildOptions& options) {
    try {
      vola::build(cloud_of(points), options);
    } catch (const vola::OptionError& e) {
      return std::string(e.option()) + ": " + e.what();
    }
    return std::string("no error");
  };
  // 256 voxels of 1 from the origin; the points reach 300 along x; depth 5 holds them.
  const std::string deep = message_of({.quantization = vola::Quantization::grid, .depth = 4, .voxel_size = 1.0});
  EXPECT_NE(deep.find("depth"), std::string::npos) << deep;
  EXPECT_NE(deep.find("reaches 300 along x"), std::string::npos) << deep;
  EXPECT_NE(deep.find("depth 5 holds it"), std::string::npos) << deep;
  const std::string high = message_of(
      {.quantization = vola::Quantization::grid, .voxel_size = 1.0, .origin = vola::Point{0.0, 1.0, 0.0}});
  EXPECT_NE(high.find("origin"), std::string::npos) << high;
  EXPECT_NE(high.find("y = 1 lies above the minimum 0.5"), std::string::npos) << high;
  // Without a depth the smallest grid that holds them is chosen, and a bbox the grid
  // holds crops as before.
  EXPECT_EQ(vola::build(cloud_of(points), {.quantization = vola::Quantization::grid, .voxel_size = 1.0}).depth(), 5);
  vola::BuildReport report;
  const vola::Tree cropped =
      vola::build(cloud_of(points),
                  {.quantization = vola::Quantization::grid, .depth = 2, .voxel_size = 1.0,
                   .origin = vola::Point{0.0, 0.0, 0.0}, .bbox = vola::Box{{0, 0, 0}, {15, 15, 15}}},
                  &report);
  EXPECT_EQ(cropped.voxel_count(), 1u);
  EXPECT_EQ(report.points_outside, 1u);
}

// The snapped default origin may not round above the points' minimum (the minimum's
// points were dropped: 470692.44 / 0.01 floors to 47069244, times 0.01 is 470692.44000000006).
TEST(BuildGrid, DefaultOriginNeverRoundsAboveTheMinimum) {
  const std::vector<vola::Point> points = {{470692.44, 10.0, 10.0}, {470692.5, 10.0, 10.0}};
  vola::BuildReport report;
  const vola::Tree tree = vola::build(cloud_of(points), {.quantization = vola::Quantization::grid, .voxel_size = 0.01},
                                      &report);
  EXPECT_EQ(report.points_outside, 0u);
  EXPECT_EQ(tree.voxel_count(), 2u);
  EXPECT_LE(tree.stored_frame()->origin[0], 470692.44);
}

TEST(BuildGrid, DefaultOriginSnapsToTheVoxelSizeAndDepthCoversTheCloud) {
  const std::vector<vola::Point> points = {{10.3, -4.7, 2.2}, {17.9, 3.3, 2.9}};
  const vola::Tree tree =
      vola::build(cloud_of(points), {.quantization = vola::Quantization::grid, .voxel_size = 0.5});
  ASSERT_TRUE(tree.stored_frame().has_value());
  const vola::Frame f = *tree.stored_frame();
  EXPECT_EQ(f.origin, (vola::Point{10.0, -5.0, 2.0}));
  // Largest extent from the origin: 3.3 - (-5) = 8.3 on y, 17 voxels of 0.5 -> depth 3 (64).
  EXPECT_EQ(tree.depth(), vola::depth_for_extent(8.3, 0.5));
  EXPECT_EQ(tree.depth(), 3);
  EXPECT_EQ(voxel_set(tree), (XyzSet{{0, 0, 0}, {15, 16, 1}}));
}

TEST(BuildGrid, DepthForExtent) {
  EXPECT_EQ(vola::depth_for_extent(3.9, 1.0), 1);
  EXPECT_EQ(vola::depth_for_extent(4.0, 1.0), 2);
  EXPECT_EQ(vola::depth_for_extent(0.0, 1.0), 1);
  EXPECT_EQ(vola::depth_for_extent(1048575.0, 1.0), 10);
  EXPECT_THROW(vola::depth_for_extent(1048576.0, 1.0), vola::InvalidArgument);
  EXPECT_THROW(vola::depth_for_extent(1.0, 0.0), vola::InvalidArgument);
}

TEST(BuildArguments, BadDepthsAndVoxelsAreRefused) {
  EXPECT_THROW(vola::build(cloud_of({{0, 0, 0}}), {.depth = 0}), vola::InvalidArgument);
  EXPECT_THROW(vola::build(cloud_of({{0, 0, 0}}), {.depth = 11}), vola::InvalidArgument);
  const std::vector<vola::Voxel> outside = {{16, 0, 0}};
  EXPECT_THROW(vola::build_from_voxels(outside, 2), vola::InvalidArgument);
  const std::vector<vola::Voxel> inside = {{15, 15, 15}};
  EXPECT_NO_THROW(vola::build_from_voxels(inside, 2));
  EXPECT_THROW(vola::build_from_voxels(inside, 0), vola::InvalidArgument);
  EXPECT_THROW(vola::build_from_keys({vola::Key{1} << 12}, 2), vola::InvalidArgument);
  EXPECT_THROW(vola::build_from_keys({}, 11), vola::InvalidArgument);
  const std::vector<vola::Key> unsorted = {5, 3}, repeated = {3, 3}, large = {1, vola::Key{1} << 12};
  EXPECT_THROW(vola::build_from_sorted_keys(unsorted, 2), vola::InvalidArgument);
  EXPECT_THROW(vola::build_from_sorted_keys(repeated, 2), vola::InvalidArgument);
  EXPECT_THROW(vola::build_from_sorted_keys(large, 2), vola::InvalidArgument);
}

TEST(BuildArguments, MismatchedCloudSizesAreRefused) {
  vola::PointCloud cloud = cloud_of({{0, 0, 0}, {1, 1, 1}});
  cloud.payload = {1};
  EXPECT_THROW(vola::build(cloud, {.depth = 1, .payload = true}), vola::InvalidArgument);
  cloud.payload.clear();
  cloud.attributes.push_back({"a", vola::ValueType::f32, vola::Reduction::mean, {1.0}});
  EXPECT_THROW(vola::build(cloud, {.depth = 1}), vola::InvalidArgument);
  cloud.attributes.clear();
  cloud.xyz.push_back(5.0);
  EXPECT_THROW(vola::build(cloud, {.depth = 1}), vola::InvalidArgument);
  EXPECT_THROW(vola::build(cloud_of({{0, 0, 0}}), {.quantization = vola::Quantization::grid}),
               vola::InvalidArgument);  // neither depth nor voxel size
}

TEST(RadixSort, SortsAndKeepsEqualKeysInInputOrder) {
  for (int bits : {6, 11, 12, 30, 60}) {
    std::mt19937_64 rng(static_cast<std::uint64_t>(bits));
    std::vector<vola::Key> keys(20000);
    // Few distinct values, so that stability matters.
    for (auto& k : keys) k = (rng() % 500) * ((vola::Key{1} << bits) / 500);
    std::vector<std::uint32_t> index(keys.size());
    std::iota(index.begin(), index.end(), 0u);
    std::vector<std::uint32_t> expected = index;
    std::stable_sort(expected.begin(), expected.end(), [&](auto a, auto b) { return keys[a] < keys[b]; });
    std::vector<vola::Key> sorted = keys;
    vola::radix_sort(sorted, &index, bits);
    EXPECT_TRUE(std::is_sorted(sorted.begin(), sorted.end())) << bits;
    EXPECT_EQ(index, expected) << bits;
    for (std::size_t i = 0; i < sorted.size(); ++i) ASSERT_EQ(sorted[i], keys[index[i]]);
  }
}

}  // namespace
}  // namespace vola_test

// Quantizer::to_keys is to_voxel + encode over a batch, with the mode's branches hoisted:
// the same keys, kept indices and drops as the per-point reference, in every mode.
TEST(QuantizerToKeys, MatchesToVoxelPointByPoint) {
  std::mt19937_64 rng(7);
  std::uniform_real_distribution<double> coordinate(-20.0, 120.0);
  std::vector<double> xyz;
  for (int i = 0; i < 30000; ++i) xyz.push_back(coordinate(rng));
  const double specials[] = {std::numeric_limits<double>::quiet_NaN(), std::numeric_limits<double>::infinity(),
                             -std::numeric_limits<double>::infinity(), 0.0, -0.0, 100.0, 1e300};
  for (std::size_t i = 0; i < std::size(specials); ++i) xyz[7 * i + i % 3] = specials[i];
  const vola::Box box{{0, 0, 0}, {100, 100, 100}};
  const vola::Quantizer quantizers[] = {
      vola::Quantizer::toolkit(box, 4), vola::Quantizer::toolkit(vola::Box{{5, 5, 5}, {5, 5, 5}}, 3),
      vola::Quantizer::grid({0, 0, 0}, 1.0, 4), vola::Quantizer::grid({-3.5, 2.25, 0}, 0.7, 6)};
  for (const vola::Quantizer& q : quantizers) {
    std::vector<vola::Key> keys, want_keys;
    std::vector<std::uint32_t> kept, want_kept;
    const std::uint64_t dropped = q.to_keys(xyz, keys, &kept);
    std::uint64_t want_dropped = 0;
    for (std::size_t i = 0; i < xyz.size() / 3; ++i) {
      vola::Voxel v;
      if (!q.to_voxel({xyz[3 * i], xyz[3 * i + 1], xyz[3 * i + 2]}, v)) {
        ++want_dropped;
        continue;
      }
      want_keys.push_back(vola::encode(v));
      want_kept.push_back(static_cast<std::uint32_t>(i));
    }
    EXPECT_EQ(keys, want_keys);
    EXPECT_EQ(kept, want_kept);
    EXPECT_EQ(dropped, want_dropped);
    std::vector<vola::Key> keys_only;
    EXPECT_EQ(q.to_keys(xyz, keys_only, nullptr), want_dropped);
    EXPECT_EQ(keys_only, want_keys);
  }
}
