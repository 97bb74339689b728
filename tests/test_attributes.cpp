// Attribute columns: the per-voxel reductions of build() against a brute-force
// std::map reduction, and their way through the extension (plain and compressed).
#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <random>

#include <gtest/gtest.h>

#include "test_support.hpp"
#include "vola/attributes.hpp"
#include "vola/builder.hpp"
#include "vola/file.hpp"

namespace vola_test {
namespace {

struct AttributeSpec {
  const char* name;
  vola::ValueType type;
  vola::Reduction reduction;
  double lo, hi;   // value range
  bool integers;   // draw whole numbers
};

// Integer columns get integer or out-of-range values (rounding and clamping), the
// majority column few distinct values (ties).
const AttributeSpec kSpecs[] = {
    {"mean_f64", vola::ValueType::f64, vola::Reduction::mean, -1e3, 1e3, false},
    {"mean_u8", vola::ValueType::u8, vola::Reduction::mean, 0, 255, true},
    {"mean_i8_clamped", vola::ValueType::i8, vola::Reduction::mean, -500, 500, true},
    {"max_i32", vola::ValueType::i32, vola::Reduction::max, -1e6, 1e6, true},
    {"min_f32", vola::ValueType::f32, vola::Reduction::min, -1.0, 1.0, false},
    {"majority_u16", vola::ValueType::u16, vola::Reduction::majority, 0, 3, true},
    {"last_i16", vola::ValueType::i16, vola::Reduction::last, -30000, 30000, true},
    {"last_u64", vola::ValueType::u64, vola::Reduction::last, 0, 1e15, true},
};

double brute_reduce(const std::vector<double>& v, vola::Reduction r) {
  switch (r) {
    case vola::Reduction::last: return v.back();
    case vola::Reduction::mean: {
      double sum = 0;
      for (double x : v) sum += x;
      return sum / static_cast<double>(v.size());
    }
    case vola::Reduction::max: return *std::max_element(v.begin(), v.end());
    case vola::Reduction::min: return *std::min_element(v.begin(), v.end());
    case vola::Reduction::majority: {
      std::map<double, int> counts;
      for (double x : v) ++counts[x];
      double best = 0;
      int best_count = 0;
      for (const auto& [value, count] : counts)  // ascending: ties go to the smallest value
        if (count > best_count) best = value, best_count = count;
      return best;
    }
  }
  return 0;
}

// The value a column of `type` holds after storing `x`.
double stored(double x, vola::ValueType type) {
  auto clamp_round = [&](double lo, double hi) { return std::clamp(std::nearbyint(x), lo, hi); };
  switch (type) {
    case vola::ValueType::f64: return x;
    case vola::ValueType::f32: return static_cast<float>(x);
    case vola::ValueType::u8: return clamp_round(0, 255);
    case vola::ValueType::i8: return clamp_round(-128, 127);
    case vola::ValueType::u16: return clamp_round(0, 65535);
    case vola::ValueType::i16: return clamp_round(-32768, 32767);
    case vola::ValueType::u32: return clamp_round(0, 4294967295.0);
    case vola::ValueType::i32: return clamp_round(-2147483648.0, 2147483647.0);
    case vola::ValueType::u64: return clamp_round(0, 1.8e19);
    case vola::ValueType::i64: return clamp_round(-9.2e18, 9.2e18);
  }
  return x;
}

struct Fixture {
  vola::PointCloud cloud;
  std::map<Xyz, std::vector<std::size_t>> points_of;  // voxel -> point indices in input order
};

// Points on a unit grid (origin 0, depth 3), 1..6 points per voxel, input order shuffled.
Fixture make_fixture(std::uint64_t seed) {
  std::mt19937_64 rng(seed);
  Fixture f;
  std::vector<Xyz> voxels;
  for (const Xyz& v : random_voxels(rng, 3, Shape::clustered, 400))
    for (int k = 0, n = 1 + static_cast<int>(rng() % 6); k < n; ++k) voxels.push_back(v);
  std::shuffle(voxels.begin(), voxels.end(), rng);
  std::uniform_real_distribution<double> inside(0.05, 0.95);
  for (std::size_t i = 0; i < voxels.size(); ++i) {
    for (int a = 0; a < 3; ++a) f.cloud.xyz.push_back(voxels[i][a] + inside(rng));
    f.points_of[voxels[i]].push_back(i);
  }
  for (const auto& spec : kSpecs) {
    vola::PointAttribute a{spec.name, spec.type, spec.reduction, {}};
    std::uniform_real_distribution<double> value(spec.lo, spec.hi);
    for (std::size_t i = 0; i < voxels.size(); ++i)
      a.values.push_back(spec.integers ? std::round(value(rng)) : value(rng));
    f.cloud.attributes.push_back(std::move(a));
  }
  return f;
}

vola::BuildOptions unit_grid() {
  return {.quantization = vola::Quantization::grid, .depth = 3, .voxel_size = 1.0, .origin = vola::Point{0, 0, 0}};
}

void expect_columns_equal(const vola::Tree& a, const vola::Tree& b) {
  ASSERT_EQ(a.attributes().size(), b.attributes().size());
  for (const auto& column : a.attributes().columns()) {
    SCOPED_TRACE(column.name());
    const vola::AttributeColumn* other = b.attributes().find(column.name());
    ASSERT_NE(other, nullptr);
    EXPECT_EQ(other->type(), column.type());
    EXPECT_EQ(other->reduction(), column.reduction());
    ASSERT_EQ(other->size(), column.size());
    EXPECT_TRUE(std::equal(column.bytes().begin(), column.bytes().end(), other->bytes().begin(), other->bytes().end()));
  }
}

TEST(Attributes, BuildReducesEveryVoxelLikeABruteForceMap) {
  for (std::uint64_t seed : {1u, 2u, 3u}) {
    SCOPED_TRACE("seed " + std::to_string(seed));
    const Fixture f = make_fixture(seed);
    const vola::Tree tree = vola::build(f.cloud, unit_grid());
    ASSERT_EQ(tree.voxel_count(), f.points_of.size());
    ASSERT_EQ(tree.attributes().size(), std::size(kSpecs));
    for (std::size_t s = 0; s < std::size(kSpecs); ++s) {
      const auto& spec = kSpecs[s];
      SCOPED_TRACE(spec.name);
      const vola::AttributeColumn* column = tree.attributes().find(spec.name);
      ASSERT_NE(column, nullptr);
      EXPECT_EQ(column->type(), spec.type);
      EXPECT_EQ(column->reduction(), spec.reduction);
      EXPECT_EQ(column->size(), tree.voxel_count());
      for (const auto& [voxel, points] : f.points_of) {
        std::vector<double> values;
        for (std::size_t p : points) values.push_back(f.cloud.attributes[s].values[p]);
        const double expected = stored(brute_reduce(values, spec.reduction), spec.type);
        const auto rank = tree.rank(to_voxel(voxel));
        ASSERT_TRUE(rank.has_value());
        ASSERT_EQ(column->get(*rank), expected) << "voxel " << voxel[0] << " " << voxel[1] << " " << voxel[2]
                                                << " with " << points.size() << " points";
      }
    }
  }
}

TEST(Attributes, ValuesSurviveSerializeAndParse) {
  const Fixture f = make_fixture(4);
  const vola::Tree tree = vola::build(f.cloud, unit_grid());
  const vola::Tree back = vola::parse(vola::serialize(tree), "attributes");
  EXPECT_EQ(voxel_sequence(back), voxel_sequence(tree));
  expect_columns_equal(tree, back);
  // Dense files carry the same extension after their levels.
  const vola::Tree dense = vola::parse(vola::serialize(tree, {.layout = vola::Layout::dense}), "dense");
  expect_columns_equal(tree, dense);
}

TEST(Attributes, ValuesSurviveCompressionAndMapping) {
  const Fixture f = make_fixture(5);
  const vola::Tree tree = vola::build(f.cloud, unit_grid());
  TempDir dir;
  const auto plain = (dir / "plain.vol").string();
  vola::write(tree, plain);
  expect_columns_equal(tree, vola::open_mapped(plain));
  if (!vola::compression_available()) return;
  const auto packed = (dir / "packed.vol").string();
  vola::write(tree, packed, {.compress = true});
  EXPECT_LT(fs::file_size(packed), fs::file_size(plain));
  expect_columns_equal(tree, vola::open_mapped(packed));
}

TEST(Attributes, ColumnStoresRoundAndClampToTheType) {
  vola::AttributeColumn u8("u8", vola::ValueType::u8, vola::Reduction::mean, 4);
  u8.set(0, 300);
  u8.set(1, -5);
  u8.set(2, 2.5);  // half to even
  u8.set(3, std::numeric_limits<double>::quiet_NaN());
  EXPECT_EQ(u8.get(0), 255);
  EXPECT_EQ(u8.get(1), 0);
  EXPECT_EQ(u8.get(2), 2);
  EXPECT_EQ(u8.get(3), 0);
  vola::AttributeColumn i64("i64", vola::ValueType::i64, vola::Reduction::last, 2);
  i64.set(0, 1e30);
  i64.set(1, -1e30);
  EXPECT_EQ(i64.get(0), static_cast<double>(std::numeric_limits<std::int64_t>::max()));
  EXPECT_EQ(i64.get(1), static_cast<double>(std::numeric_limits<std::int64_t>::lowest()));
  vola::AttributeColumn f32("f32", vola::ValueType::f32, vola::Reduction::last, 1);
  f32.set(0, 0.1);
  EXPECT_EQ(f32.get(0), static_cast<double>(0.1f));
  EXPECT_EQ(f32.bytes().size(), 4u);
}

TEST(Attributes, NamesOfTypesAndReductionsRoundTrip) {
  for (int t = 0; t < 10; ++t) {
    const auto type = static_cast<vola::ValueType>(t);
    EXPECT_EQ(vola::parse_value_type(vola::name_of(type)), type);
  }
  EXPECT_EQ(vola::size_of(vola::ValueType::u16), 2u);
  EXPECT_EQ(vola::size_of(vola::ValueType::f64), 8u);
  for (int r = 0; r < 5; ++r) {
    const auto reduction = static_cast<vola::Reduction>(r);
    EXPECT_EQ(vola::parse_reduction(vola::name_of(reduction)), reduction);
  }
  EXPECT_FALSE(vola::parse_value_type("float").has_value());
  EXPECT_FALSE(vola::parse_reduction("median").has_value());
}

TEST(Attributes, NamesAreUnique) {
  vola::Attributes attributes;
  attributes.add(vola::AttributeColumn("a", vola::ValueType::u8, vola::Reduction::last));
  EXPECT_THROW(attributes.add(vola::AttributeColumn("a", vola::ValueType::f32, vola::Reduction::mean)),
               vola::InvalidArgument);
  EXPECT_NE(attributes.find("a"), nullptr);
  EXPECT_EQ(attributes.find("b"), nullptr);
  EXPECT_EQ(attributes.size(), 1u);
}

TEST(Attributes, TreesWithAttributesCarryAnExtensionEvenInToolkitMode) {
  vola::PointCloud cloud;
  cloud.xyz = {0, 0, 0, 3, 3, 3};
  cloud.attributes.push_back({"i", vola::ValueType::u8, vola::Reduction::last, {7, 9}});
  const vola::Tree tree = vola::build(cloud, {.depth = 1});
  const auto bytes = vola::serialize(tree);
  EXPECT_GT(bytes.size(), 80 + 8 * tree.words().size());
  const vola::Tree back = vola::parse(bytes);
  ASSERT_NE(back.attributes().find("i"), nullptr);
  EXPECT_EQ(back.attributes().find("i")->get(*back.rank({3, 3, 3})), 9);
}

}  // namespace
}  // namespace vola_test
