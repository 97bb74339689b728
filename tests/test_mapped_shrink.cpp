// A mapped .vol cut by someone else while open: reading the lost pages must not end the
// process with SIGBUS; check_mapped() names the file instead. Each case runs in a forked
// child (a regression dies of SIGBUS there, and the test reads the signal).
#include <gtest/gtest.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <filesystem>
#include <functional>
#include <random>
#include <string>
#include <vector>

#include "child_process.hpp"
#include "test_support.hpp"
#include "vola/builder.hpp"
#include "vola/error.hpp"
#include "vola/file.hpp"

namespace {

namespace fs = std::filesystem;

volatile std::uint64_t sink = 0;  // keeps the reads of the cut mapping from being optimized away

using vola_test::in_child;

// A tree whose levels span many pages, so that cutting the file to its header leaves
// most of the mapping past the end.
vola::Tree scattered_tree() {
  std::mt19937 random(21);
  std::uniform_int_distribution<std::uint32_t> coordinate(0, vola::side_of(7) - 1);
  std::vector<vola::Voxel> voxels(200000);
  for (auto& v : voxels) v = {coordinate(random), coordinate(random), coordinate(random)};
  return vola::build_from_voxels(voxels, 7);
}

TEST(MappedShrink, ReadingAFileCutWhileMappedIsAnErrorNotSigbus) {
  vola_test::TempDir dir;
  const fs::path path = dir.path() / "cut.vol";
  const vola::Tree original = scattered_tree();
  vola::write(original, path.string());
  ASSERT_GT(fs::file_size(path), 64u * 4096u);
  const int status = in_child([&] {
    const vola::Tree mapped = vola::open_mapped(path.string());
    vola::check_mapped(mapped);  // whole: nothing to say
    // Half: the upper levels stay, the walk reaches leaf words past the new end (a cut
    // within the first page would read zeros there and stop the walk at the root).
    fs::resize_file(path, fs::file_size(path) / 2);
    std::uint64_t seen = 0;
    mapped.for_each_voxel([&](const vola::Voxel& v) { seen += mapped.contains(v) ? 1 : 0; });
    sink = seen;  // the reads must happen
    try {
      vola::check_mapped(mapped);
    } catch (const vola::IoError& e) {
      const std::string what = e.what();
      return what.find(path.string()) == 0 && what.find("cut") != std::string::npos ? 0 : 5;
    }
    return 6;  // the loss went unreported
  });
  EXPECT_EQ(status, 0) << (status == -SIGBUS ? "died of SIGBUS" : "exit status / -signal");
}

TEST(MappedShrink, LookupsOfALevelOfDetailAfterTheCutAreReportedToo) {
  vola_test::TempDir dir;
  const fs::path path = dir.path() / "lod.vol";
  vola::write(scattered_tree(), path.string());
  const int status = in_child([&] {
    const vola::Tree mapped = vola::open_mapped(path.string());
    const vola::Tree coarse = mapped.level_of_detail(6);
    fs::resize_file(path, 0);
    std::uint64_t seen = 0;
    for (std::uint32_t x = 0; x < coarse.side(); ++x)
      for (std::uint32_t y = 0; y < coarse.side(); y += 7) seen += coarse.contains(x, y, x) ? 1 : 0;
    sink = seen;
    try {
      vola::check_mapped(coarse);
    } catch (const vola::IoError&) {
      return 0;
    }
    return 6;
  });
  EXPECT_EQ(status, 0) << (status == -SIGBUS ? "died of SIGBUS" : "exit status / -signal");
}

// `cp other.vol mapped.vol` truncates the file and writes the other's bytes: unless a
// read falls in the moment it is short, no SIGBUS comes, and the mapping shows the
// other file's words under this one's counts (Python's voxels() wrote past its array).
// check_mapped() finds the rewrite by the file's size and time, and the mapping reads
// zeros from then on, as a cut one.
TEST(MappedShrink, AFileRewrittenInPlaceIsReportedAsCut) {
  vola_test::TempDir dir;
  const fs::path path = dir.path() / "small.vol", other = dir.path() / "big.vol";
  const std::vector<vola::Voxel> two{{1, 2, 3}, {4, 5, 6}};
  vola::write(vola::build_from_voxels(two, 7), path.string());
  vola::write(scattered_tree(), other.string());
  const vola::Tree mapped = vola::open_mapped(path.string());
  EXPECT_NO_THROW(vola::check_mapped(mapped));
  fs::copy_file(other, path, fs::copy_options::overwrite_existing);  // in place, as cp does
  try {
    vola::check_mapped_often(mapped);  // its first look at the file
    ADD_FAILURE() << "the rewrite went unreported";
  } catch (const vola::IoError& e) {
    EXPECT_EQ(std::string(e.what()).find(path.string()), 0u) << e.what();
    EXPECT_NE(std::string(e.what()).find("rewritten in place"), std::string::npos) << e.what();
  }
  std::uint64_t seen = 0;
  mapped.for_each_voxel([&](const vola::Voxel&) { ++seen; });
  EXPECT_EQ(seen, 0u);  // zeros, as after a cut: never the other file's 200,000 voxels
  EXPECT_THROW(vola::check_mapped(mapped), vola::IoError);
}

// In a loop that checks once per point, the file is looked at once a millisecond at most:
// a rewrite between two looks is found by the next one.
TEST(MappedShrink, ChecksInALoopFindARewriteWithinAMillisecond) {
  vola_test::TempDir dir;
  const fs::path path = dir.path() / "loop.vol", other = dir.path() / "other.vol";
  const std::vector<vola::Voxel> two{{1, 2, 3}, {4, 5, 6}};
  vola::write(vola::build_from_voxels(two, 7), path.string());
  vola::write(scattered_tree(), other.string());
  const vola::Tree mapped = vola::open_mapped(path.string());
  vola::check_mapped_often(mapped);  // looked at: the next look is a millisecond away
  fs::copy_file(other, path, fs::copy_options::overwrite_existing);
  const auto start = std::chrono::steady_clock::now();
  bool found = false;
  while (!found && std::chrono::steady_clock::now() - start < std::chrono::milliseconds(50)) try {
      vola::check_mapped_often(mapped);
    } catch (const vola::IoError&) {
      found = true;
    }
  EXPECT_TRUE(found) << "no look at the file in 50 ms of checks";
}

// A file renamed over the path (how vola::write and most tools replace a file) leaves
// the mapped one whole: nothing to report, and the tree reads its own voxels.
TEST(MappedShrink, AFileReplacedByARenameLeavesTheMappingWhole) {
  vola_test::TempDir dir;
  const fs::path path = dir.path() / "kept.vol";
  const std::vector<vola::Voxel> two{{1, 2, 3}, {4, 5, 6}};
  vola::write(vola::build_from_voxels(two, 7), path.string());
  const vola::Tree mapped = vola::open_mapped(path.string());
  vola::write(scattered_tree(), path.string());  // a temporary file renamed over it
  EXPECT_NO_THROW(vola::check_mapped(mapped));
  EXPECT_NO_THROW(vola::check_mapped_often(mapped));
  EXPECT_EQ(mapped.voxel_count(), 2u);
  EXPECT_TRUE(mapped.contains(4, 5, 6));
}

TEST(MappedShrink, FilesReadIntoMemoryAndUncutMappingsSayNothing) {
  vola_test::TempDir dir;
  const fs::path path = dir.path() / "whole.vol";
  const vola::Tree original = scattered_tree();
  vola::write(original, path.string());
  const vola::Tree read = vola::read(path.string());
  const vola::Tree mapped = vola::open_mapped(path.string());
  EXPECT_NO_THROW(vola::check_mapped(read));
  EXPECT_NO_THROW(vola::check_mapped(mapped));
  EXPECT_TRUE(mapped.is_mapped());
  EXPECT_EQ(mapped.voxel_count(), original.voxel_count());
}

// Past the table of live mappings (1024) a file is read into memory: is_mapped says so
// (it said 1 for every one of 1100 opens, though the last 76 were copies).
TEST(MappedShrink, FilesPastTheMappingTableAreCopiesAndSaySo) {
  vola_test::TempDir dir;
  const fs::path path = dir.path() / "many.vol";
  const std::vector<vola::Voxel> two{{1, 2, 3}, {4, 5, 6}};
  vola::write(vola::build_from_voxels(two, 3), path.string());
  std::vector<vola::Tree> open;
  std::size_t mapped = 0, copies = 0;
  for (int i = 0; i < 1100; ++i) {
    open.push_back(vola::open_mapped(path.string()));
    (open.back().is_mapped() ? mapped : copies) += 1;
    EXPECT_EQ(open.back().voxel_count(), 2u);
  }
  EXPECT_LE(mapped, 1024u);
  EXPECT_GE(copies, 76u);
}

// The guard handles faults in vola's mappings only: any other SIGBUS still ends the
// process by SIGBUS, as it would without vola.
TEST(MappedShrink, OtherSigbusStillEndsTheProcess) {
  vola_test::TempDir dir;
  const fs::path path = dir.path() / "any.vol";
  vola::write(scattered_tree(), path.string());
  const int status = in_child([&] {
    const vola::Tree mapped = vola::open_mapped(path.string());  // installs the guard
    ::raise(SIGBUS);
    return mapped.empty() ? 7 : 8;
  });
  EXPECT_EQ(status, -SIGBUS);
}

}  // namespace
