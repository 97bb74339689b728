// StreamBuilder against vola::build over the same points at once: same voxels, same
// payloads, same attribute values, for random chunkings.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <random>

#include "test_support.hpp"
#include "vola/vola.hpp"

namespace {

struct Points {
  vola::PointCloud cloud;
  std::vector<vola::AttributeSpec> specs;
};

Points random_points(std::uint64_t seed, std::size_t n) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> coordinate(-5.0, 45.0);
  std::uniform_int_distribution<int> small(0, 5), byte(0, 255);
  Points p;
  p.specs = {{"mean", vola::ValueType::f64, vola::Reduction::mean},
             {"max", vola::ValueType::u16, vola::Reduction::max},
             {"min", vola::ValueType::i32, vola::Reduction::min},
             {"last", vola::ValueType::u8, vola::Reduction::last},
             {"majority", vola::ValueType::u8, vola::Reduction::majority}};
  for (const auto& s : p.specs) p.cloud.attributes.push_back({s.name, s.type, s.reduction, {}});
  for (std::size_t i = 0; i < n; ++i) {
    for (int a = 0; a < 3; ++a) p.cloud.xyz.push_back(coordinate(rng));
    // Few distinct values so that majorities and ties happen; means skip NaN (no value).
    const bool no_value = byte(rng) < 40;
    p.cloud.attributes[0].values.push_back(no_value ? std::numeric_limits<double>::quiet_NaN() : small(rng) * 0.25);
    p.cloud.attributes[1].values.push_back(byte(rng));
    p.cloud.attributes[2].values.push_back(small(rng) - 2);
    p.cloud.attributes[3].values.push_back(byte(rng));
    p.cloud.attributes[4].values.push_back(small(rng));
    p.cloud.payload.push_back(static_cast<std::uint64_t>(byte(rng)) * 0x0101010101ull);
  }
  return p;
}

class StreamBuilderEqualsBuild : public ::testing::TestWithParam<int> {};

TEST_P(StreamBuilderEqualsBuild, ForRandomChunks) {
  const std::uint64_t seed = static_cast<std::uint64_t>(GetParam());
  const Points p = random_points(seed, 20000);
  for (const auto mode : {vola::Quantization::toolkit, vola::Quantization::grid}) {
    vola::BuildOptions options;
    options.quantization = mode;
    options.depth = 1 + static_cast<int>(seed % 4);  // coarse grids: many points per voxel
    // A grid that holds the points (-5..45): 80 units a side.
    options.voxel_size = mode == vola::Quantization::grid ? 80.0 / vola::side_of(options.depth) : 0.0;
    options.payload = true;
    const vola::Tree expected = vola::build(p.cloud, options);

    vola::BuildOptions resolved = options;
    const vola::Box box = p.cloud.bounds();
    const vola::Quantizer quantizer = vola::resolve_quantizer(box, resolved);
    vola::StreamBuilder builder(quantizer, p.specs, true);
    std::mt19937_64 rng(seed + 99);
    for (std::size_t at = 0; at < p.cloud.size();) {
      const std::size_t n = std::min<std::size_t>(p.cloud.size() - at, 1 + rng() % 3000);
      std::vector<std::span<const double>> values;
      for (const auto& a : p.cloud.attributes) values.emplace_back(a.values.data() + at, n);
      builder.add({p.cloud.xyz.data() + 3 * at, 3 * n}, values, {p.cloud.payload.data() + at, n});
      at += n;
    }
    const vola::Tree got = builder.finish();
    ASSERT_EQ(got.depth(), expected.depth());
    ASSERT_EQ(std::vector<std::uint64_t>(got.words().begin(), got.words().end()),
              std::vector<std::uint64_t>(expected.words().begin(), expected.words().end()));
    ASSERT_EQ(std::vector<std::uint64_t>(got.voxel_payloads().begin(), got.voxel_payloads().end()),
              std::vector<std::uint64_t>(expected.voxel_payloads().begin(), expected.voxel_payloads().end()));
    ASSERT_EQ(got.attributes().size(), expected.attributes().size());
    for (std::size_t c = 0; c < got.attributes().size(); ++c) {
      const auto& g = got.attributes().columns()[c];
      const auto& e = expected.attributes().columns()[c];
      ASSERT_EQ(g.name(), e.name());
      for (std::size_t v = 0; v < g.size(); ++v) {  // means may differ in the order of summation only
        if (std::isnan(e.get(v)))
          ASSERT_TRUE(std::isnan(g.get(v))) << g.name() << " voxel " << v;
        else
          ASSERT_NEAR(g.get(v), e.get(v), 1e-9) << g.name() << " voxel " << v;
      }
    }
    EXPECT_EQ(builder.points_in(), p.cloud.size());
  }
}

