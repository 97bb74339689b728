// The streaming LAS path (io::build_las, what `vola convert` uses: occupancy through a
// StreamBuilder, then attribute columns in a second pass over the records into a
// VoxelReducer) against the obvious one (the whole file as a PointCloud, then
// vola::build): the same tree for every shared LAS and LAZ file and for a generated
// multi-chunk file, in both quantization modes, with and without attribute columns and
// payloads, and with a given bbox. Attribute columns without payloads are the same bytes
// (points fold in input order); with payloads (chunks merged) means may differ in the
// order of summation.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <functional>
#include <map>
#include <random>

#include "io_test_data.hpp"
#include "vola/file.hpp"
#include "vola/io/export.hpp"
#include "vola/io/las.hpp"
#include "vola/parallel.hpp"

namespace {

using vola_io_test::Bytes;
using vola_io_test::put;

struct Case {
  const char* name;
  vola::Quantization quantization;
  int depth;
  double voxel_fraction;  // grid mode: voxel edge as a fraction of the largest extent
  bool attributes;
  bool payload;
  bool given_bbox;
};

const Case kCases[] = {
    {"toolkit occupancy", vola::Quantization::toolkit, 6, 0, false, false, false},
    {"toolkit attributes", vola::Quantization::toolkit, 5, 0, true, false, false},
    {"toolkit payload", vola::Quantization::toolkit, 7, 0, false, true, false},
    {"grid occupancy", vola::Quantization::grid, 0, 1.0 / 40, false, false, false},
    {"grid attributes and payload", vola::Quantization::grid, 0, 1.0 / 25, true, true, false},
    {"grid with a bbox inside the points", vola::Quantization::grid, 0, 1.0 / 30, true, false, true},
};

vola::BuildOptions options_for(const Case& c, const vola::io::LasHeader& h) {
  vola::BuildOptions o;
  o.quantization = c.quantization;
  o.depth = c.depth;
  o.payload = c.payload;
  const double extent = std::max({h.max[0] - h.min[0], h.max[1] - h.min[1], h.max[2] - h.min[2], 1e-3});
  if (c.quantization == vola::Quantization::grid) o.voxel_size = extent * c.voxel_fraction;
  if (c.given_bbox) {  // the middle of the header's box: some points fall outside
    vola::Box b;
    for (int a = 0; a < 3; ++a) {
      const double q = (h.max[a] - h.min[a]) / 4;
      b.min[a] = h.min[a] + q;
      b.max[a] = h.max[a] - q;
    }
    o.bbox = b;
  }
  return o;
}

// Same words, payloads, attribute columns and frame; unless `exact`, means may differ in
// the order of floating-point summation only (per chunk, then across chunks).
void expect_same_tree(const vola::Tree& got, const vola::Tree& want, bool exact) {
  ASSERT_EQ(got.depth(), want.depth());
  ASSERT_EQ(got.voxel_count(), want.voxel_count());
  EXPECT_TRUE(std::equal(got.words().begin(), got.words().end(), want.words().begin(), want.words().end()));
  EXPECT_TRUE(std::equal(got.voxel_payloads().begin(), got.voxel_payloads().end(), want.voxel_payloads().begin(),
                         want.voxel_payloads().end()));
  EXPECT_EQ(got.frame().voxel_size, want.frame().voxel_size);
  for (int a = 0; a < 3; ++a) EXPECT_EQ(got.frame().origin[a], want.frame().origin[a]);
  ASSERT_EQ(got.attributes().size(), want.attributes().size());
  for (std::size_t c = 0; c < got.attributes().size(); ++c) {
    const auto& g = got.attributes().columns()[c];
    const auto& w = want.attributes().columns()[c];
    ASSERT_EQ(g.name(), w.name());
    ASSERT_EQ(g.size(), w.size());
    ASSERT_EQ(g.type(), w.type());
    ASSERT_EQ(g.reduction(), w.reduction());
    if (exact) {
      ASSERT_TRUE(std::equal(g.bytes().begin(), g.bytes().end(), w.bytes().begin(), w.bytes().end())) << g.name();
      continue;
    }
    for (std::size_t v = 0; v < g.size(); ++v) {
      if (std::isnan(w.get(v))) {  // no data (an extra-bytes field's no_data value) on both sides
        ASSERT_TRUE(std::isnan(g.get(v))) << g.name() << " voxel " << v;
        continue;
      }
      ASSERT_NEAR(g.get(v), w.get(v), 1e-6 * (1 + std::abs(w.get(v)))) << g.name() << " voxel " << v;
    }
  }
}

void check_file(const std::function<vola::io::LasReader()>& open, std::size_t chunk_points) {
  for (const Case& c : kCases) {
    SCOPED_TRACE(c.name);
    vola::io::LasReader reader = open();
    vola::BuildOptions streamed = options_for(c, reader.header());
    vola::BuildOptions whole = streamed;
    vola::BuildReport streamed_report, whole_report;
    const vola::Tree got =
        vola::io::build_las(reader, streamed, c.attributes, c.payload, &streamed_report, {}, chunk_points);
    reader.rewind();
    const vola::PointCloud cloud = vola::io::las_points(reader, c.attributes, c.payload);
    const vola::Tree want = vola::build(cloud, whole, &whole_report);
    expect_same_tree(got, want, !c.payload);
    EXPECT_EQ(streamed_report.points_in, whole_report.points_in);
    EXPECT_EQ(streamed_report.points_outside, whole_report.points_outside);
    if (!c.payload) {
      EXPECT_EQ(vola::serialize(got), vola::serialize(want));
    }
  }
}

// A LAS 1.2 format 3 file (RGB, GPS time) of `n` points in clusters, so that voxels get
// several points with differing colours, classes and intensities. A negative x scale
// reverses the order of the stored integers (the bounds pass must cope).
Bytes generated_las(std::size_t n, std::uint64_t seed, double x_scale = 0.01) {
  Bytes b(227, 0);
  std::memcpy(b.data(), "LASF", 4);
  b[24] = 1;
  b[25] = 2;
  const auto at = [&](std::size_t offset, auto value) { std::memcpy(&b[offset], &value, sizeof value); };
  at(94, std::uint16_t{227});
  at(96, std::uint32_t{227});
  b[104] = 3;
  at(105, std::uint16_t{34});
  at(107, static_cast<std::uint32_t>(n));
  const double scales[3] = {x_scale, 0.01, 0.01};
  for (int a = 0; a < 3; ++a) at(131 + 8 * a, scales[a]);
  at(155, 1000.0);  // x offset
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> spread(0.0, 3.0);
  std::uniform_int_distribution<int> centre(0, 200), small(0, 4);
  double lo[3] = {1e300, 1e300, 1e300}, hi[3] = {-1e300, -1e300, -1e300};
  for (std::size_t i = 0; i < n; ++i) {
    std::int32_t raw[3];
    for (int a = 0; a < 3; ++a) {
      raw[a] = static_cast<std::int32_t>((centre(rng) + spread(rng)) / scales[a]);
      const double v = raw[a] * scales[a] + (a == 0 ? 1000.0 : 0.0);
      lo[a] = std::min(lo[a], v);
      hi[a] = std::max(hi[a], v);
      put(b, raw[a]);
    }
    put(b, static_cast<std::uint16_t>(small(rng) * 100));  // intensity
    b.push_back(static_cast<std::uint8_t>((1 + small(rng) % 3) | 3 << 3));  // return 1..3 of 3
    b.push_back(static_cast<std::uint8_t>(small(rng) + 1));               // class
    b.push_back(0);                                                       // scan angle
    b.push_back(0);                                                       // user data
    put(b, std::uint16_t{7});                                             // point source
    put(b, static_cast<double>(i));                                       // GPS time
    for (int k = 0; k < 3; ++k) put(b, static_cast<std::uint16_t>(small(rng) * 16000));
  }
  for (int a = 0; a < 3; ++a) {
    at(179 + 16 * a, hi[a]);
    at(187 + 16 * a, lo[a]);
  }
  return b;
}

TEST(LasStream, SharedFilesBuildAsTheWholeCloudDoes) {
  VOLA_REQUIRE_DATA(data);
  const auto files = vola_io_test::files_ending(data / "las", ".las");
  ASSERT_GE(files.size(), 20u);
  for (const auto& file : files) {
    SCOPED_TRACE(file.string());
    // Chunks of 997 points: every file of more than that takes several chunks and merges.
    check_file([&] { return vola::io::LasReader(file.string()); }, 997);
  }
}

// LAZ: the second pass decodes the chunks again; the same bytes as the whole cloud's.
TEST(LasStream, SharedLazFilesBuildAsTheWholeCloudDoes) {
  VOLA_REQUIRE_DATA(data);
  const auto files = vola_io_test::files_ending(data / "laz", ".laz");
  ASSERT_GE(files.size(), 5u);
  for (const auto& file : files) {
    SCOPED_TRACE(file.string());
    check_file([&] { return vola::io::LasReader(file.string()); }, 997);
  }
}

// The attribute pass on 1, 2 or 3 threads (the voxels dealt to as many parts, each
// reducing its own points in input order): the same bytes every time.
void check_threads(const std::function<vola::io::LasReader()>& open) {
  struct Restore {
    ~Restore() { vola::set_thread_count(0); }
  } restore;
  for (const Case& c : kCases) {
    if (!c.attributes || c.payload) continue;
    SCOPED_TRACE(c.name);
    std::vector<std::uint8_t> one;
    for (const unsigned threads : {1u, 2u, 3u}) {
      SCOPED_TRACE("threads " + std::to_string(threads));
      vola::set_thread_count(threads);
      vola::io::LasReader reader = open();
      const vola::Tree tree = vola::io::build_las(reader, options_for(c, reader.header()), true, false, nullptr, {});
      const std::vector<std::uint8_t> bytes = vola::serialize(tree);
      if (threads == 1) one = bytes;
      else EXPECT_TRUE(bytes == one);
    }
  }
}

TEST(LasStream, SharedFilesGiveTheSameBytesOnAnyThreads) {
  VOLA_REQUIRE_DATA(data);
  std::vector<std::filesystem::path> files = vola_io_test::files_ending(data / "las", ".las");
  const auto laz = vola_io_test::files_ending(data / "laz", ".laz");
  ASSERT_GE(files.size(), 20u);
  ASSERT_GE(laz.size(), 5u);
  files.insert(files.end(), laz.begin(), laz.end());
  for (const auto& file : files) {
    SCOPED_TRACE(file.string());
    check_threads([&] { return vola::io::LasReader(file.string()); });
  }
}

TEST(LasStream, GeneratedFileGivesTheSameBytesOnAnyThreads) {
  const Bytes bytes = generated_las(300000, 23);
  const vola_test::TempDir dir;
  const auto path = dir.path() / "generated.las";
  vola_test::write_bytes(path, bytes);
  check_threads([&] { return vola::io::LasReader(path.string()); });
}

TEST(LasStream, GeneratedFileInManyChunksBuildsAsTheWholeCloudDoes) {
  const Bytes bytes = generated_las(60000, 11);
  for (const std::size_t chunk : {std::size_t{61}, std::size_t{4096}, std::size_t{1} << 20}) {
    SCOPED_TRACE("chunk " + std::to_string(chunk));
    check_file([&] { return vola::io::LasReader(bytes, "generated.las"); }, chunk);
  }
}

// The same from a file on disk (read with pread() in batches of kLasRecordBatchBytes):
// chunks smaller than a batch, and chunks of many batches.
TEST(LasStream, GeneratedFileOnDiskBuildsAsTheWholeCloudDoes) {
  const Bytes bytes = generated_las(60000, 16);
  const vola_test::TempDir dir;
  const auto path = dir.path() / "generated.las";
  vola_test::write_bytes(path, bytes);
  ASSERT_GT(60000u, 3 * vola::io::kLasRecordBatchBytes / 34);
  for (const std::size_t chunk : {std::size_t{61}, std::size_t{25000}, std::size_t{1} << 20}) {
    SCOPED_TRACE("chunk " + std::to_string(chunk));
    check_file([&] { return vola::io::LasReader(path.string()); }, chunk);
  }
  // Chunks of whole records from the file and from memory are the same.
  vola::io::LasReader from_file(path.string()), from_memory(bytes, "generated.las");
  vola::io::LasChunk a, b;
  while (true) {
    const std::size_t n = from_file.read(a, 20011);
    ASSERT_EQ(n, from_memory.read(b, 20011));
    if (n == 0) break;
    EXPECT_EQ(a.xyz, b.xyz);
    EXPECT_EQ(a.gps_time, b.gps_time);
    EXPECT_EQ(a.red, b.red);
    EXPECT_EQ(a.classification, b.classification);
  }
  EXPECT_EQ(from_file.points_read(), 60000u);
}

// Point format 7 (the extended fields) with extra bytes, as vola's own LAS export writes
// them: "height" (which replaces z as the height column), a fractional f64 field and an
// integer one; as LAS and as LAZ.
TEST(LasStream, ExtendedFormatWithExtraBytesBuildsAsTheWholeCloudDoes) {
  std::mt19937_64 rng(17);
  std::uniform_real_distribution<double> coordinate(0.0, 40.0), any(-50.0, 50.0);
  std::uniform_int_distribution<int> small(0, 6), wide(0, 65535);
  vola::PointCloud cloud;
  const std::vector<std::pair<std::string, vola::ValueType>> columns = {
      {"red", vola::ValueType::u16},       {"green", vola::ValueType::u16},
      {"blue", vola::ValueType::u16},      {"intensity", vola::ValueType::u16},
      {"classification", vola::ValueType::u8}, {"number_of_returns", vola::ValueType::u8},
      {"height", vola::ValueType::f64},    {"temperature", vola::ValueType::f64},
      {"count16", vola::ValueType::u16}};
  for (const auto& [name, type] : columns) cloud.attributes.push_back({name, type, vola::Reduction::mean, {}});
  for (int i = 0; i < 30000; ++i) {
    for (int a = 0; a < 3; ++a) cloud.xyz.push_back(coordinate(rng));
    for (std::size_t c = 0; c < columns.size(); ++c) {
      const std::string& name = columns[c].first;
      const double v = name == "height" || name == "temperature" ? any(rng)
                       : name == "classification" || name == "number_of_returns" ? small(rng) + 1
                                                                                 : wide(rng);
      cloud.attributes[c].values.push_back(v);
    }
  }
  const vola_test::TempDir dir;
  for (const char* name : {"extra.las", "extra.laz"}) {
    SCOPED_TRACE(name);
    const auto path = dir.path() / name;
    const vola::io::LasReport written = vola::io::write_las(cloud, path.string());
    ASSERT_EQ(written.point_format, 7);
    vola::io::LasReader probe(path.string());
    ASSERT_EQ(probe.header().extra_fields.size(), 3u);
    check_file([&] { return vola::io::LasReader(path.string()); }, 4001);
  }
}

// Extra-bytes identifiers (lidR writes its segmented trees' treeID as one) are reduced
// by majority, measurements (GEOID: a geoid height, upper case) by mean; the streamed
// build and the whole cloud agree, and every voxel's treeID is one its points hold most.
TEST(LasStream, IdentifierExtraBytesTakeTheMajorityOfAVoxel) {
  std::mt19937_64 rng(29);
  std::uniform_real_distribution<double> coordinate(0.0, 8.0), any(-50.0, 50.0);
  std::uniform_int_distribution<int> tree(1, 5);
  vola::PointCloud cloud;
  for (const char* name : {"treeID", "GEOID", "temperature"})
    cloud.attributes.push_back({name, vola::ValueType::f64, vola::Reduction::mean, {}});
  for (int i = 0; i < 20000; ++i) {
    for (int a = 0; a < 3; ++a) cloud.xyz.push_back(coordinate(rng));
    cloud.attributes[0].values.push_back(tree(rng));
    cloud.attributes[1].values.push_back(any(rng));
    cloud.attributes[2].values.push_back(any(rng));
  }
  const vola_test::TempDir dir;
  const auto path = dir.path() / "trees.las";
  vola::io::write_las(cloud, path.string());
  vola::io::LasReader reader(path.string());
  for (const auto& spec : vola::io::las_attributes(reader.header())) {
    const vola::Reduction want = spec.name == "treeID" ? vola::Reduction::majority : vola::Reduction::mean;
    if (spec.name == "treeID" || spec.name == "GEOID" || spec.name == "temperature") {
      EXPECT_EQ(spec.reduction, want) << spec.name;
    }
  }
  check_file([&] { return vola::io::LasReader(path.string()); }, 3001);

  vola::BuildOptions options;
  options.quantization = vola::Quantization::grid;
  options.voxel_size = 1.0;
  options.origin = vola::Point{0, 0, 0};
  const vola::Tree built = vola::io::build_las(reader, options, true, false, nullptr);
  const vola::Quantizer grid = vola::Quantizer::grid({0, 0, 0}, 1.0, built.depth());
  const vola::AttributeColumn* ids = built.attributes().find("treeID");
  ASSERT_NE(ids, nullptr);
  ASSERT_EQ(ids->reduction(), vola::Reduction::majority);
  std::map<std::uint64_t, std::map<double, int>> counts;  // voxel rank -> tree id -> points
  for (std::size_t i = 0; i < cloud.size(); ++i) {
    vola::Voxel v;
    ASSERT_TRUE(grid.to_voxel({cloud.xyz[3 * i], cloud.xyz[3 * i + 1], cloud.xyz[3 * i + 2]}, v));
    ++counts[*built.rank(v)][cloud.attributes[0].values[i]];
  }
  ASSERT_EQ(counts.size(), built.voxel_count());
  std::size_t ties = 0;
  for (const auto& [rank, ids_of_voxel] : counts) {
    int most = 0;
    for (const auto& [id, n] : ids_of_voxel) most = std::max(most, n);
    const double got = ids->get(rank);
    ASSERT_TRUE(ids_of_voxel.count(got) && ids_of_voxel.at(got) == most) << "voxel " << rank << " holds " << got;
    ties +=
        std::count_if(ids_of_voxel.begin(), ids_of_voxel.end(), [&](const auto& e) { return e.second == most; }) > 1;
  }
  EXPECT_LT(ties, counts.size());  // most voxels have one most common id: the check has teeth
}

TEST(LasStream, NegativeScaleBoundsAsDecoded) {
  const Bytes bytes = generated_las(5000, 12, -0.01);
  check_file([&] { return vola::io::LasReader(bytes, "negative_scale.las"); }, 333);
}

// x stored in steps of 0.5 while the toolkit grid at depth 6 and 7 has cells far
// narrower: most cells hold no stored integer at all (the stored-integer -> key tables
// of the occupancy path must skip them), and a grid voxel holds a few steps.
TEST(LasStream, CoarseStoredStepsBuildAsTheWholeCloudDoes) {
  const Bytes bytes = generated_las(20000, 13, 0.5);
  check_file([&] { return vola::io::LasReader(bytes, "coarse.las"); }, 777);
}

// A header whose bounds are wider than the points' (stale): the one-pass occupancy
// build guesses the grid from the header, finds that the points' bounds resolve to
// another one, and must fall back to building on the points' bounds.
TEST(LasStream, StaleHeaderBoundsBuildAsTheWholeCloudDoes) {
  Bytes bytes = generated_las(8000, 14);
  for (int a = 0; a < 3; ++a) {
    double lo = 0, hi = 0;
    std::memcpy(&hi, &bytes[179 + 16 * a], 8);
    std::memcpy(&lo, &bytes[187 + 16 * a], 8);
    hi += 7.3;
    lo -= 11.1;
    std::memcpy(&bytes[179 + 16 * a], &hi, 8);
    std::memcpy(&bytes[187 + 16 * a], &lo, 8);
  }
  check_file([&] { return vola::io::LasReader(bytes, "stale.las"); }, 1500);
}

// Occupancy only with the header's bounds right: one pass over the records; stale: the
// pass is redone on the points' bounds. (Passes counted as progress reports that end one.)
TEST(LasStream, OccupancyTakesOnePassWhenTheHeaderBoundsAreRight) {
  Bytes bytes = generated_las(5000, 15);
  const auto passes = [&] {
    vola::io::LasReader reader(bytes, "passes.las");
    vola::BuildOptions options;
    options.quantization = vola::Quantization::grid;
    options.voxel_size = 2.0;
    int ends = 0;
    vola::io::build_las(reader, options, false, false, nullptr,
                        [&](std::uint64_t done, std::uint64_t total) { ends += done == total; }, 1000);
    return ends;
  };
  EXPECT_EQ(passes(), 1);
  double hi = 0;
  std::memcpy(&hi, &bytes[179], 8);
  hi += 1000.0;  // another depth
  std::memcpy(&bytes[179], &hi, 8);
  EXPECT_EQ(passes(), 2);
}

}  // namespace
