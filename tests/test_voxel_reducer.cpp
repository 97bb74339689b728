// VoxelReducer (points with their voxel's rank, reduced in place) against vola::build
// over the same points in the same order: bit-identical columns for every reduction,
// NaN rules included, however the points are split into calls.
#include <gtest/gtest.h>

#include <algorithm>
#include <bit>
#include <cstring>
#include <cmath>
#include <limits>
#include <random>

#include "vola/vola.hpp"
#include "vola/voxel_reducer.hpp"

namespace {

const double kNaN = std::numeric_limits<double>::quiet_NaN();

vola::PointCloud random_cloud(std::uint64_t seed, std::size_t n) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> coordinate(0.0, 20.0), any(-1e6, 1e6);
  std::uniform_int_distribution<int> small(0, 4), byte(0, 255);
  vola::PointCloud cloud;
  const std::vector<std::pair<vola::ValueType, vola::Reduction>> columns = {
      {vola::ValueType::f64, vola::Reduction::mean},     {vola::ValueType::f32, vola::Reduction::mean},
      {vola::ValueType::u16, vola::Reduction::max},      {vola::ValueType::i32, vola::Reduction::min},
      {vola::ValueType::u8, vola::Reduction::last},      {vola::ValueType::u8, vola::Reduction::majority},
      {vola::ValueType::f64, vola::Reduction::majority}, {vola::ValueType::f64, vola::Reduction::max}};
  for (std::size_t c = 0; c < columns.size(); ++c)
    cloud.attributes.push_back({std::string("a").append(std::to_string(c)), columns[c].first, columns[c].second, {}});
  for (std::size_t i = 0; i < n; ++i) {
    for (int a = 0; a < 3; ++a) cloud.xyz.push_back(coordinate(rng));
    const bool nan = rng() % 7 == 0;
    cloud.attributes[0].values.push_back(any(rng));  // means of large values: the order of summation shows
    cloud.attributes[1].values.push_back(nan ? kNaN : small(rng) * 0.1);  // a mean skips NaN
    cloud.attributes[2].values.push_back(byte(rng));
    cloud.attributes[3].values.push_back(small(rng) - 2);
    cloud.attributes[4].values.push_back(byte(rng));
    cloud.attributes[5].values.push_back(small(rng));
    cloud.attributes[6].values.push_back(nan ? kNaN : small(rng) == 0 ? -0.0 : small(rng));  // NaN, -0 and 0
    cloud.attributes[7].values.push_back(nan ? kNaN : any(rng));
  }
  return cloud;
}

// The reducer over `cloud` (ranks from a tree built on its coordinates, points split
// into calls of random sizes up to max_call) against vola::build: the same bytes.
// How the values reach the reducer: as double arrays (add), packed in records
// (add_records: each call's values as u8 or u16 fields where they are whole numbers
// that fit, doubles otherwise, through a shuffled index), or read in place from the
// cloud's arrays (add_columns).
enum class Feed { values, records, columns };

void feed_records(vola::VoxelReducer& reducer, const vola::PointCloud& cloud, std::size_t at, std::size_t n,
                  std::span<const std::uint64_t> ranks, std::mt19937_64& rng) {
  using Kind = vola::RecordField::Kind;
  std::vector<vola::RecordField> fields;
  std::uint32_t stride = 0;
  for (const auto& a : cloud.attributes) {
    double hi = 0.0;
    bool whole = true;
    for (std::size_t i = at; i < at + n; ++i) {
      const double v = a.values[i];
      whole = whole && v >= 0.0 && v <= 65535.0 && v == std::floor(v);
      hi = std::max(hi, v);
    }
    const Kind kind = !whole ? Kind::f64 : hi <= 255.0 && rng() % 2 ? Kind::u8 : Kind::u16;
    fields.push_back({.kind = kind, .offset = stride, .scaled = false});
    stride += kind == Kind::f64 ? 8 : kind == Kind::u16 ? 2 : 1;
  }
  // Record j holds point order[j]; index[i] = j finds point i again.
  std::vector<std::uint32_t> order(n), index(n);
  for (std::size_t i = 0; i < n; ++i) order[i] = static_cast<std::uint32_t>(i);
  std::shuffle(order.begin(), order.end(), rng);
  std::vector<std::uint8_t> records(n * stride + 1);
  for (std::size_t j = 0; j < n; ++j) {
    index[order[j]] = static_cast<std::uint32_t>(j);
    for (std::size_t a = 0; a < fields.size(); ++a) {
      const double v = cloud.attributes[a].values[at + order[j]];
      std::uint8_t* p = records.data() + j * stride + fields[a].offset;
      if (fields[a].kind == Kind::u8) *p = static_cast<std::uint8_t>(v);
      else if (fields[a].kind == Kind::u16) {
        const auto x = static_cast<std::uint16_t>(v);
        std::memcpy(p, &x, 2);
      } else {
        std::memcpy(p, &v, 8);
      }
    }
  }
  reducer.add_records(ranks, records.data(), stride, index, fields);
}