INSTANTIATE_TEST_SUITE_P(Seeds, StreamBuilderEqualsBuild, ::testing::Range(1, 9));

// Payloads without attribute columns once took a merge path that dropped them.
TEST(StreamBuilder, PayloadsWithoutAttributes) {
  Points p = random_points(42, 5000);
  p.cloud.attributes.clear();
  vola::BuildOptions options;
  options.quantization = vola::Quantization::toolkit;
  options.depth = 3;
  options.payload = true;
  const vola::Tree expected = vola::build(p.cloud, options);
  vola::BuildOptions resolved = options;
  vola::StreamBuilder builder(vola::resolve_quantizer(p.cloud.bounds(), resolved), {}, true);
  for (std::size_t at = 0; at < p.cloud.size(); at += 1000)
    builder.add({p.cloud.xyz.data() + 3 * at, 3000}, {}, {p.cloud.payload.data() + at, 1000});
  const vola::Tree got = builder.finish();
  EXPECT_EQ(std::vector<std::uint64_t>(got.words().begin(), got.words().end()),
            std::vector<std::uint64_t>(expected.words().begin(), expected.words().end()));
  EXPECT_EQ(std::vector<std::uint64_t>(got.voxel_payloads().begin(), got.voxel_payloads().end()),
            std::vector<std::uint64_t>(expected.voxel_payloads().begin(), expected.voxel_payloads().end()));
}

// NaN in a majority column is one value among others, sorting after the numbers (it
// once made the reduction loop forever: NaN != NaN); max and min skip NaN unless every
// value is NaN; a mean is over the values that are numbers (NaN is a point without a
// value: a LAS no_data). Built at once and streamed one point per chunk (so that the
// merges combine the histograms and the counts of NaN), the same answers.
TEST(StreamBuilder, MajorityWithNaNValues) {
  const double nan = std::numeric_limits<double>::quiet_NaN();
  vola::PointCloud cloud;
  cloud.xyz = {0.1, 0.1, 0.1, 0.2, 0.2, 0.2, 0.3, 0.3, 0.3, 5.1, 5.1, 5.1, 5.2, 5.2, 5.2, 9.9, 9.9, 9.9};
  cloud.attributes.push_back({"m", vola::ValueType::f64, vola::Reduction::majority, {nan, 1.0, nan, 2.0, nan, nan}});
  cloud.attributes.push_back({"hi", vola::ValueType::f64, vola::Reduction::max, {nan, 1.0, nan, nan, 2.0, nan}});
  cloud.attributes.push_back({"avg", vola::ValueType::f64, vola::Reduction::mean, {nan, 1.0, 4.0, nan, 2.0, nan}});
  vola::BuildOptions options;
  options.quantization = vola::Quantization::grid;
  options.voxel_size = 1.0;
  options.origin = std::array<double, 3>{0.0, 0.0, 0.0};
  const vola::Tree built = vola::build(cloud, options);
  vola::BuildOptions resolved = options;
  vola::StreamBuilder builder(vola::resolve_quantizer(cloud.bounds(), resolved),
                              {{"m", vola::ValueType::f64, vola::Reduction::majority},
                               {"hi", vola::ValueType::f64, vola::Reduction::max},
                               {"avg", vola::ValueType::f64, vola::Reduction::mean}},
                              false);
  for (std::size_t i = 0; i < cloud.size(); ++i) {
    const std::vector<std::span<const double>> values{{cloud.attributes[0].values.data() + i, 1},
                                                      {cloud.attributes[1].values.data() + i, 1},
                                                      {cloud.attributes[2].values.data() + i, 1}};
    builder.add({cloud.xyz.data() + 3 * i, 3}, values, {});
  }
  const vola::Tree streamed = builder.finish();
  for (const vola::Tree* tree : {&built, &streamed}) {
    const auto& column = tree->attributes().columns()[0];
    ASSERT_EQ(column.size(), 3u);
    EXPECT_TRUE(std::isnan(column.get(0)));  // NaN, 1, NaN: NaN twice
    EXPECT_EQ(column.get(1), 2.0);           // 2, NaN: a tie goes to the number
    EXPECT_TRUE(std::isnan(column.get(2)));  // NaN alone
    // max ignores NaN where a number is there, whatever the order or chunking.
    const auto& high = tree->attributes().columns()[1];
    EXPECT_EQ(high.get(0), 1.0);
    EXPECT_EQ(high.get(1), 2.0);
    EXPECT_TRUE(std::isnan(high.get(2)));
    const auto& mean = tree->attributes().columns()[2];
    EXPECT_EQ(mean.get(0), 2.5);           // NaN, 1, 4: the mean of 1 and 4
    EXPECT_EQ(mean.get(1), 2.0);           // NaN, 2
    EXPECT_TRUE(std::isnan(mean.get(2)));  // no value at all
  }
}

