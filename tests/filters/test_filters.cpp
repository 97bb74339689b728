// Each filter on small synthetic clouds against a slow reference written here: k nearest
// neighbours and outliers by O(n^2) distances, decimation by its invariants, crops by
// direct tests, height above ground by a scan of every ground point, SMRF on a scene
// whose ground is known.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <numeric>
#include <map>
#include <random>

#include "vola/error.hpp"
#include "vola/filters/crop.hpp"
#include "vola/filters/dimensions.hpp"
#include "vola/filters/kd_tree.hpp"
#include "vola/filters/neighbours.hpp"
#include "vola/filters/smrf.hpp"
#include "vola/filters/stages.hpp"

namespace {

using namespace vola::filters;

std::vector<double> random_points(std::size_t n, std::uint64_t seed, double extent = 50.0) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> u(0.0, extent);
  std::vector<double> xyz(3 * n);
  for (double& v : xyz) v = u(rng);
  // Some exact duplicates and points on a lattice: ties the tree must break by index.
  for (std::size_t i = 0; i + 1 < n / 10; ++i)
    for (int a = 0; a < 3; ++a) xyz[3 * (n - 1 - i) + a] = std::round(xyz[3 * i + a]);
  return xyz;
}

double distance2(const std::vector<double>& xyz, std::size_t i, const double* q, int dims) {
  double d2 = 0.0;
  for (int a = 0; a < dims; ++a) d2 += (xyz[3 * i + a] - q[a]) * (xyz[3 * i + a] - q[a]);
  return d2;
}

// Dimension names as users type them: vola's columns, PDAL's spellings, any case.
TEST(Dimensions, PdalNamesFindVolaColumns) {
  vola::PointCloud cloud;
  cloud.xyz = {1, 2, 3};
  for (const char* name : {"scanner_channel", "nir", "classification_flags", "scan_angle_rank", "return_number"})
    cloud.attributes.push_back({name, vola::ValueType::u8, vola::Reduction::last, {0}});
  const std::pair<const char*, std::size_t> cases[] = {{"ScanChannel", 0},   {"scanner_channel", 0}, {"Infrared", 1},
                                                       {"NIR", 1},           {"ClassFlags", 2},      {"ScanAngleRank", 3},
                                                       {"ReturnNumber", 4}};
  for (const auto& [name, column] : cases) {
    const auto d = find_dimension(cloud, name);
    ASSERT_TRUE(d && d->axis < 0) << name;
    EXPECT_EQ(d->column, column) << name;
  }
  EXPECT_FALSE(find_dimension(cloud, "ScanAngle"));
  EXPECT_EQ(find_dimension(cloud, "Z")->axis, 2);
}

// PDAL's one-bit flag dimensions are bits 0-3 of the LAS classification flags, unless the
// points carry columns of their own by those names (a CSV that PDAL wrote).
TEST(Dimensions, PdalFlagDimensionsAreBitsOfTheClassificationFlags) {
  vola::PointCloud cloud;
  cloud.xyz = {0, 0, 0, 1, 1, 1};
  cloud.attributes.push_back({"classification_flags", vola::ValueType::u8, vola::Reduction::last, {0b0101, 0b1010}});
  const char* names[] = {"Synthetic", "KeyPoint", "Withheld", "Overlap"};
  for (int bit = 0; bit < 4; ++bit) {
    const auto d = find_dimension(cloud, names[bit]);
    ASSERT_TRUE(d) << names[bit];
    EXPECT_EQ(value_of(cloud, *d, 0), (0b0101 >> bit) & 1) << names[bit];
    EXPECT_EQ(value_of(cloud, *d, 1), (0b1010 >> bit) & 1) << names[bit];
  }
  // ensure_column never hands a flag bit out as a whole column.
  EXPECT_EQ(ensure_column(cloud, "withheld", vola::ValueType::u8, vola::Reduction::last), 1u);
  const auto own = find_dimension(cloud, "Withheld");
  ASSERT_TRUE(own);
  EXPECT_EQ(own->column, 1u);
  EXPECT_LT(own->bit, 0);
  EXPECT_FALSE(find_dimension(vola::PointCloud{}, "Overlap"));
}

TEST(KdTree, NearestEqualsBruteForceIn2dAnd3d) {
  const auto xyz = random_points(2000, 1);
  const KdTree<3> tree3(xyz, 3);
  const KdTree<2> tree2(xyz, 3);
  std::mt19937_64 rng(2);
  std::uniform_real_distribution<double> u(-5.0, 55.0);
  for (int q = 0; q < 200; ++q) {
    const double p[3] = {u(rng), u(rng), u(rng)};
    for (int dims : {2, 3}) {
      std::vector<std::pair<double, std::uint32_t>> all;
      for (std::size_t i = 0; i < xyz.size() / 3; ++i)
        all.push_back({distance2(xyz, i, p, dims), static_cast<std::uint32_t>(i)});
      std::sort(all.begin(), all.end());
      for (std::size_t k : {1u, 8u, 9u}) {
        const auto got = dims == 3 ? tree3.nearest({p[0], p[1], p[2]}, k) : tree2.nearest({p[0], p[1]}, k);
        ASSERT_EQ(got.size(), k);
        for (std::size_t j = 0; j < k; ++j) ASSERT_EQ(got[j], all[j]) << "query " << q << " dims " << dims << " k " << k;
      }
    }
  }
}