void expect_reducer_equals_build(const vola::PointCloud& cloud, const vola::BuildOptions& options, std::uint64_t seed,
                                 std::size_t max_call = 2000, Feed feed = Feed::values) {
  const vola::Tree expected = vola::build(cloud, options);
  vola::PointCloud xyz_only;
  xyz_only.xyz = cloud.xyz;
  vola::Tree got = vola::build(xyz_only, options);
  std::vector<vola::AttributeSpec> specs;
  for (const auto& a : cloud.attributes) specs.push_back({a.name, a.type, a.reduction});
  vola::VoxelReducer reducer(specs, got.voxel_count());
  const vola::Quantizer quantizer = vola::Quantizer::grid(got.frame().origin, got.frame().voxel_size, got.depth());
  std::mt19937_64 rng(seed + 5);
  for (std::size_t at = 0; at < cloud.size();) {
    const std::size_t n = std::min<std::size_t>(cloud.size() - at, 1 + rng() % max_call);
    std::vector<std::uint64_t> ranks;
    for (std::size_t i = at; i < at + n; ++i) {
      vola::Voxel v;
      ASSERT_TRUE(quantizer.to_voxel({cloud.xyz[3 * i], cloud.xyz[3 * i + 1], cloud.xyz[3 * i + 2]}, v));
      ranks.push_back(*got.rank(v));
    }
    if (feed == Feed::records) {
      feed_records(reducer, cloud, at, n, ranks, rng);
    } else if (feed == Feed::columns) {
      std::vector<vola::FieldColumn> columns;
      for (const auto& a : cloud.attributes)
        columns.push_back({reinterpret_cast<const std::uint8_t*>(a.values.data() + at), sizeof(double),
                           {.kind = vola::RecordField::Kind::f64, .scaled = false}});
      reducer.add_columns(ranks, columns);
    } else {
      std::vector<std::span<const double>> values;
      for (const auto& a : cloud.attributes) values.emplace_back(a.values.data() + at, n);
      reducer.add(ranks, values);
    }
    at += n;
  }
  reducer.finish_into(got);
  ASSERT_EQ(got.attributes().size(), expected.attributes().size());
  for (std::size_t c = 0; c < got.attributes().size(); ++c) {
    const auto& g = got.attributes().columns()[c];
    const auto& e = expected.attributes().columns()[c];
    ASSERT_EQ(g.type(), e.type());
    ASSERT_EQ(g.reduction(), e.reduction());
    ASSERT_TRUE(std::equal(g.bytes().begin(), g.bytes().end(), e.bytes().begin(), e.bytes().end()))
        << "column " << c << " " << g.name() << " (" << vola::name_of(e.reduction()) << ")";
  }
}

class VoxelReducerEqualsBuild : public ::testing::TestWithParam<int> {};

TEST_P(VoxelReducerEqualsBuild, BitForBit) {
  const auto seed = static_cast<std::uint64_t>(GetParam());
  const vola::PointCloud cloud = random_cloud(seed, 30000);
  vola::BuildOptions options;
  options.quantization = vola::Quantization::grid;
  options.voxel_size = 1.0 + static_cast<double>(seed % 3);  // 1..3: tens to hundreds of points a voxel
  expect_reducer_equals_build(cloud, options, seed);
}