// expect_points is a hint only: too small, right or absurdly large (the reservation is
// capped), the attribute columns and payloads come out the same as without it.
TEST(StreamBuilder, ExpectPointsIsOnlyAHint) {
  const Points p = random_points(7, 6000);
  vola::BuildOptions options;
  options.quantization = vola::Quantization::toolkit;
  options.depth = 3;
  options.payload = true;
  const vola::Tree expected = vola::build(p.cloud, options);
  for (const std::uint64_t hint : {std::uint64_t{0}, std::uint64_t{10}, std::uint64_t{6000}, ~std::uint64_t{0}}) {
    vola::BuildOptions resolved = options;
    vola::StreamBuilder builder(vola::resolve_quantizer(p.cloud.bounds(), resolved), p.specs, true);
    builder.expect_points(hint);
    for (std::size_t at = 0; at < p.cloud.size(); at += 1000) {
      std::vector<std::span<const double>> values;
      for (const auto& a : p.cloud.attributes) values.emplace_back(a.values.data() + at, 1000);
      builder.add({p.cloud.xyz.data() + 3 * at, 3000}, values, {p.cloud.payload.data() + at, 1000});
    }
    const vola::Tree got = builder.finish();
    ASSERT_EQ(std::vector<std::uint64_t>(got.words().begin(), got.words().end()),
              std::vector<std::uint64_t>(expected.words().begin(), expected.words().end()))
        << "hint " << hint;
    ASSERT_EQ(std::vector<std::uint64_t>(got.voxel_payloads().begin(), got.voxel_payloads().end()),
              std::vector<std::uint64_t>(expected.voxel_payloads().begin(), expected.voxel_payloads().end()));
    for (std::size_t c = 0; c < got.attributes().size(); ++c)
      for (std::size_t v = 0; v < got.attributes().columns()[c].size(); ++v) {
        const double g = got.attributes().columns()[c].get(v), e = expected.attributes().columns()[c].get(v);
        if (std::isnan(e))
          ASSERT_TRUE(std::isnan(g)) << "hint " << hint << " column " << c << " voxel " << v;
        else
          ASSERT_NEAR(g, e, 1e-9) << "hint " << hint << " column " << c << " voxel " << v;
      }
  }
}

// What a builder fed `keys` (in any order, with repeats) must finish as: the tree of
// their set.
void expect_tree_of_key_set(vola::StreamBuilder& builder, std::vector<vola::Key> keys, int depth) {
  std::sort(keys.begin(), keys.end());
  keys.erase(std::unique(keys.begin(), keys.end()), keys.end());
  const vola::Tree got = builder.finish();
  const vola::Tree want = vola::build_from_sorted_keys(keys, depth);
  EXPECT_EQ(std::vector<std::uint64_t>(got.words().begin(), got.words().end()),
            std::vector<std::uint64_t>(want.words().begin(), want.words().end()));
}

// add_keys (occupancy from keys: sort of the varying bits only, dedupe, union of runs)
// against the set of keys, for keys that share high bits, keys that differ in one bit,
// all-equal chunks, single keys and empty chunks, at every depth.
TEST(StreamBuilder, KeysEqualTheSetOfKeys) {
  std::mt19937_64 rng(5);
  for (int depth = 1; depth <= 10; ++depth) {
    SCOPED_TRACE("depth " + std::to_string(depth));
    const vola::Key limit = vola::Key{1} << (6 * depth);
    vola::StreamBuilder builder(vola::Quantizer::grid({0, 0, 0}, 1.0, depth), {}, false);
    std::vector<vola::Key> all;
    for (int chunk = 0; chunk < 40; ++chunk) {
      const std::size_t n = chunk % 7 == 0 ? chunk % 3 : 1 + rng() % 5000;
      const vola::Key high = rng() % limit;
      const int varying = static_cast<int>(rng() % (6 * depth + 1));  // bits that vary in this chunk
      std::vector<vola::Key> keys(n);
      for (auto& k : keys) {
        k = varying == 0 ? high : (high & ~((vola::Key{1} << varying) - 1)) | (rng() % (vola::Key{1} << varying));
        if (rng() % 4 == 0 && !all.empty()) k = all[rng() % all.size()];  // duplicates across chunks
      }
      all.insert(all.end(), keys.begin(), keys.end());
      builder.add_keys(keys, chunk % 5);
    }
    expect_tree_of_key_set(builder, all, depth);
    EXPECT_EQ(builder.points_outside(), 40u / 5 * (0 + 1 + 2 + 3 + 4));
  }
  vola::StreamBuilder builder(vola::Quantizer::grid({0, 0, 0}, 1.0, 2), {}, false);
  std::vector<vola::Key> too_large{vola::Key{1} << 12};
  EXPECT_THROW(builder.add_keys(too_large), vola::InvalidArgument);
  vola::StreamBuilder with_payload(vola::Quantizer::grid({0, 0, 0}, 1.0, 2), {}, true);
  std::vector<vola::Key> one{1};
  EXPECT_THROW(with_payload.add_keys(one), vola::InvalidArgument);
}