TEST(Outliers, EqualBruteForceStatistics) {
  auto xyz = random_points(800, 3, 20.0);
  for (int far = 0; far < 6; ++far)  // a few points far from everything
    for (int a = 0; a < 3; ++a) xyz.push_back(200.0 + 37.0 * far + a);
  const std::size_t n = xyz.size() / 3;
  std::vector<double> mean(n);
  for (std::size_t i = 0; i < n; ++i) {
    std::vector<double> d;
    for (std::size_t j = 0; j < n; ++j)
      if (j != i) d.push_back(std::sqrt(distance2(xyz, j, &xyz[3 * i], 3)));
    std::sort(d.begin(), d.end());
    mean[i] = std::accumulate(d.begin(), d.begin() + 8, 0.0) / 8.0;
  }
  const double average = std::accumulate(mean.begin(), mean.end(), 0.0) / static_cast<double>(n);
  double squares = 0.0;
  for (double m : mean) squares += (m - average) * (m - average);
  // PDAL's filters.outlier: the sample standard deviation; a mean at the limit is an outlier.
  const double limit = average + 2.0 * std::sqrt(squares / static_cast<double>(n - 1));
  const std::vector<bool> got = statistical_outliers(xyz, OutlierOptions{});
  std::size_t outliers = 0;
  for (std::size_t i = 0; i < n; ++i) {
    ASSERT_EQ(got[i], mean[i] >= limit) << i;
    outliers += got[i];
  }
  EXPECT_GE(outliers, 6u);  // the far points at least
  for (std::size_t i = n - 6; i < n; ++i) EXPECT_TRUE(got[i]);
}

TEST(Decimation, VoxelKeepsTheNearestToEachCentreOncePerCube) {
  const auto xyz = random_points(3000, 4, 10.0);
  const double size = 1.5;
  const std::vector<bool> keep = voxel_decimation(xyz, size);
  const std::size_t n = xyz.size() / 3;
  double lo[3] = {INFINITY, INFINITY, INFINITY};
  for (std::size_t i = 0; i < n; ++i)
    for (int a = 0; a < 3; ++a) lo[a] = std::min(lo[a], xyz[3 * i + a]);
  // Brute force: per cube, the first point at the smallest distance to its centre.
  std::map<std::array<long, 3>, std::pair<double, std::size_t>> best;
  for (std::size_t i = 0; i < n; ++i) {
    std::array<long, 3> c{};
    double d2 = 0.0;
    for (int a = 0; a < 3; ++a) {
      c[a] = static_cast<long>(std::floor((xyz[3 * i + a] - lo[a]) / size));
      const double centre = lo[a] + (static_cast<double>(c[a]) + 0.5) * size;
      d2 += (xyz[3 * i + a] - centre) * (xyz[3 * i + a] - centre);
    }
    auto [it, added] = best.try_emplace(c, d2, i);
    if (!added && d2 < it->second.first - 1e-12) it->second = {d2, i};
  }
  std::vector<bool> expected(n, false);
  for (const auto& [c, chosen] : best) expected[chosen.second] = true;
  EXPECT_EQ(keep, expected);
  EXPECT_LT(std::count(keep.begin(), keep.end(), true), static_cast<long>(n));
}

TEST(Decimation, PoissonKeepsNoTwoCloseAndCoversEveryDroppedPoint) {
  const auto xyz = random_points(3000, 5, 10.0);
  const double r = 0.8;
  const std::vector<bool> keep = poisson_decimation(xyz, r);
  const std::size_t n = xyz.size() / 3;
  for (std::size_t i = 0; i < n; ++i) {
    // A dropped point has a kept point before it within r; kept points are r apart.
    bool covered = false;
    for (std::size_t j = 0; j < n; ++j) {
      if (j == i || !keep[j]) continue;
      const double d2 = distance2(xyz, j, &xyz[3 * i], 3);
      if (keep[i]) ASSERT_GE(d2, r * r) << i << " and " << j;
      else if (j < i && d2 < r * r) covered = true;
    }
    if (!keep[i]) {
      ASSERT_TRUE(covered) << i;
    }
  }
  EXPECT_TRUE(keep[0]);
}