INSTANTIATE_TEST_SUITE_P(Seeds, VoxelReducerEqualsBuild, ::testing::Range(1, 7));

// A record field's decoding: shift and mask of the unsigned kinds, x * scale + add
// (as a LAS reader decodes), signed and floating kinds; -0 kept when not scaled.
TEST(VoxelReducer, RecordFieldsDecodeLikeTheValues) {
  using Kind = vola::RecordField::Kind;
  const std::vector<vola::AttributeSpec> specs = {{"returns", vola::ValueType::u8, vola::Reduction::max},
                                                  {"z", vola::ValueType::f64, vola::Reduction::mean},
                                                  {"s", vola::ValueType::f64, vola::Reduction::last},
                                                  {"f", vola::ValueType::f32, vola::Reduction::majority}};
  const std::vector<vola::RecordField> fields = {{.kind = Kind::u8, .offset = 0, .shift = 3, .mask = 7},
                                                 {.kind = Kind::i32, .offset = 1, .scale = 0.001, .add = 1234.5},
                                                 {.kind = Kind::i16, .offset = 5},
                                                 {.kind = Kind::f32, .offset = 7, .scaled = false}};
  std::mt19937_64 rng(11);
  const std::size_t n = 5000, stride = 11;
  std::vector<std::uint8_t> records(n * stride);
  std::vector<std::uint64_t> ranks(n);
  std::vector<std::vector<double>> values(4, std::vector<double>(n));
  for (std::size_t i = 0; i < n; ++i) {
    std::uint8_t* r = records.data() + i * stride;
    r[0] = static_cast<std::uint8_t>(rng());
    const auto z = static_cast<std::int32_t>(rng());
    const auto s16 = static_cast<std::int16_t>(rng());
    const float f = i % 5 == 0 ? -0.0f : static_cast<float>(rng() % 4) * 0.5f;
    std::memcpy(r + 1, &z, 4);
    std::memcpy(r + 5, &s16, 2);
    std::memcpy(r + 7, &f, 4);
    ranks[i] = rng() % 700;
    values[0][i] = (r[0] >> 3) & 7;
    values[1][i] = static_cast<double>(z) * 0.001 + 1234.5;
    values[2][i] = static_cast<double>(s16) * 1.0 + 0.0;
    values[3][i] = f;
  }
  vola::VoxelReducer by_values(specs, 700), by_records(specs, 700);
  const std::vector<std::span<const double>> views(values.begin(), values.end());
  by_values.add(ranks, views);
  by_records.add_records(ranks, records.data(), stride, {}, fields);
  const auto expected = by_values.finish(), got = by_records.finish();
  for (std::size_t a = 0; a < specs.size(); ++a)
    EXPECT_TRUE(std::equal(got[a].bytes().begin(), got[a].bytes().end(), expected[a].bytes().begin(),
                           expected[a].bytes().end()))
        << specs[a].name;
}

TEST(VoxelReducer, RefusesRanksOutOfRangeAndMismatchedArrays) {
  vola::VoxelReducer reducer({{"m", vola::ValueType::f32, vola::Reduction::mean}}, 3);
  const std::vector<double> values{1.0, 2.0};
  const std::vector<std::span<const double>> columns{values};
  const std::vector<std::uint64_t> bad{0, 3}, short_ranks{0};
  EXPECT_THROW(reducer.add(bad, columns), vola::InvalidArgument);
  EXPECT_THROW(reducer.add(short_ranks, columns), vola::InvalidArgument);
  EXPECT_THROW(reducer.add(std::span<const std::uint64_t>(bad.data(), 1), {}), vola::InvalidArgument);
}