// Occupancy runs are leaf blocks with their voxel bits, united in place from the back
// when the older run has room: chunks that overlap all the others (a survey in random
// order), chunks above everything so far, below everything so far (every block moves),
// interleaved ones, and runs of one block, against the set of keys.
TEST(StreamBuilder, OccupancyUnionsInPlaceEqualTheSetOfKeys) {
  const int depth = 6;
  const vola::Key limit = vola::Key{1} << (6 * depth);
  for (int pattern = 0; pattern < 5; ++pattern) {
    SCOPED_TRACE("pattern " + std::to_string(pattern));
    std::mt19937_64 rng(100 + pattern);
    vola::StreamBuilder builder(vola::Quantizer::grid({0, 0, 0}, 1.0, depth), {}, false);
    std::vector<vola::Key> all;
    for (int chunk = 0; chunk < 60; ++chunk) {
      std::vector<vola::Key> keys(1 + rng() % 4000);
      for (std::size_t i = 0; i < keys.size(); ++i) {
        switch (pattern) {
          case 0: keys[i] = rng() % 20000; break;                                  // all chunks overlap
          case 1: keys[i] = vola::Key(chunk) * 100000 + rng() % 100000; break;    // ascending
          case 2: keys[i] = limit - 1 - vola::Key(chunk) * 100000 - rng() % 100000; break;  // descending
          case 3: keys[i] = (rng() % 500) * 4096 + vola::Key(chunk % 7) * 64 + rng() % 64; break;  // interleaved
          default: keys[i] = vola::Key(chunk % 3) * 64 + rng() % 8; break;         // one block per chunk
        }
      }
      all.insert(all.end(), keys.begin(), keys.end());
      builder.add_keys(keys);
    }
    expect_tree_of_key_set(builder, all, depth);
  }
}

// Occupancy from coordinates (add() without attributes or payloads) against vola::build.
TEST(StreamBuilder, OccupancyFromPointsEqualsBuild) {
  for (int depth = 1; depth <= 7; ++depth) {
    SCOPED_TRACE("depth " + std::to_string(depth));
    Points p = random_points(static_cast<std::uint64_t>(depth), 30000);
    p.cloud.attributes.clear();
    p.cloud.payload.clear();
    vola::BuildOptions options;
    options.quantization = vola::Quantization::toolkit;
    options.depth = depth;
    const vola::Tree expected = vola::build(p.cloud, options);
    vola::BuildOptions resolved = options;
    vola::StreamBuilder builder(vola::resolve_quantizer(p.cloud.bounds(), resolved), {}, false);
    std::mt19937_64 rng(depth);
    for (std::size_t at = 0; at < p.cloud.size();) {
      const std::size_t n = std::min<std::size_t>(p.cloud.size() - at, 1 + rng() % 5000);
      builder.add({p.cloud.xyz.data() + 3 * at, 3 * n}, {}, {});
      at += n;
    }
    const vola::Tree got = builder.finish();
    EXPECT_EQ(std::vector<std::uint64_t>(got.words().begin(), got.words().end()),
              std::vector<std::uint64_t>(expected.words().begin(), expected.words().end()));
  }
}

TEST(StreamBuilder, RefusesMismatchedArrays) {
  vola::StreamBuilder builder(vola::Quantizer::grid({0, 0, 0}, 1.0, 2), {{"a", vola::ValueType::u8, vola::Reduction::max}},
                              false);
  const std::vector<double> xyz{1, 1, 1, 2, 2, 2};
  const std::vector<double> one{1};
  std::vector<std::span<const double>> values{one};
  EXPECT_THROW(builder.add(xyz, values, {}), vola::InvalidArgument);
  EXPECT_THROW(builder.add(xyz, {}, {}), vola::InvalidArgument);
}

}  // namespace