TEST(Crop, BoxAndPolygonsWithHolesAgainstDirectTests) {
  const auto xyz = random_points(2000, 6, 10.0);
  CropBox box{2, 3, 7, 8, std::nullopt, std::nullopt};
  const auto in2 = inside_box(xyz, box);
  box.min_z = 1;
  box.max_z = 4;
  const auto in3 = inside_box(xyz, box);
  // A square 1..9 with a square hole 4..6, as WKT and as GeoJSON.
  const PolygonSet wkt = parse_polygons("POLYGON ((1 1, 9 1, 9 9, 1 9, 1 1), (4 4, 6 4, 6 6, 4 6, 4 4))", "wkt");
  const PolygonSet json = parse_polygons(
      R"({"type":"Feature","geometry":{"type":"MultiPolygon","coordinates":[[[[1,1],[9,1],[9,9],[1,9],[1,1]],[[4,4],[6,4],[6,6],[4,6],[4,4]]]]}})",
      "json");
  const auto in_wkt = inside_polygons(xyz, wkt), in_json = inside_polygons(xyz, json);
  std::size_t counts[4] = {};
  for (std::size_t i = 0; i < xyz.size() / 3; ++i) {
    const double x = xyz[3 * i], y = xyz[3 * i + 1], z = xyz[3 * i + 2];
    const bool b2 = x >= 2 && x <= 7 && y >= 3 && y <= 8;
    ASSERT_EQ(in2[i], b2);
    ASSERT_EQ(in3[i], b2 && z >= 1 && z <= 4);
    const bool ring = x > 1 && x < 9 && y > 1 && y < 9 && !(x > 4 && x < 6 && y > 4 && y < 6);
    const auto on_edge = [](double v) { return v == 1 || v == 4 || v == 6 || v == 9; };
    if (on_edge(x) || on_edge(y)) continue;  // which side an edge point lies on is the test's own choice
    ASSERT_EQ(in_wkt[i], ring) << x << " " << y;
    ASSERT_EQ(in_json[i], ring);
    counts[0] += b2, counts[1] += in3[i], counts[2] += ring, counts[3] += !ring;
  }
  for (auto c : counts) EXPECT_GT(c, 0u);
  EXPECT_THROW(parse_polygons("LINESTRING (0 0, 1 1)", "line"), vola::InvalidArgument);
  EXPECT_THROW(parse_polygons(R"({"type":"Point","coordinates":[1,2]})", "point"), vola::InvalidArgument);
}

// Overlapping polygons (two features, two members of a multipolygon) make a union: the
// even-odd rule over every ring at once dropped the points inside both.
TEST(Crop, OverlappingPolygonsAreAUnion) {
  const auto xyz = random_points(3000, 8, 10.0);
  const PolygonSet features = parse_polygons(
      R"({"type":"FeatureCollection","features":[
          {"type":"Feature","geometry":{"type":"Polygon","coordinates":[[[1,1],[6,1],[6,6],[1,6],[1,1]]]}},
          {"type":"Feature","geometry":{"type":"Polygon","coordinates":[[[4,4],[9,4],[9,9],[4,9],[4,4]]]}}]})",
      "features");
  const PolygonSet multi =
      parse_polygons("MULTIPOLYGON (((1 1, 6 1, 6 6, 1 6, 1 1)), ((4 4, 9 4, 9 9, 4 9, 4 4), (7 7, 8 7, 8 8, 7 8, 7 7)))",
                     "multi");
  ASSERT_EQ(multi.polygons.size(), 2u);
  EXPECT_EQ(multi.polygons[1].size(), 2u);  // the second with its hole
  const auto in_features = inside_polygons(xyz, features), in_multi = inside_polygons(xyz, multi);
  std::size_t both = 0;
  for (std::size_t i = 0; i < xyz.size() / 3; ++i) {
    const double x = xyz[3 * i], y = xyz[3 * i + 1];
    const bool a = x > 1 && x < 6 && y > 1 && y < 6, b = x > 4 && x < 9 && y > 4 && y < 9;
    const bool hole = x > 7 && x < 8 && y > 7 && y < 8;
    const auto on_edge = [](double v) { return v == 1 || v == 4 || v == 6 || v == 7 || v == 8 || v == 9; };
    if (on_edge(x) || on_edge(y)) continue;  // which side an edge point lies on is the test's own choice
    ASSERT_EQ(in_features[i], a || b) << x << " " << y;
    ASSERT_EQ(in_multi[i], a || (b && !hole)) << x << " " << y;
    both += a && b;
  }
  EXPECT_GT(both, 0u);
  EXPECT_THROW(parse_polygons("MULTIPOLYGON (0 0, 1 0, 1 1)", "flat"), vola::InvalidArgument);
}

TEST(Outliers, PointsWithoutAPlaceAreDroppedAndChangeNothingElse) {
  // One NaN or infinite point made the limit NaN, and every outlier was kept.
  auto xyz = random_points(400, 5, 20.0);
  for (int a = 0; a < 3; ++a) xyz.push_back(300.0 + a);  // far from everything
  const std::vector<bool> clean = statistical_outliers(xyz, OutlierOptions{});
  ASSERT_TRUE(clean.back());
  auto with_holes = xyz;
  with_holes.insert(with_holes.end(), {NAN, 1.0, 1.0, 2.0, INFINITY, 2.0});
  const std::vector<bool> got = statistical_outliers(with_holes, OutlierOptions{});
  ASSERT_EQ(got.size(), clean.size() + 2);
  EXPECT_TRUE(std::equal(clean.begin(), clean.end(), got.begin()));
  EXPECT_TRUE(got[clean.size()] && got[clean.size() + 1]);
  // No spread at all (duplicates, two points): nothing stands out, nothing is dropped.
  const std::vector<double> same(300, 1.5);
  const auto none = statistical_outliers(same, OutlierOptions{});
  EXPECT_EQ(std::count(none.begin(), none.end(), true), 0);
  const auto two = statistical_outliers(std::vector<double>{0, 0, 0, 1, 1, 1}, OutlierOptions{});
  EXPECT_EQ(std::count(two.begin(), two.end(), true), 0);
}

