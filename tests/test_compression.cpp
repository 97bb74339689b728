// Compressed files (--compress, --compress-max): the context-coded occupancy levels (levels flags 3; 4 with mixed models) and
// the predicted attribute encodings (2 delta planes, 3 quantized floats, 4 delta planes
// against an earlier column) round-trip bit
// for bit on random trees and every value type, NaN payloads, infinities and -0.0
// included; corrupt and cut compressed records are FormatErrors, never a crash; a lying
// size is refused before anything is allocated.
#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>
#include <map>
#include <random>
#include <string>
#include <utility>
#include <vector>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "allocation_probe.hpp"
#include "test_support.hpp"
#include "vola/builder.hpp"
#include "vola/file.hpp"

namespace vola_test {
namespace {

using ::testing::HasSubstr;

std::vector<vola::Voxel> to_voxels(const XyzSet& set) {
  std::vector<vola::Voxel> out;
  for (const Xyz& v : set) out.push_back(to_voxel(v));
  return out;
}

template <class T>
void put(vola::AttributeColumn& column, std::size_t i, T value) {
  std::memcpy(column.bytes().data() + i * sizeof(T), &value, sizeof(T));
}

// Every value type: random bit patterns (NaNs with payloads among the floats), and for
// floats also values that are integers times 0.01 near each voxel's z (what a LAS height
// looks like) mixed with values that are not, and the special values.
void add_columns(vola::Tree& tree, std::mt19937_64& rng) {
  const std::size_t n = tree.voxel_count();
  const vola::Frame frame = tree.frame();
  std::vector<vola::Voxel> voxels;
  tree.for_each_voxel([&](const vola::Voxel& v) { voxels.push_back(v); });
  for (int t = 0; t <= 9; ++t) {
    const auto type = static_cast<vola::ValueType>(t);
    vola::AttributeColumn random("random_" + std::string(vola::name_of(type)), type, vola::Reduction::mean, n);
    for (auto& b : random.bytes()) b = static_cast<std::byte>(rng());
    tree.attributes().add(std::move(random));
    vola::AttributeColumn smooth("smooth_" + std::string(vola::name_of(type)), type, vola::Reduction::last, n);
    for (std::size_t i = 0; i < n; ++i) smooth.set(i, static_cast<double>(100 + (i % 7) + (rng() % 3)));
    tree.attributes().add(std::move(smooth));
  }
  const double specials[] = {std::numeric_limits<double>::quiet_NaN(), std::numeric_limits<double>::infinity(),
                             -std::numeric_limits<double>::infinity(), -0.0, 0.0,
                             std::numeric_limits<double>::denorm_min(), std::numeric_limits<double>::max(),
                             -std::numeric_limits<double>::max(), 1e300, 0.005};
  vola::AttributeColumn h32("height32", vola::ValueType::f32, vola::Reduction::mean, n);
  vola::AttributeColumn h64("height64", vola::ValueType::f64, vola::Reduction::mean, n);
  for (std::size_t i = 0; i < n; ++i) {
    const double corner = frame.origin[2] + voxels[i].z * frame.voxel_size;
    double v = std::round((corner + frame.voxel_size * static_cast<double>(rng() % 100) / 100.0) * 100.0) / 100.0;
    if (rng() % 17 == 0) v += 0.001234;                  // not an integer times 0.01
    if (rng() % 23 == 0) v = specials[rng() % 10];       // the special values
    put(h32, i, static_cast<float>(v));
    put(h64, i, v);
    if (rng() % 31 == 0) {  // a NaN with a payload and a sign
      const std::uint32_t nan32 = 0xFFC00000u | static_cast<std::uint32_t>(rng() & 0x3FFFFF);
      const std::uint64_t nan64 = 0x7FF8000000000000ull | (rng() & 0x7FFFFFFFFFFFFull);
      std::memcpy(h32.bytes().data() + 4 * i, &nan32, 4);
      std::memcpy(h64.bytes().data() + 8 * i, &nan64, 8);
    }
  }
  tree.attributes().add(std::move(h32));
  tree.attributes().add(std::move(h64));
}

void expect_same(const vola::Tree& a, const vola::Tree& b) {
  ASSERT_EQ(a.depth(), b.depth());
  ASSERT_TRUE(std::equal(a.words().begin(), a.words().end(), b.words().begin(), b.words().end()));
  ASSERT_EQ(a.attributes().size(), b.attributes().size());
  for (const auto& column : a.attributes().columns()) {
    const auto* other = b.attributes().find(column.name());
    ASSERT_NE(other, nullptr) << column.name();
    EXPECT_EQ(other->type(), column.type());
    EXPECT_EQ(other->reduction(), column.reduction());
    ASSERT_EQ(other->bytes().size(), column.bytes().size()) << column.name();
    EXPECT_EQ(std::memcmp(other->bytes().data(), column.bytes().data(), column.bytes().size()), 0) << column.name();
  }
}

// The attribute records' encodings, in record order (walking the extension of a
// version-2 file from byte 80).
std::map<std::string, int> attribute_encodings(const std::vector<std::uint8_t>& bytes) {
  std::map<std::string, int> out;
  const auto records = get_le<std::uint32_t>(bytes, 92);
  std::size_t at = 96;
  for (std::uint32_t r = 0; r < records; ++r) {
    const auto tag = get_le<std::uint32_t>(bytes, at);
    const auto length = get_le<std::uint64_t>(bytes, at + 8);
    if (tag == 3) {
      const auto name_length = get_le<std::uint32_t>(bytes, at + 20);
      out[std::string(bytes.begin() + static_cast<std::ptrdiff_t>(at + 32),
                      bytes.begin() + static_cast<std::ptrdiff_t>(at + 32 + name_length))] = bytes[at + 18];
    }
    at += 16 + ((length + 7) / 8) * 8;
  }
  return out;
}

// The flags of the levels record (tag 4) of a version-2 file, walking its extension.
std::uint32_t levels_flags(const std::vector<std::uint8_t>& bytes) {
  const auto records = get_le<std::uint32_t>(bytes, 92);
  std::size_t at = 96;
  for (std::uint32_t r = 0; r < records; ++r) {
    if (get_le<std::uint32_t>(bytes, at) == 4) return get_le<std::uint32_t>(bytes, at + 4);
    at += 16 + ((get_le<std::uint64_t>(bytes, at + 8) + 7) / 8) * 8;
  }
  return 0;
}

TEST(Compression, LevelsRoundTripOnRandomTrees) {
  if (!vola::compression_available()) GTEST_SKIP() << "built without zstd";
  for (bool mixed : {false, true})
    for (Shape shape : kAllShapes)
      for (std::uint64_t seed : seeds_for(shape, 1)) {
        const Scenario s = make_scenario(seed);
        SCOPED_TRACE(s.describe() + (mixed ? ", mixed models" : ", one context per bit"));
        const vola::Tree tree = vola::build_from_voxels(to_voxels(s.unique()), s.depth);
        vola::FileLayout layout;
        const auto bytes = vola::serialize(tree, {.compress = true, .mix_occupancy_models = mixed});
        EXPECT_EQ(levels_flags(bytes), mixed ? 4u : 3u);
        const vola::Tree back = vola::parse(bytes, "random", &layout);
        EXPECT_TRUE(layout.compressed_levels);
        expect_same(tree, back);
      }
}

// The mixed models code a surface (a rolling height field sampled sparsely, as an
// airborne survey is) in fewer bytes than one context per bit.
TEST(Compression, MixedOccupancyModelsAreSmallerOnASampledSurface) {
  if (!vola::compression_available()) GTEST_SKIP() << "built without zstd";
  std::mt19937_64 rng(11);
  std::vector<vola::Voxel> voxels;
  for (std::uint32_t x = 0; x < 400; ++x)
    for (std::uint32_t y = 0; y < 400; ++y)
      if (rng() % 5 == 0) {
        const double z = 60 + 20 * std::sin(x / 40.0) * std::cos(y / 55.0) + static_cast<double>(rng() % 3);
        voxels.push_back({x, y, static_cast<std::uint32_t>(z)});
      }
  const vola::Tree tree = vola::build_from_voxels(voxels, 5);
  const auto contexts = vola::serialize(tree, {.compress = true});
  const auto mixed = vola::serialize(tree, {.compress = true, .mix_occupancy_models = true});
  expect_same(tree, vola::parse(mixed, "mixed"));
  EXPECT_LT(mixed.size(), contexts.size() * 95 / 100) << mixed.size() << " against " << contexts.size();
}

TEST(Compression, LevelsWithPayloadRoundTrip) {
  if (!vola::compression_available()) GTEST_SKIP() << "built without zstd";
  std::mt19937_64 rng(7);
  for (int depth : {1, 2, 3, 5}) {
    vola::PointCloud cloud;
    for (int i = 0; i < 3000; ++i) {
      for (int a = 0; a < 3; ++a) cloud.xyz.push_back(static_cast<double>(rng() % 10000) / 100.0);
      cloud.payload.push_back(rng() % 256);
    }
    const vola::Tree tree = vola::build(cloud, {.depth = depth, .payload = true});
    ASSERT_TRUE(tree.has_payload());
    const vola::Tree back = vola::parse(vola::serialize(tree, {.compress = true}), "payload");
    expect_same(tree, back);
    EXPECT_TRUE(back.has_payload());
  }
}

TEST(Compression, EveryColumnTypeRoundTripsBitForBit) {
  if (!vola::compression_available()) GTEST_SKIP() << "built without zstd";
  std::mt19937_64 rng(11);
  for (std::uint64_t seed : seeds_for(Shape::clustered, 1)) {
    const Scenario s = make_scenario(seed);
    SCOPED_TRACE(s.describe());
    vola::Tree tree = vola::build_from_voxels(to_voxels(s.unique()), s.depth);
    add_columns(tree, rng);
    const auto bytes = vola::serialize(tree, {.compress = true});
    expect_same(tree, vola::parse(bytes, "columns"));
    if (tree.voxel_count() > 200) {
      const auto encodings = attribute_encodings(bytes);
      EXPECT_EQ(encodings.at("height32"), 3) << "quantized floats";
      EXPECT_EQ(encodings.at("height64"), 3) << "quantized floats";
      EXPECT_EQ(encodings.at("smooth_u16"), 2) << "delta planes";
    }
  }
}

TEST(Compression, FilesReadMappedAndReadAlike) {
  if (!vola::compression_available()) GTEST_SKIP() << "built without zstd";
  std::mt19937_64 rng(5);
  const Scenario s = make_scenario(seeds_for(Shape::slab, 1)[5]);
  vola::Tree tree = vola::build_from_voxels(to_voxels(s.unique()), s.depth);
  add_columns(tree, rng);
  const TempDir dir;
  const std::string packed = (dir.path() / "packed.vol").string(), plain = (dir.path() / "plain.vol").string();
  vola::write(tree, packed, {.compress = true});
  vola::write(tree, plain);
  expect_same(tree, vola::read(packed));
  expect_same(tree, vola::open_mapped(packed));
  // An uncompressed file is still used in place: its levels are the mapping's bytes.
  const vola::Tree mapped = vola::open_mapped(plain);
  EXPECT_TRUE(mapped.is_mapped());
  const auto file = read_bytes(plain);
  const auto* words = reinterpret_cast<const std::uint8_t*>(mapped.words().data());
  EXPECT_EQ(std::memcmp(words, file.data() + 80, 8 * mapped.words().size()), 0);
  EXPECT_NE(static_cast<const void*>(words), static_cast<const void*>(file.data() + 80));
  expect_same(tree, mapped);
}

// Every cut and (sampled) every changed byte of a compressed file: a FormatError, never
// a crash or another exception; with the checksum resealed the decoders themselves see
// the damage (then the file may also read, as some other tree).
void expect_damage_refused(bool mixed, std::size_t samples) {
  std::mt19937_64 rng(3);
  const Scenario s = make_scenario(seeds_for(Shape::clustered, 1)[4]);
  vola::Tree tree = vola::build_from_voxels(to_voxels(s.unique()), s.depth);
  add_columns(tree, rng);
  const auto bytes = vola::serialize(tree, {.compress = true, .mix_occupancy_models = mixed});
  for (std::size_t cut = 0; cut < bytes.size(); cut += 1 + bytes.size() / (samples / 2)) {
    const std::vector<std::uint8_t> part(bytes.begin(), bytes.begin() + static_cast<std::ptrdiff_t>(cut));
    EXPECT_THROW((void)vola::parse(part, "cut"), vola::FormatError) << "cut at " << cut;
  }
  std::size_t refused = 0, read = 0;
  for (std::size_t at = 80; at + 16 < bytes.size(); at += 1 + bytes.size() / samples) {
    auto changed = bytes;
    changed[at] ^= static_cast<std::uint8_t>(1u << (at % 8));
    EXPECT_THROW((void)vola::parse(changed, "flipped"), vola::FormatError) << "byte " << at;
    reseal_extension(changed, 80);
    try {
      (void)vola::parse(changed, "resealed");
      ++read;
    } catch (const vola::FormatError&) {
      ++refused;
    }
  }
  EXPECT_GT(refused, 0u);
  ::testing::Test::RecordProperty(mixed ? "mixed_resealed_refused" : "resealed_refused", static_cast<int>(refused));
  ::testing::Test::RecordProperty(mixed ? "mixed_resealed_read" : "resealed_read", static_cast<int>(read));
}

TEST(Compression, CorruptAndCutRecordsAreFormatErrors) {
  if (!vola::compression_available()) GTEST_SKIP() << "built without zstd";
  expect_damage_refused(false, 3000);
  // Each mixed level allocates its models (a few MB): fewer samples.
  expect_damage_refused(true, 600);
}

// A levels record claiming more parts than the header's depth allows (each coded level
// costs its context models however small its part) is refused before any is decoded.
TEST(Compression, MoreLevelPartsThanTheDepthAreRefused) {
  if (!vola::compression_available()) GTEST_SKIP() << "built without zstd";
  const Scenario s = make_scenario(seeds_for(Shape::clustered, 1)[0]);
  const vola::Tree tree = vola::build_from_voxels(to_voxels(s.unique()), s.depth);
  const auto bytes = vola::serialize(tree, {.compress = true});
  std::size_t at = 96;
  const auto records = get_le<std::uint32_t>(bytes, 92);
  bool found = false;
  for (std::uint32_t r = 0; r < records; ++r) {
    const auto length = get_le<std::uint64_t>(bytes, at + 8);
    if (get_le<std::uint32_t>(bytes, at) == 4) {
      found = true;
      ASSERT_EQ(get_le<std::uint32_t>(bytes, at + 16), static_cast<std::uint32_t>(tree.depth()));
      for (std::uint32_t parts : {static_cast<std::uint32_t>(tree.depth() + 1), std::uint32_t{1} << 20}) {
        auto lying = bytes;
        put_le<std::uint32_t>(lying, at + 16, parts);
        reseal_extension(lying, 80);
        const auto error = format_error_of([&] { (void)vola::parse(lying, "parts"); });
        ASSERT_TRUE(error.has_value()) << parts;
        EXPECT_THAT(error->cause(), HasSubstr("level parts for a tree of depth"));
        EXPECT_EQ(error->offset(), at + 16);
      }
    }
    at += 16 + ((length + 7) / 8) * 8;
  }
  EXPECT_TRUE(found);
}

TEST(Compression, LyingSizesAreRefusedBeforeAllocating) {
  if (!vola::compression_available()) GTEST_SKIP() << "built without zstd";
  std::mt19937_64 rng(9);
  const Scenario s = make_scenario(seeds_for(Shape::uniform, 1)[3]);
  vola::Tree tree = vola::build_from_voxels(to_voxels(s.unique()), s.depth);
  add_columns(tree, rng);
  const auto bytes = vola::serialize(tree, {.compress = true});
  // Each attribute record's raw size claims 2^40 bytes.
  std::size_t at = 96;
  const auto records = get_le<std::uint32_t>(bytes, 92);
  for (std::uint32_t r = 0; r < records; ++r) {
    const auto tag = get_le<std::uint32_t>(bytes, at);
    const auto length = get_le<std::uint64_t>(bytes, at + 8);
    if (tag == 3 || tag == 4) {
      auto lying = bytes;
      put_le<std::uint64_t>(lying, at + 24, std::uint64_t{1} << 40);
      LargestAllocation probe;
      const auto error = format_error_of([&] { (void)vola::parse(lying, "lying"); });
      ASSERT_TRUE(error.has_value()) << "record " << r;
      EXPECT_LT(probe.bytes(), std::size_t{64} << 20) << "record " << r;
    }
    at += 16 + ((length + 7) / 8) * 8;
  }
}

TEST(Compression, QuantizedColumnWithLyingExceptionsIsAFormatError) {
  if (!vola::compression_available()) GTEST_SKIP() << "built without zstd";
  std::mt19937_64 rng(13);
  vola::Tree tree;
  for (std::uint64_t seed : seeds_for(Shape::clustered, 1)) {
    const Scenario s = make_scenario(seed);
    tree = vola::build_from_voxels(to_voxels(s.unique()), s.depth);
    if (tree.voxel_count() > 2000) break;
  }
  add_columns(tree, rng);
  auto bytes = vola::serialize(tree, {.compress = true});
  ASSERT_EQ(attribute_encodings(bytes).at("height32"), 3);
  std::size_t at = 96;
  const auto records = get_le<std::uint32_t>(bytes, 92);
  for (std::uint32_t r = 0; r < records; ++r) {
    const auto length = get_le<std::uint64_t>(bytes, at + 8);
    if (get_le<std::uint32_t>(bytes, at) == 3 && bytes[at + 18] == 3) {
      const auto name_length = get_le<std::uint32_t>(bytes, at + 20);
      const std::size_t data = at + 32 + name_length;
      for (std::uint64_t lie : {~std::uint64_t{0}, std::uint64_t{1} << 50, tree.voxel_count() + 1}) {
        auto changed = bytes;
        put_le<std::uint64_t>(changed, data + 16, lie);  // the exception count
        reseal_extension(changed, 80);
        EXPECT_THROW((void)vola::parse(changed, "exceptions"), vola::FormatError);
      }
      auto changed = bytes;
      changed[data + 8] = 9;  // an unknown predictor
      reseal_extension(changed, 80);
      const auto error = format_error_of([&] { (void)vola::parse(changed, "predictor"); });
      ASSERT_TRUE(error.has_value());
      EXPECT_THAT(error->cause(), HasSubstr("unknown predictor 9"));
      EXPECT_EQ(error->offset(), data + 8);
    }
    at += 16 + ((length + 7) / 8) * 8;
  }
}


// Colour channels: green's steps follow red's, blue's follow green's (as in a LAS survey's
// RGB). Green and blue are coded against an earlier channel (encoding 4) and come back bit
// for bit; a partner index that is not an earlier column, or names one of another type,
// is a FormatError at the partner index's offset.
TEST(Compression, ColourChannelsArePredictedFromAnEarlierChannel) {
  if (!vola::compression_available()) GTEST_SKIP() << "built without zstd";
  std::mt19937_64 rng(17);
  vola::Tree tree;
  for (std::uint64_t seed : seeds_for(Shape::clustered, 1)) {
    const Scenario s = make_scenario(seed);
    tree = vola::build_from_voxels(to_voxels(s.unique()), s.depth);
    if (tree.voxel_count() > 2000) break;
  }
  const std::size_t n = tree.voxel_count();
  vola::AttributeColumn classes("classification", vola::ValueType::u8, vola::Reduction::majority, n);
  vola::AttributeColumn red("red", vola::ValueType::u16, vola::Reduction::mean, n);
  vola::AttributeColumn green("green", vola::ValueType::u16, vola::Reduction::mean, n);
  vola::AttributeColumn blue("blue", vola::ValueType::u16, vola::Reduction::mean, n);
  double r = 30000;
  for (std::size_t i = 0; i < n; ++i) {
    r = std::clamp(r + static_cast<double>(static_cast<int>(rng() % 4001) - 2000), 2000.0, 60000.0);
    const double g = r + static_cast<double>(rng() % 300), b = g + static_cast<double>(rng() % 300);
    classes.set(i, static_cast<double>(rng() % 3));
    red.set(i, r);
    green.set(i, g);
    blue.set(i, b);
  }
  tree.attributes().add(std::move(classes));
  tree.attributes().add(std::move(red));
  tree.attributes().add(std::move(green));
  tree.attributes().add(std::move(blue));
  const auto bytes = vola::serialize(tree, {.compress = true});
  expect_same(tree, vola::parse(bytes, "colours"));
  const auto encodings = attribute_encodings(bytes);
  EXPECT_NE(encodings.at("red"), 4);  // no earlier u16 column to lean on
  EXPECT_EQ(encodings.at("green"), 4);
  EXPECT_EQ(encodings.at("blue"), 4);

  // Lying partner indices in green's record: its own index, one past the end, the u8 column.
  std::size_t at = 96;
  const auto records = get_le<std::uint32_t>(bytes, 92);
  bool found = false;
  for (std::uint32_t k = 0; k < records; ++k) {
    const auto length = get_le<std::uint64_t>(bytes, at + 8);
    const auto name_length = get_le<std::uint32_t>(bytes, at + 20);
    const std::string name(bytes.begin() + static_cast<std::ptrdiff_t>(at + 32),
                           bytes.begin() + static_cast<std::ptrdiff_t>(at + 32 + name_length));
    if (get_le<std::uint32_t>(bytes, at) == 3 && name == "green") {
      found = true;
      const std::size_t data = at + 32 + name_length;
      EXPECT_EQ(get_le<std::uint32_t>(bytes, data), 1u);  // red, after classification
      for (const auto& [index, cause] : std::vector<std::pair<std::uint32_t, std::string>>{
               {2, "is not one of the 2 columns before 'green'"},
               {~std::uint32_t{0}, "is not one of the 2 columns before 'green'"},
               {0, "partner column 'classification' holds"}}) {
        auto changed = bytes;
        put_le<std::uint32_t>(changed, data, index);
        reseal_extension(changed, 80);
        const auto error = format_error_of([&] { (void)vola::parse(changed, "partner"); });
        ASSERT_TRUE(error.has_value()) << index;
        EXPECT_THAT(error->cause(), HasSubstr(cause));
        EXPECT_EQ(error->offset(), data);
      }
      auto changed = bytes;
      changed[data + 5] = 1;  // reserved
      reseal_extension(changed, 80);
      EXPECT_THROW((void)vola::parse(changed, "reserved"), vola::FormatError);
    }
    at += 16 + ((length + 7) / 8) * 8;
  }
  EXPECT_TRUE(found);
}

}  // namespace
}  // namespace vola_test