// A voxel no point reached reads 0 in every column (never NaN from an empty max).
TEST(VoxelReducer, UnreachedVoxelsAreZero) {
  vola::VoxelReducer reducer({{"hi", vola::ValueType::f64, vola::Reduction::max},
                              {"m", vola::ValueType::f64, vola::Reduction::mean},
                              {"c", vola::ValueType::f64, vola::Reduction::majority}},
                             2);
  reducer.add(1, std::vector<double>{5.0, 4.0, 3.0});
  const auto columns = reducer.finish();
  for (const auto& c : columns) EXPECT_EQ(c.get(0), 0.0) << c.name();
  EXPECT_EQ(columns[0].get(1), 5.0);
  EXPECT_EQ(columns[1].get(1), 4.0);
  EXPECT_EQ(columns[2].get(1), 3.0);
}

// finish_range over ranges of random sizes, into the caller's columns, gives finish()'s
// bytes (majority's other values included); ranges out of order and points added after
// are refused.
TEST(VoxelReducer, FinishInRangesEqualsFinish) {
  const vola::PointCloud cloud = random_cloud(9, 20000);
  vola::BuildOptions options;
  options.quantization = vola::Quantization::grid;
  options.voxel_size = 1.0;
  vola::PointCloud xyz_only;
  xyz_only.xyz = cloud.xyz;
  const vola::Tree tree = vola::build(xyz_only, options);
  const vola::Quantizer quantizer = vola::Quantizer::grid(tree.frame().origin, tree.frame().voxel_size, tree.depth());
  std::vector<vola::AttributeSpec> specs;
  for (const auto& a : cloud.attributes) specs.push_back({a.name, a.type, a.reduction});
  std::vector<std::uint64_t> ranks;
  for (std::size_t i = 0; i < cloud.size(); ++i) {
    vola::Voxel v;
    ASSERT_TRUE(quantizer.to_voxel({cloud.xyz[3 * i], cloud.xyz[3 * i + 1], cloud.xyz[3 * i + 2]}, v));
    ranks.push_back(*tree.rank(v));
  }
  std::vector<std::span<const double>> values;
  for (const auto& a : cloud.attributes) values.emplace_back(a.values);
  vola::VoxelReducer whole(specs, tree.voxel_count()), ranged(specs, tree.voxel_count());
  whole.add(ranks, values);
  ranged.add(ranks, values);
  const std::vector<vola::AttributeColumn> want = whole.finish();
  std::vector<std::vector<std::byte>> got(specs.size());
  for (std::size_t a = 0; a < specs.size(); ++a) got[a].resize(tree.voxel_count() * vola::size_of(specs[a].type));
  std::mt19937_64 rng(3);
  std::vector<std::byte*> to(specs.size());
  for (std::uint64_t first = 0; first < tree.voxel_count();) {
    const std::uint64_t last = std::min<std::uint64_t>(tree.voxel_count(), first + rng() % 700);
    for (std::size_t a = 0; a < specs.size(); ++a) to[a] = got[a].data() + first * vola::size_of(specs[a].type);
    ranged.finish_range(first, last, to);
    if (first > 0) {
      EXPECT_THROW(ranged.finish_range(first - 1, last, to), vola::InvalidArgument);
    }
    first = last;
  }
  EXPECT_THROW(ranged.add(std::span<const std::uint64_t>(ranks.data(), 1),
                          std::vector<std::span<const double>>(values.size(), std::span<const double>(values[0].data(), 1))),
               vola::InvalidArgument);
  ASSERT_EQ(want.size(), specs.size());
  for (std::size_t a = 0; a < specs.size(); ++a)
    EXPECT_TRUE(std::equal(got[a].begin(), got[a].end(), want[a].bytes().begin(), want[a].bytes().end())) << specs[a].name;
}

}  // namespace