TEST(HeightAboveGround, GroundPointsWithoutAPlaceAreNotSearched) {
  // NaN ground points misled the k-d tree: heights from a ground point 5 m away.
  vola::PointCloud cloud;
  cloud.xyz = random_points(1200, 9, 30.0);
  cloud.attributes.push_back({"classification", vola::ValueType::u8, vola::Reduction::majority, {}});
  for (std::size_t i = 0; i < cloud.size(); ++i) cloud.attributes[0].values.push_back(i % 3 == 0 ? 2 : 1);
  for (std::size_t i = 0; i < cloud.size(); i += 30) cloud.xyz[3 * i + (i % 90 == 0 ? 0 : 2)] = NAN;  // ground points
  add_height_above_ground(cloud);
  const auto hag = find_dimension(cloud, "HeightAboveGround");
  ASSERT_TRUE(hag);
  const auto placed = [&](std::size_t i) {
    return std::isfinite(cloud.xyz[3 * i]) && std::isfinite(cloud.xyz[3 * i + 1]) &&
           std::isfinite(cloud.xyz[3 * i + 2]);
  };
  for (std::size_t i = 0; i < cloud.size(); ++i) {
    if (!placed(i)) {
      EXPECT_TRUE(std::isnan(value_of(cloud, *hag, i))) << i;
      continue;
    }
    double best = INFINITY;
    std::size_t nearest = 0;
    for (std::size_t j = 0; j < cloud.size(); j += 3) {
      if (!placed(j)) continue;
      const double d2 = distance2(cloud.xyz, j, &cloud.xyz[3 * i], 2);
      if (d2 < best) best = d2, nearest = j;
    }
    ASSERT_EQ(value_of(cloud, *hag, i), cloud.xyz[3 * i + 2] - cloud.xyz[3 * nearest + 2]) << i;
  }
}

TEST(HeightAboveGround, EqualsZMinusTheNearestGroundPointByBruteForce) {
  vola::PointCloud cloud;
  cloud.xyz = random_points(1500, 7, 30.0);
  cloud.attributes.push_back({"classification", vola::ValueType::u8, vola::Reduction::majority, {}});
  for (std::size_t i = 0; i < cloud.size(); ++i) cloud.attributes[0].values.push_back(i % 4 == 0 ? 2 : 1);
  add_height_above_ground(cloud);
  const auto hag = find_dimension(cloud, "HeightAboveGround");
  ASSERT_TRUE(hag && hag->axis < 0);
  for (std::size_t i = 0; i < cloud.size(); ++i) {
    double best = INFINITY;
    std::size_t nearest = 0;
    for (std::size_t j = 0; j < cloud.size(); j += 4) {
      const double d2 = distance2(cloud.xyz, j, &cloud.xyz[3 * i], 2);
      if (d2 < best) best = d2, nearest = j;
    }
    ASSERT_EQ(value_of(cloud, *hag, i), cloud.xyz[3 * i + 2] - cloud.xyz[3 * nearest + 2]) << i;
  }
  vola::PointCloud no_ground;
  no_ground.xyz = {0, 0, 0};
  EXPECT_THROW(add_height_above_ground(no_ground), vola::InvalidArgument);
}

// A sloping field (5%) with a low outlier, a 20 x 30 m building 8 m high and a few
// trees, 2 points per square metre with 5 cm noise: SMRF finds the field and not the
// roof, tree tops or outlier.
TEST(Smrf, SeparatesGroundFromABuildingTreesAndALowOutlier) {
  std::mt19937_64 rng(8);
  std::uniform_real_distribution<double> u(0.0, 100.0);
  std::normal_distribution<double> noise(0.0, 0.05);
  vola::PointCloud cloud;
  std::vector<int> truth;  // 2 ground, 6 building, 5 tree, 7 outlier
  const auto ground_z = [](double x, double y) { return 100.0 + 0.05 * x + 0.02 * y; };
  for (int i = 0; i < 20000; ++i) {
    const double x = u(rng), y = u(rng);
    double z = ground_z(x, y) + noise(rng);
    int kind = 2;
    if (x > 40 && x < 60 && y > 30 && y < 60) z += 8.0, kind = 6;
    else if (std::hypot(x - 20, y - 80) < 3 && i % 2) z += 6.0 + noise(rng), kind = 5;
    cloud.xyz.insert(cloud.xyz.end(), {x, y, z});
    truth.push_back(kind);
  }
  cloud.xyz.insert(cloud.xyz.end(), {70.0, 70.0, ground_z(70, 70) - 30.0});
  truth.push_back(7);
  classify_ground(cloud, SmrfOptions{}, Units{});
  const auto& cls = cloud.attributes[0].values;
  std::size_t ground = 0, found = 0, wrong = 0;
  for (std::size_t i = 0; i < truth.size(); ++i) {
    ground += truth[i] == 2;
    found += truth[i] == 2 && cls[i] == 2;
    wrong += truth[i] != 2 && cls[i] == 2;
  }
  EXPECT_GE(static_cast<double>(found), 0.99 * static_cast<double>(ground));
  EXPECT_EQ(wrong, 0u);
  EXPECT_EQ(cls.back(), 1.0);  // the outlier is not ground
}

