// .npz reading: the labelled grid layout, dtype conversions and every refusal.
#include <gtest/gtest.h>

#include <array>
#include <cstring>

#include "learn_test_data.hpp"
#include "memory_cap.hpp"
#include "test_support.hpp"
#include "vola/error.hpp"
#include "vola/io/input.hpp"
#include "vola/learn/npz.hpp"

namespace {

using namespace vola_learn_test;
using vola::learn::read_labelled_grids;

std::vector<std::vector<std::uint8_t>> three_grids() {
  return {shape_grid(0, 1), shape_grid(3, 2), shape_grid(9, 3)};
}

// The FormatError message of read_labelled_grids, or "" when it reads.
std::string read_error(const std::string& path, const std::string& split = {}) {
  try {
    read_labelled_grids(path, split);
  } catch (const vola::Error& e) {
    return e.what();
  }
  return "";
}

TEST(Npz, ReadsGridsAndLabelsInNpyOrder) {
  vola_test::TempDir dir;
  const auto grids = three_grids();
  for (const std::string dtype : {"|u1", "<i4"}) {
    std::string name = "a";  // (appended, not "a" + ... + ".npz": GCC 12 warns falsely there)
    name += dtype.substr(1);
    name += ".npz";
    const std::string path = (dir / name).string();
    write_npz(path, {{"X_train", grids_npy(grids, 32, dtype)}, {"y_train", labels_npy({0, 3, 9})}});
    EXPECT_EQ(vola::io::npz_array_names(path), (std::vector<std::string>{"X_train", "y_train"}));
    const auto read = read_labelled_grids(path);
    EXPECT_EQ(read.split, "train");
    EXPECT_EQ(read.side, 32);
    ASSERT_EQ(read.size(), 3u);
    EXPECT_EQ(read.labels, (std::vector<int>{0, 3, 9}));
    for (std::size_t i = 0; i < 3; ++i) {
      const auto g = read.grid(i);
      EXPECT_TRUE(std::equal(g.begin(), g.end(), grids[i].begin(), grids[i].end())) << dtype << " grid " << i;
    }
  }
}

TEST(Npz, NamesTheSplitWhenThereAreSeveral) {
  vola_test::TempDir dir;
  const std::string path = (dir / "two.npz").string();
  const auto grids = three_grids();
  write_npz(path, {{"X_train", grids_npy(grids, 32)}, {"y_train", labels_npy({0, 1, 2})},
                   {"X_test", grids_npy({grids[0]}, 32)}, {"y_test", labels_npy({7})}});
  EXPECT_NE(read_error(path).find("several X_<split>"), std::string::npos);
  const auto test = read_labelled_grids(path, "test");
  EXPECT_EQ(test.split, "test");
  EXPECT_EQ(test.labels, std::vector<int>{7});
  EXPECT_NE(read_error(path, "val").find("no array 'X_val'"), std::string::npos);
}

TEST(Npz, RefusesBadShapesDtypesValuesAndLabels) {
  vola_test::TempDir dir;
  const auto grids = three_grids();
  const auto check = [&](const std::string& name, const std::vector<std::pair<std::string, Bytes>>& members,
                         const std::string& expected) {
    const std::string path = (dir / (name + ".npz")).string();
    write_npz(path, members);
    const std::string message = read_error(path);
    EXPECT_NE(message.find(expected), std::string::npos) << name << ": " << message;
    EXPECT_NE(message.find(path), std::string::npos) << name << ": " << message;
  };
  check("no_x", {{"y_train", labels_npy({1})}}, "no X_<split>");
  check("no_y", {{"X_train", grids_npy(grids, 32)}}, "no array 'y_train'");
  check("flat", {{"X_train", vola_io_test::npy_bytes("|u1", {3, 32}, false, Bytes(96, 0))}, {"y_train", labels_npy({0, 1, 2})}},
        "expected (N, S, S, S)");
  check("not_cubic", {{"X_train", vola_io_test::npy_bytes("|u1", {1, 8, 8, 4}, false, Bytes(256, 0))}, {"y_train", labels_npy({0})}},
        "expected (N, S, S, S)");
  check("count", {{"X_train", grids_npy(grids, 32)}, {"y_train", labels_npy({0, 1})}}, "one label per grid (3)");
  check("label", {{"X_train", grids_npy(grids, 32)}, {"y_train", labels_npy({0, 12, 1})}}, "grid 1's label is 12, not 0..9");
  check("float_labels", {{"X_train", grids_npy(grids, 32)}, {"y_train", vola_io_test::npy_bytes("<f8", {3}, false, Bytes(24, 0))}},
        "expected integer labels");
  Bytes two(8 * 8 * 8, 0);
  two[100] = 2;
  check("value", {{"X_train", vola_io_test::npy_bytes("|u1", {1, 8, 8, 8}, false, two)}, {"y_train", labels_npy({0})}},
        "grid 0 holds 2");
  Bytes truncated = grids_npy(grids, 32);
  truncated.resize(truncated.size() - 10);
  check("short", {{"X_train", truncated}, {"y_train", labels_npy({0, 1, 2})}}, "X_train.npy");
}

TEST(Npz, RefusesFilesThatAreNotArchives) {
  vola_test::TempDir dir;
  const std::string text = (dir / "text.npz").string();
  vola_test::write_bytes(text, Bytes(200, 'x'));
  EXPECT_NE(read_error(text).find("not a readable .npz"), std::string::npos) << read_error(text);
  const std::string missing = (dir / "missing.npz").string();
  EXPECT_NE(read_error(missing).find("cannot open"), std::string::npos) << read_error(missing);
  // A member that is no .npy.
  const std::string junk = (dir / "junk.npz").string();
  write_npz(junk, {{"X_train", Bytes(64, 7)}, {"y_train", labels_npy({0})}});
  EXPECT_NE(read_error(junk).find("X_train.npy"), std::string::npos) << read_error(junk);
}

// Sets the central directory's compressed and uncompressed sizes of `member` (the
// sizes libzip reports) in the archive bytes.
void lie_about_sizes(Bytes& zip, const std::string& member, std::uint32_t compressed, std::uint32_t size) {
  for (std::size_t at = 0; at + 46 + member.size() <= zip.size(); ++at) {
    if (std::memcmp(zip.data() + at, "PK\x01\x02", 4) != 0) continue;
    const std::size_t name_length = zip[at + 28] | (zip[at + 29] << 8);
    if (std::string(reinterpret_cast<const char*>(zip.data() + at + 46), name_length) != member) continue;
    for (int i = 0; i < 4; ++i) {
      zip[at + 20 + i] = static_cast<std::uint8_t>(compressed >> (8 * i));
      zip[at + 24 + i] = static_cast<std::uint8_t>(size >> (8 * i));
    }
    return;
  }
  FAIL() << "no central directory entry for " << member;
}

// A zip directory that claims 4 GiB for a member of a few kilobytes: the reader
// allocated what it claimed (4.35 GB for a 2.5 KB file). Run under a 2 GiB cap.
TEST(Npz, SizesTheArchiveCannotHoldAreRefusedBeforeAllocating) {
  vola_test::TempDir dir;
  const std::string path = (dir / "lying.npz").string();
  write_npz(path, {{"X_train", grids_npy(three_grids(), 32)}, {"y_train", labels_npy({0, 3, 9})}});
  Bytes zip = vola_test::read_bytes(path);
  lie_about_sizes(zip, "X_train.npy", 0xFFFFFF00u, 0xFFFFFF00u);
  vola_test::write_bytes(path, zip);
  const std::string outcome = vola_test::run_with_memory_cap([&] {
    read_labelled_grids(path);
    return std::string("read");
  });
  EXPECT_NE(outcome.find("FormatError: " + path + ": X_train.npy: the zip directory states 4294967040 compressed "
                         "bytes, more than the archive's"),
            std::string::npos)
      << outcome;
  // A size deflate could reach from the compressed bytes (3 MiB of random bytes claimed
  // to inflate to 2.1 GB): the buffer grows with what actually inflates.
  Bytes noise(3 << 20);
  std::uint64_t state = 12345;
  for (auto& b : noise) b = static_cast<std::uint8_t>((state = state * 6364136223846793005u + 1442695040888963407u) >> 56);
  write_npz(path, {{"X_train", noise}, {"y_train", labels_npy({0})}});
  zip = vola_test::read_bytes(path);
  std::uint32_t compressed = 0;
  for (std::size_t at = 0; at + 4 <= zip.size(); ++at)
    if (std::memcmp(zip.data() + at, "PK\x01\x02", 4) == 0 && zip[at + 46] == 'X') {
      std::memcpy(&compressed, zip.data() + at + 20, 4);
      break;
    }
  ASSERT_GT(compressed, 3u << 20);
  lie_about_sizes(zip, "X_train.npy", compressed, compressed * 680);
  vola_test::write_bytes(path, zip);
  const std::string inflated = vola_test::run_with_memory_cap([&] {
    read_labelled_grids(path);
    return std::string("read");
  });
  EXPECT_EQ(inflated.rfind("FormatError: " + path + ": X_train.npy: ", 0), 0u) << inflated;
}

TEST(Npz, ReadsTheModelNetTrainingSplit) {
  VOLA_REQUIRE_DATA(data);
  const auto grids = read_labelled_grids((data / "modelnet" / "modelnet10_32_train.npz").string());
  EXPECT_EQ(grids.split, "train");
  EXPECT_EQ(grids.side, 32);
  ASSERT_EQ(grids.size(), 3991u);
  std::vector<int> counts(10, 0);
  for (int label : grids.labels) ++counts[std::size_t(label)];
  // The label histogram an independent reader found (EXPECTED.txt).
  EXPECT_EQ(counts, (std::vector<int>{106, 515, 889, 200, 200, 465, 200, 680, 392, 344}));
  std::size_t filled = 0;
  for (auto c : grids.cells) filled += c;
  EXPECT_NEAR(double(filled) / double(grids.cells.size()), 0.0954, 0.0005);
}

// ---- .npz archives as point files (vola convert X.npz, io::read_input) ----

// (N, 3) little-endian doubles, one row per point.
Bytes points_npy(const std::vector<std::array<double, 3>>& points) {
  Bytes data;
  for (const auto& p : points)
    for (double v : p) vola_io_test::put(data, v);
  return vola_io_test::npy_bytes("<f8", {points.size(), 3}, false, data);
}

// The FormatError message of reading `path` as a point file, or "" when it reads.
std::string points_error(const std::string& path, const std::string& member = {}) {
  vola::io::InputOptions options;
  options.grid = member;
  try {
    vola::io::read_input(path, "auto", options);
  } catch (const vola::Error& e) {
    return e.what();
  }
  return "";
}

// What pyntcloud's to_file("x.npz") writes: a "points" record array beside a "mesh".
TEST(NpzPoints, PyntcloudsPointsBesideItsMeshAreRead) {
  vola_test::TempDir dir;
  const std::string path = (dir / "diamond.npz").string();
  Bytes records;
  for (float x : {0.5f, 0.0f, 1.0f}) {
    vola_io_test::put(records, x);
    vola_io_test::put(records, 1.0f - x);
    vola_io_test::put(records, 0.25f);
    records.push_back(static_cast<std::uint8_t>(x * 200));
  }
  std::string dict =
      "{'descr': [('x', '<f4'), ('y', '<f4'), ('z', '<f4'), ('red', '|u1')], 'fortran_order': False, "
      "'shape': (3,), }";
  while ((10 + dict.size() + 1) % 64) dict.push_back(' ');
  dict.push_back('\n');
  Bytes npy = {0x93, 'N', 'U', 'M', 'P', 'Y', 1, 0};
  vola_io_test::put<std::uint16_t>(npy, static_cast<std::uint16_t>(dict.size()));
  npy.insert(npy.end(), dict.begin(), dict.end());
  npy.insert(npy.end(), records.begin(), records.end());
  write_npz(path, {{"points", npy}, {"mesh", labels_npy({0, 1, 2})}});
  const vola::io::Input in = vola::io::read_input(path, "auto", {});
  EXPECT_EQ(in.format, "npy");
  ASSERT_EQ(in.cloud.size(), 3u);
  EXPECT_EQ(in.cloud.xyz, (std::vector<double>{0.5, 0.5, 0.25, 0.0, 1.0, 0.25, 1.0, 0.0, 0.25}));
  ASSERT_EQ(in.cloud.attributes.size(), 1u);
  EXPECT_EQ(in.cloud.attributes[0].name, "red");
  EXPECT_EQ(in.cloud.attributes[0].values, (std::vector<double>{100, 0, 200}));
}

// numpy.savez("x.npz", points) names its only array arr_0.
TEST(NpzPoints, TheOnlyArrayIsReadWhateverItsName) {
  vola_test::TempDir dir;
  const std::string path = (dir / "x.npz").string();
  write_npz(path, {{"arr_0", points_npy({{1, 2, 3}, {4, 5, 6}})}});
  const vola::io::Input in = vola::io::read_input(path, "auto", {});
  EXPECT_EQ(in.cloud.xyz, (std::vector<double>{1, 2, 3, 4, 5, 6}));
}

TEST(NpzPoints, SeveralArraysNeedANameAndTheErrorListsThem) {
  vola_test::TempDir dir;
  const std::string path = (dir / "two.npz").string();
  write_npz(path, {{"before", points_npy({{1, 2, 3}})}, {"after", points_npy({{7, 8, 9}, {1, 1, 1}})}});
  const std::string error = points_error(path);
  EXPECT_NE(error.find("which array holds the points? The archive holds before, after"), std::string::npos) << error;
  EXPECT_NE(error.find("--grid NAME"), std::string::npos) << error;
  EXPECT_NE(points_error(path, "later").find("no array 'later' in the archive (it holds before, after)"),
            std::string::npos);
  vola::io::InputOptions options;
  options.grid = "after";
  const vola::io::Input in = vola::io::read_input(path, "auto", options);
  EXPECT_EQ(in.cloud.size(), 2u);
  // Two arrays named as points are as ambiguous as none.
  const std::string both = (dir / "both.npz").string();
  write_npz(both, {{"xyz", points_npy({{1, 2, 3}})}, {"points", points_npy({{7, 8, 9}})}});
  EXPECT_NE(points_error(both).find("several named as points are"), std::string::npos) << points_error(both);
  // The chosen array's own errors name the archive and the member.
  const std::string flat = (dir / "flat.npz").string();
  write_npz(flat, {{"points", labels_npy({0, 1, 2})}, {"rgb", labels_npy({0})}});
  EXPECT_NE(points_error(flat).find(flat + ":points: an array of shape (3)"), std::string::npos) << points_error(flat);
}

}  // namespace