namespace {

// Integer columns of every reduction whose values fit the narrow slots, the same points
// in `voxels` voxels of a 2x2x2 grid.
vola::PointCloud narrow_cloud(std::size_t n, std::uint64_t seed, double value_hi) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> coordinate(0.0, 2.0);
  std::uniform_int_distribution<int> value(0, static_cast<int>(value_hi));
  vola::PointCloud cloud;
  const std::vector<std::pair<vola::ValueType, vola::Reduction>> columns = {
      {vola::ValueType::u16, vola::Reduction::mean},     {vola::ValueType::u8, vola::Reduction::mean},
      {vola::ValueType::u16, vola::Reduction::max},      {vola::ValueType::u8, vola::Reduction::min},
      {vola::ValueType::u16, vola::Reduction::last},     {vola::ValueType::u8, vola::Reduction::majority},
      {vola::ValueType::u16, vola::Reduction::majority}, {vola::ValueType::i32, vola::Reduction::mean}};
  for (std::size_t c = 0; c < columns.size(); ++c)
    cloud.attributes.push_back({std::string("n").append(std::to_string(c)), columns[c].first, columns[c].second, {}});
  for (std::size_t i = 0; i < n; ++i) {
    for (int a = 0; a < 3; ++a) cloud.xyz.push_back(coordinate(rng));
    for (auto& a : cloud.attributes) {
      const double hi = a.type == vola::ValueType::u8 ? std::min(value_hi, 255.0) : value_hi;
      a.values.push_back(std::min<double>(value(rng), hi));
    }
  }
  return cloud;
}

vola::BuildOptions unit_grid() {
  vola::BuildOptions options;
  options.quantization = vola::Quantization::grid;
  options.voxel_size = 1.0;
  return options;
}

}  // namespace

// Means of 16-bit values keep 32-bit sums: 70000 points of 65535 in each of 8 voxels
// carry past 2^32 (the carry table), and the count passes 65536.
TEST(VoxelReducer, IntegerSumsCarryPastThirtyTwoBits) {
  vola::PointCloud cloud = narrow_cloud(8 * 70000, 3, 65535);
  for (auto& a : cloud.attributes)
    if (a.reduction == vola::Reduction::mean) std::fill(a.values.begin(), a.values.end(), a.type == vola::ValueType::u8 ? 255.0 : 65535.0);
  cloud.attributes[0].values[12345] = 1.0;  // a mean that is not a whole number
  expect_reducer_equals_build(cloud, unit_grid(), 3, 50000);
}

// The same for an f64 mean column of whole numbers (a double sum, no narrow slot) and
// for a u16 mean whose exact mean is a fraction: only the stored value is rounded.
TEST(VoxelReducer, IntegerSumEqualsTheDoubleSum) {
  vola::VoxelReducer narrow({{"m", vola::ValueType::u32, vola::Reduction::mean}}, 1);
  vola::VoxelReducer wide({{"m", vola::ValueType::f64, vola::Reduction::mean}}, 1);
  std::vector<std::uint64_t> ranks(70001, 0);
  std::vector<double> values(70001, 65535.0);
  values[0] = 2.0;
  const std::vector<std::span<const double>> columns{values};
  narrow.add(ranks, columns);
  wide.add(ranks, columns);
  const double exact = (70000.0 * 65535.0 + 2.0) / 70001.0;
  EXPECT_EQ(wide.finish()[0].get(0), exact);
  EXPECT_EQ(narrow.finish()[0].get(0), std::nearbyint(exact));
}

// Values that stop fitting the narrow slots part-way (a fraction, a negative number, a
// value past 255 in a u8 column, NaN): the attribute widens to doubles holding the
// partials so far, and the result is still build's.
TEST(VoxelReducer, NarrowSlotsWidenWhenAValueDoesNotFit) {
  for (const double odd : {2.5, -3.0, 300.0, 70000.0, kNaN}) {
    SCOPED_TRACE(odd);
    vola::PointCloud cloud = narrow_cloud(20000, 4, 200);
    for (auto& a : cloud.attributes) {
      a.values[9000] = odd;
      a.values[15000] = odd;
    }
    expect_reducer_equals_build(cloud, unit_grid(), 4, 3000);
  }
}