// Half of a survey is flight-line overlap (class 12), a 20 x 20 m roof 8 m high among it:
// the overlap points keep their class, yet they are the surface that the few other
// points there are judged against (one point in 50 of the overlap half is class 1).
TEST(Smrf, OverlapPointsKeepTheirClassAndStillShapeTheSurface) {
  std::mt19937_64 rng(21);
  std::uniform_real_distribution<double> u(0.0, 100.0);
  std::normal_distribution<double> noise(0.0, 0.05);
  vola::PointCloud cloud;
  std::vector<int> kind;  // 0 ground, 1 roof
  std::vector<double> classes;
  for (int i = 0; i < 20000; ++i) {
    const double x = u(rng), y = u(rng);
    const bool roof = x > 70 && x < 90 && y > 40 && y < 60;
    cloud.xyz.insert(cloud.xyz.end(), {x, y, 50.0 + 0.03 * x + (roof ? 8.0 : 0.0) + noise(rng)});
    kind.push_back(roof ? 1 : 0);
    classes.push_back(x > 50 && i % 50 != 0 ? 12.0 : 1.0);
  }
  cloud.attributes.push_back({"classification", vola::ValueType::u8, vola::Reduction::majority, classes});
  classify_ground(cloud, SmrfOptions{}, Units{});
  const auto& cls = cloud.attributes[0].values;
  std::size_t kept = 0, others_right = 0, others = 0;
  for (std::size_t i = 0; i < kind.size(); ++i) {
    if (classes[i] == 12) {
      kept += cls[i] == 12;
      continue;
    }
    if (cloud.xyz[3 * i] <= 50) continue;
    ++others;
    others_right += cls[i] == (kind[i] == 1 ? 1.0 : 2.0);
  }
  EXPECT_EQ(kept, static_cast<std::size_t>(std::count(classes.begin(), classes.end(), 12.0)));
  ASSERT_GT(others, 100u);
  EXPECT_EQ(others_right, others);  // ground among the overlap is ground, the roof is not
}

// Ground at one point per m2 (a third of the 1 m cells empty) with echoes scattered 5 to
// 60 m below it over a 20 x 20 m patch, in three cells of ten: each lies below cells
// that hold ground, and no cell nearby continues it. The negated opening alone keeps
// those among other lows and empty cells, and the ground beside them then reads as
// objects, or the echoes as ground (both failed before the unsupported-low pass).
TEST(Smrf, ScatteredLowEchoesDoNotTakeTheGroundAroundThem) {
  std::mt19937_64 rng(12);
  std::uniform_real_distribution<double> u(0.0, 60.0), depth(5.0, 60.0), unit(0.0, 1.0);
  std::normal_distribution<double> noise(0.0, 0.03);
  std::vector<double> xyz;
  std::vector<bool> is_ground;
  const auto ground_z = [](double x, double y) { return 50.0 + 0.04 * x - 0.03 * y; };
  for (int i = 0; i < 3600; ++i) {
    const double x = u(rng), y = u(rng);
    xyz.insert(xyz.end(), {x, y, ground_z(x, y) + noise(rng)});
    is_ground.push_back(true);
  }
  for (int cx = 20; cx < 40; ++cx)
    for (int cy = 20; cy < 40; ++cy)
      if (unit(rng) < 0.3) {
        const double x = cx + unit(rng), y = cy + unit(rng);
        xyz.insert(xyz.end(), {x, y, ground_z(x, y) - depth(rng)});
        is_ground.push_back(false);
      }
  const std::vector<bool> all(is_ground.size(), true);
  const std::vector<bool> ground = smrf_ground(xyz, all, SmrfOptions{}, Units{});
  std::size_t truth = 0, found = 0, wrong = 0;
  for (std::size_t i = 0; i < ground.size(); ++i) {
    truth += is_ground[i];
    found += is_ground[i] && ground[i];
    wrong += !is_ground[i] && ground[i];
  }
  EXPECT_GE(static_cast<double>(found), 0.995 * static_cast<double>(truth)) << found << " of " << truth;
  EXPECT_EQ(wrong, 0u);
}

// A 40 x 40 m patch of ground at one point per m2 in an otherwise empty 100 x 100 m
// survey, with single echoes 20 to 60 m below the ground scattered 4 to 12 m beyond its
// edge, each more than 3 m from any other cell: no cell within 3 m judges them, so they must be
// judged against their nearest cells, however far. Kept, the surface filled around them
// sinks at the edge of the patch and the opening reads the ground along it as objects.
TEST(Smrf, EchoesOutInAnEmptySurveyDoNotTakeTheEdgeOfTheGround) {
  std::mt19937_64 rng(14);
  std::uniform_real_distribution<double> u(0.0, 40.0), out(4.0, 12.0), depth(20.0, 60.0);
  std::normal_distribution<double> noise(0.0, 0.03);
  std::vector<double> xyz;
  std::vector<bool> is_ground;
  const auto ground_z = [](double x, double y) { return 80.0 + 0.03 * x + 0.02 * y; };
  for (int i = 0; i < 1600; ++i) {
    const double x = u(rng), y = u(rng);
    xyz.insert(xyz.end(), {x, y, ground_z(x, y) + noise(rng)});
    is_ground.push_back(true);
  }
  for (int i = 0; i < 8; ++i) {  // beyond the east edge, 5 m apart along it
    const double x = 40.0 + out(rng), y = 2.5 + 5.0 * i;
    xyz.insert(xyz.end(), {x, y, ground_z(x, y) - depth(rng)});
    is_ground.push_back(false);
  }
  xyz.insert(xyz.end(), {100.0, 100.0, ground_z(100.0, 100.0)});  // the survey's far corner
  is_ground.push_back(true);
  const std::vector<bool> all(is_ground.size(), true);
  const std::vector<bool> ground = smrf_ground(xyz, all, SmrfOptions{}, Units{});
  std::size_t truth = 0, found = 0, wrong = 0;
  for (std::size_t i = 0; i < ground.size(); ++i) {
    truth += is_ground[i];
    found += is_ground[i] && ground[i];
    wrong += !is_ground[i] && ground[i];
  }
  EXPECT_GE(static_cast<double>(found), 0.995 * static_cast<double>(truth)) << found << " of " << truth;
  EXPECT_EQ(wrong, 0u);
}

// Found and wrongly-called counts of smrf_ground on a scene whose truth is known.
struct GroundCount {
  std::size_t truth = 0, found = 0, wrong = 0, objects = 0;
};
GroundCount count_ground(const std::vector<double>& xyz, const std::vector<bool>& is_ground) {
  const std::vector<bool> all(is_ground.size(), true);
  const std::vector<bool> ground = smrf_ground(xyz, all, SmrfOptions{}, Units{});
  GroundCount n;
  for (std::size_t i = 0; i < ground.size(); ++i) {
    n.truth += is_ground[i];
    n.objects += !is_ground[i];
    n.found += is_ground[i] && ground[i];
    n.wrong += !is_ground[i] && ground[i];
  }
  return n;
}

// A forest on gently sloping ground, 150 x 150 m: last returns reach the ground at 0.15
// per m2 (lidR's Megaplot.laz has 0.14), and leaves and branches 2 to 25 m up at 1.5 per
// m2 everywhere. Most 1 m cells hold only vegetation, so each cell that holds ground lies
// metres below all its neighbours, and the low-outlier opening takes it for a pit; yet
// those cells continue one another across the forest. Taken for pits, they left the
// canopy as the surface (Megaplot: 82.7% of its ground found, 12.8% of the points called
// ground more than 1 m above it).
TEST(Smrf, GroundSeenThroughADenseCanopyIsNotTakenForPits) {
  std::mt19937_64 rng(23);
  std::uniform_real_distribution<double> u(0.0, 150.0), height(2.0, 25.0);
  std::normal_distribution<double> noise(0.0, 0.05);
  std::vector<double> xyz;
  std::vector<bool> is_ground;
  const auto ground_z = [](double x, double y) { return 300.0 + 0.04 * x + 0.02 * y; };
  for (int i = 0; i < 3375; ++i) {
    const double x = u(rng), y = u(rng);
    xyz.insert(xyz.end(), {x, y, ground_z(x, y) + noise(rng)});
    is_ground.push_back(true);
  }
  for (int i = 0; i < 33750; ++i) {
    const double x = u(rng), y = u(rng);
    xyz.insert(xyz.end(), {x, y, ground_z(x, y) + height(rng)});
    is_ground.push_back(false);
  }
  const GroundCount n = count_ground(xyz, is_ground);
  EXPECT_GE(static_cast<double>(n.found), 0.95 * static_cast<double>(n.truth)) << n.found << " of " << n.truth;
  EXPECT_LE(static_cast<double>(n.wrong), 0.01 * static_cast<double>(n.found)) << n.wrong << " of " << n.found;
}

// A clip that is mostly one roof (62 x 80 m, wider than the 36 m the window spans), 25 m
// above a strip of road along one side, with the building's shadow (no points) between
// them: no opening removes the roof; it stands above the road on a wall, so it is not
// ground (the roof was all ground before the raised-plateau step).
TEST(Smrf, ARoofWiderThanTheWindowIsNotGround) {
  std::mt19937_64 rng(21);
  std::uniform_real_distribution<double> x_of(0.0, 90.0), y_of(0.0, 80.0);
  std::normal_distribution<double> noise(0.0, 0.03);
  std::vector<double> xyz;
  std::vector<bool> is_ground;
  for (int i = 0; i < 7200; ++i) {
    const double x = x_of(rng), y = y_of(rng);
    if (x >= 14.0 && x < 28.0) continue;  // the shadow
    const bool roof = x >= 28.0;
    xyz.insert(xyz.end(), {x, y, (roof ? 125.0 + 0.03 * x : 100.0 + 0.02 * y) + noise(rng)});
    is_ground.push_back(!roof);
  }
  const GroundCount n = count_ground(xyz, is_ground);
  EXPECT_GE(static_cast<double>(n.found), 0.99 * static_cast<double>(n.truth)) << n.found << " of " << n.truth;
  EXPECT_LE(static_cast<double>(n.wrong), 0.005 * static_cast<double>(n.objects)) << n.wrong << " of " << n.objects;
}