// A mean is over the points with a value: NaN (a LAS no_data) is skipped, and a voxel
// with no value at all is NaN, whether the values come as doubles or as record fields
// with a no_data value, and whenever the first NaN comes (the slots widen to count them).
TEST(VoxelReducer, MeansSkipPointsWithoutAValue) {
  // Voxels of rank 0, 1, 2: {1, no data, 4, no data, 7}, {no data, no data}, {2}.
  const std::vector<std::uint64_t> ranks = {0, 0, 1, 0, 2, 0, 1, 0};
  const std::vector<std::int32_t> stored = {1, -9999, -9999, 4, 2, -9999, -9999, 7};
  std::vector<double> values;
  for (const std::int32_t x : stored) values.push_back(x == -9999 ? kNaN : x);
  const std::vector<vola::AttributeSpec> specs = {{"mean_u16", vola::ValueType::u16, vola::Reduction::mean},
                                                  {"mean_f64", vola::ValueType::f64, vola::Reduction::mean}};
  const auto expect_means = [](const std::vector<vola::AttributeColumn>& columns) {
    for (const auto& column : columns) {
      SCOPED_TRACE(column.name());
      EXPECT_EQ(column.get(0), 4.0);
      EXPECT_EQ(column.get(2), 2.0);
      if (column.type() == vola::ValueType::f64)
        EXPECT_TRUE(std::isnan(column.get(1)));
      else
        EXPECT_EQ(column.get(1), 0.0);  // an integer column stores NaN as 0
    }
  };
  for (const std::size_t split : {std::size_t{0}, std::size_t{1}, std::size_t{4}}) {
    SCOPED_TRACE(split);
    vola::VoxelReducer as_values(specs, 3);
    const std::span<const std::uint64_t> r(ranks);
    const std::span<const double> v(values);
    const std::vector<std::span<const double>> first{v.first(split), v.first(split)};
    const std::vector<std::span<const double>> rest{v.subspan(split), v.subspan(split)};
    as_values.add(r.first(split), first);
    as_values.add(r.subspan(split), rest);
    expect_means(as_values.finish());

    // The same as an int32 field whose no_data is -9999 (after a whole-number field).
    vola::VoxelReducer as_records(specs, 3);
    const vola::RecordField field{.kind = vola::RecordField::Kind::i32, .has_no_data = true, .no_data = -9999};
    const std::vector<vola::RecordField> fields{field, field};
    const auto* bytes = reinterpret_cast<const std::uint8_t*>(stored.data());
    const std::vector<std::uint32_t> index = {0, 1, 2, 3, 4, 5, 6, 7};
    const std::span<const std::uint32_t> at(index);
    as_records.add_records(r.first(split), bytes, 4, at.first(split), fields);
    as_records.add_records(r.subspan(split), bytes, 4, at.subspan(split), fields);
    expect_means(as_records.finish());
  }
}

// Narrow slots with thousands of points per voxel and many distinct values: majority
// counts (first value's count derived from the voxel's), max/min/last.
TEST(VoxelReducer, NarrowSlotsEqualBuild) {
  for (const double hi : {3.0, 255.0, 65535.0}) {
    SCOPED_TRACE(hi);
    expect_reducer_equals_build(narrow_cloud(40000, 5, hi), unit_grid(), 5);
  }
}

// Values read from packed records or from columns in place give build's bytes too:
// whole-number fields folded as integers, the others (fractions, negative numbers, NaN,
// -0) decoded, narrow slots widened when a field's values do not fit them.
TEST(VoxelReducer, RecordsAndColumnsEqualBuild) {
  for (const Feed feed : {Feed::records, Feed::columns}) {
    SCOPED_TRACE(static_cast<int>(feed));
    for (std::uint64_t seed = 1; seed <= 3; ++seed) {
      vola::BuildOptions options;
      options.quantization = vola::Quantization::grid;
      options.voxel_size = 1.0 + static_cast<double>(seed % 3);
      expect_reducer_equals_build(random_cloud(seed, 20000), options, seed, 2000, feed);
    }
    for (const double hi : {3.0, 255.0, 65535.0}) expect_reducer_equals_build(narrow_cloud(30000, 5, hi), unit_grid(), 5, 2000, feed);
    for (const double odd : {2.5, -3.0, 300.0, 70000.0, kNaN}) {
      vola::PointCloud cloud = narrow_cloud(20000, 4, 200);
      for (auto& a : cloud.attributes) {
        a.values[9000] = odd;
        a.values[15000] = odd;
      }
      expect_reducer_equals_build(cloud, unit_grid(), 4, 3000, feed);
    }
  }
}