// The same step the other way round: flat ground around a 40 x 40 m excavation with
// vertical walls 8 m deep. The ground is the upper side of every wall it has, but the
// excavation lies inside it, so neither is taken for a roof.
TEST(Smrf, FlatGroundAroundAWideExcavationStaysGround) {
  std::mt19937_64 rng(22);
  std::uniform_real_distribution<double> u(0.0, 120.0);
  std::normal_distribution<double> noise(0.0, 0.03);
  std::vector<double> xyz;
  for (int i = 0; i < 14400; ++i) {
    const double x = u(rng), y = u(rng);
    const bool pit = x > 40.0 && x < 80.0 && y > 40.0 && y < 80.0;
    xyz.insert(xyz.end(), {x, y, (pit ? 42.0 : 50.0) + noise(rng)});
  }
  const GroundCount n = count_ground(xyz, std::vector<bool>(xyz.size() / 3, true));
  EXPECT_GE(static_cast<double>(n.found), 0.99 * static_cast<double>(n.truth)) << n.found << " of " << n.truth;
}

// A hillside (slope 0.3) of rough ground (points +-0.4 m about it, 2 per m2) under shrubs
// whose last returns lie 1.1 m up (1 per m2). The tolerance is 0.5 m + 1.25 x slope: with
// the hillside's slope, 0.875 m, the shrubs are not ground; with the slope between
// neighbouring cells of the rough minimum surface it grew past 1.1 m in places (164 shrub
// points called ground, 2.6%; 13 with the 3 m baseline, kSlopeBaseline).
TEST(Smrf, RoughGroundDoesNotWidenTheToleranceForShrubsOnAHillside) {
  std::mt19937_64 rng(31);
  std::uniform_real_distribution<double> u(0.0, 80.0), rough(-0.4, 0.4);
  std::vector<double> xyz;
  std::vector<bool> is_ground;
  const auto ground_z = [](double x, double y) { return 200.0 + 0.3 * x + 0.05 * y; };
  for (int i = 0; i < 12800; ++i) {
    const double x = u(rng), y = u(rng);
    xyz.insert(xyz.end(), {x, y, ground_z(x, y) + rough(rng)});
    is_ground.push_back(true);
  }
  for (int i = 0; i < 6400; ++i) {
    const double x = u(rng), y = u(rng);
    xyz.insert(xyz.end(), {x, y, ground_z(x, y) + 1.1});
    is_ground.push_back(false);
  }
  const GroundCount n = count_ground(xyz, is_ground);
  EXPECT_GE(static_cast<double>(n.found), 0.99 * static_cast<double>(n.truth)) << n.found << " of " << n.truth;
  EXPECT_LE(n.wrong, n.objects / 100) << n.wrong << " of " << n.objects << " shrub points called ground";
}

// A stray point far from the survey stretches SMRF's grid over empty ground: the grid is
// refused before it is allocated, and the error gives the extent that made it large and
// what to do, instead of taking gigabytes (80 bytes a cell) or being killed for memory.
TEST(Smrf, AGridStretchedByAStrayPointIsRefusedNamingItsExtent) {
  const std::vector<double> xyz = {0, 0, 10, 1, 1, 10, 2, 0, 10, 900000, 900000, 11};
  const std::vector<bool> all(4, true);
  try {
    smrf_ground(xyz, all, SmrfOptions{}, Units{});
    FAIL() << "a 900 km grid of 1 m cells was not refused";
  } catch (const vola::InvalidArgument& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("the points span 900000 x 900000 m, from (0, 0) to (900000, 900000)"), std::string::npos)
        << what;
    EXPECT_NE(what.find("remove points far from the survey"), std::string::npos) << what;
  }
  // Coordinates near the double range still give a whole message, not 300 digits cut off.
  const std::vector<double> wild = {0, 0, 10, 1e300, 1e300, 11, -1e300, 5, 10};
  try {
    smrf_ground(wild, std::vector<bool>(3, true), SmrfOptions{}, Units{});
    FAIL() << "a grid of 1e300 m was not refused";
  } catch (const vola::InvalidArgument& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("from (-1e+300, 0) to (1e+300, 1e+300)"), std::string::npos) << what;
    EXPECT_NE(what.find("or give a larger cell"), std::string::npos) << what;
    EXPECT_LT(what.size(), 600u) << what;
  }
  SmrfOptions coarse;
  coarse.cell = 1000.0;  // 901 x 901 cells: well within any machine
  EXPECT_EQ(smrf_ground(xyz, all, coarse, Units{}).size(), 4u);
}

// The same scene in US survey feet gives the same answer as in metres.
TEST(Smrf, ParametersAreMetresWhateverTheUnits) {
  std::mt19937_64 rng(9);
  std::uniform_real_distribution<double> u(0.0, 60.0);
  std::vector<double> metres;
  for (int i = 0; i < 6000; ++i) {
    const double x = u(rng), y = u(rng);
    const bool roof = x > 20 && x < 35 && y > 20 && y < 40;
    metres.insert(metres.end(), {x, y, 50.0 + 0.1 * x + (roof ? 3.0 : 0.0)});
  }
  const double foot = 1200.0 / 3937.0;
  std::vector<double> feet = metres;
  for (double& v : feet) v /= foot;
  const std::vector<bool> all(metres.size() / 3, true);
  const auto in_metres = smrf_ground(metres, all, SmrfOptions{}, Units{});
  const auto in_feet = smrf_ground(feet, all, SmrfOptions{}, Units{foot, foot});
  EXPECT_EQ(in_metres, in_feet);
  EXPECT_GT(std::count(in_metres.begin(), in_metres.end(), false), 400);  // the roof, 3 m up (~500 points)
  EXPECT_EQ(*metres_per_unit("US survey foot"), foot);
}

TEST(Stages, ParseTheirStringsAndRefuseUnknownOnes) {
  EXPECT_EQ(parse_stage("smrf:cell=2,window=30").smrf.window, 30.0);
  EXPECT_EQ(parse_stage("voxel:0.5").size, 0.5);
  EXPECT_EQ(parse_stage("crop:1,2,3,4,5,6").box.max_x, 4.0);
  EXPECT_EQ(parse_stage("outlier:k=12").outlier.neighbours, 12);
  const auto message = [](const std::string& spec) {
    try {
      parse_stage(spec);
    } catch (const vola::OptionError& e) {
      return std::string(e.what());
    }
    return std::string();
  };
  EXPECT_EQ(message("ground"), "filters: 'ground': no filter 'ground' (where:EXPR, smrf, hag, outlier, voxel:R, "
                               "poisson:R, crop:..., polygon:FILE)");
  EXPECT_EQ(message("smrf:cells=2"), "filters: 'smrf:cells=2': smrf has no parameter 'cells' (cell, slope, window, threshold, scalar)");
  // A where stage came from --where: its error names that option and the expression alone.
  EXPECT_EQ(message("where:z >"), "where: 'z >': where: at character 4: expected a dimension name or a number, found the end");
  EXPECT_EQ(message("crop:1,2,3"), "filters: 'crop:1,2,3': crop takes MINX,MINY,MAXX,MAXY or MINX,MINY,MINZ,MAXX,MAXY,MAXZ");
  // A parameter's own check names it inside the stage (the CLI shows "filters" as --filter),
  // not as a flag of its own ("--cell" is no option of any command).
  EXPECT_EQ(message("smrf:cell=-1"), "filters: 'smrf:cell=-1': cell must be a positive number (metres), not -1");
  EXPECT_EQ(message("outlier:multiplier=-2"), "filters: 'outlier:multiplier=-2': multiplier must be 0 or more");
  // k = 200000 over 110,000 points did not end in minutes.
  EXPECT_EQ(parse_stage("outlier:k=1000").outlier.neighbours, 1000);
  EXPECT_EQ(message("outlier:k=1001"), "filters: 'outlier:k=1001': k must be a whole number from 1 to 1000 (the "
                                       "neighbours of each point whose mean distance is compared; PDAL's default is 8)");
}

TEST(Stages, RunInOrderAndReportTheInputIndexOfEveryPointLeft) {
  vola::PointCloud cloud;
  for (int i = 0; i < 10; ++i) cloud.xyz.insert(cloud.xyz.end(), {double(i), 0.0, double(i % 3)});
  cloud.attributes.push_back({"classification", vola::ValueType::u8, vola::Reduction::majority,
                              {2, 1, 2, 1, 2, 1, 2, 1, 2, 1}});
  const auto result = run_stages(parse_stages({"where:z > 0", "crop:2,-1,9,1", "where:Classification==2"}), cloud, {}, "");
  EXPECT_EQ(result.kept, (std::vector<std::uint64_t>{2, 4, 8}));
  EXPECT_EQ(cloud.xyz, (std::vector<double>{2, 0, 2, 4, 0, 1, 8, 0, 2}));
  ASSERT_EQ(result.stages.size(), 3u);
  EXPECT_EQ(result.stages[0].points_out, 6u);
  EXPECT_EQ(result.stages[1].points_out, 5u);
}

}  // namespace

// Points with a NaN or infinite coordinate are in no cell (never kept, no undefined
// conversion of NaN to an integer), and sizes too small for the coordinates are refused.
TEST(Decimation, NonFinitePointsAreDroppedAndTinySizesRefused) {
  const std::vector<double> xyz{0.1, 0.1, 0.1, NAN, 0, 0, 0.2, INFINITY, 0, 5, 5, 5};
  const std::vector<bool> voxel = vola::filters::voxel_decimation(xyz, 1.0);
  const std::vector<bool> poisson = vola::filters::poisson_decimation(xyz, 1.0);
  EXPECT_EQ(voxel, (std::vector<bool>{true, false, false, true}));
  EXPECT_EQ(poisson, (std::vector<bool>{true, false, false, true}));
  const std::vector<double> far{1e300, 0, 0};
  EXPECT_THROW(vola::filters::voxel_decimation(far, 1e-300), vola::OptionError);
  EXPECT_THROW(vola::filters::poisson_decimation(far, 1e-300), vola::OptionError);
  EXPECT_THROW(vola::filters::parse_stage("outlier:k=1e200"), vola::OptionError);
  EXPECT_THROW(vola::filters::parse_stage("smrf:cell=1e-9"), vola::OptionError);
}
