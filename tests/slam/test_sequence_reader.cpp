// Reading TUM-layout and numbered sequences, depth images and trajectories: the values,
// and errors that name the file and the line (or byte).
#include <gtest/gtest.h>

#include <cmath>
#include <fstream>

#include "slam_test_support.hpp"
#include "vola/error.hpp"
#include "vola/slam/fuse_sequence.hpp"
#include "vola/slam/image.hpp"
#include "vola/slam/sequence.hpp"

namespace {

using namespace vola::slam;
using vola_slam_test::ScratchDir;
using vola_slam_test::write_text;
namespace fs = vola_slam_test::fs;

// The FormatError's message, or "" when none is thrown.
template <class F>
std::string format_error(F&& f) {
  try {
    f();
  } catch (const vola::FormatError& e) {
    return e.what();
  }
  return "";
}

DepthImage ramp(std::uint32_t w, std::uint32_t h) {
  DepthImage d{w, h, std::vector<float>(std::size_t{w} * h)};
  for (std::size_t i = 0; i < d.metres.size(); ++i) d.metres[i] = i % 7 == 0 ? 0.0f : 0.5f + 0.001f * static_cast<float>(i);
  return d;
}

TEST(SlamSequence, DepthPngRoundTripsAtTheDepthFactor) {
  ScratchDir dir("png");
  const DepthImage d = ramp(37, 11);
  write_depth_png((dir.path() / "d.png").string(), d, 5000.0);
  const DepthImage back = read_depth((dir.path() / "d.png").string(), 5000.0);
  ASSERT_EQ(back.width, 37u);
  ASSERT_EQ(back.height, 11u);
  for (std::size_t i = 0; i < d.metres.size(); ++i) {
    if (d.metres[i] == 0.0f)
      EXPECT_EQ(back.metres[i], 0.0f);
    else  // quantised to 1/5000 m
      EXPECT_NEAR(back.metres[i], d.metres[i], 0.5 / 5000.0 + 1e-6);
  }
}

TEST(SlamSequence, ColourPngIsNotDepth) {
  ScratchDir dir("rgb");
  RgbImage rgb{4, 3, std::vector<std::uint8_t>(36, 200)};
  write_rgb_png((dir.path() / "c.png").string(), rgb);
  EXPECT_EQ(read_rgb_png((dir.path() / "c.png").string()).rgb, rgb.rgb);
  const std::string message = format_error([&] { read_depth((dir.path() / "c.png").string(), 5000.0); });
  EXPECT_NE(message.find("c.png"), std::string::npos) << message;
  EXPECT_NE(message.find("16-bit grey"), std::string::npos) << message;
}

TEST(SlamSequence, TruncatedAndForgedFilesAreRefused) {
  ScratchDir dir("bad");
  write_depth_png((dir.path() / "d.png").string(), ramp(64, 64), 1000.0);
  std::ifstream in(dir.path() / "d.png", std::ios::binary);
  std::vector<char> bytes((std::istreambuf_iterator<char>(in)), {});
  // Cut in the middle of the image data.
  {
    std::ofstream out(dir.path() / "cut.png", std::ios::binary);
    out.write(bytes.data(), static_cast<std::streamsize>(bytes.size() / 2));
  }
  EXPECT_NE(format_error([&] { read_depth((dir.path() / "cut.png").string(), 1000.0); }).find("cut.png"), std::string::npos);
  write_text(dir.path() / "text.png", "not a png at all");
  EXPECT_NE(format_error([&] { read_depth((dir.path() / "text.png").string(), 1000.0); }).find("signature"),
            std::string::npos);
  // PGM: 16-bit big-endian, header says more samples than the file holds.
  write_text(dir.path() / "short.pgm", "P5\n# comment\n4 4\n65535\n" + std::string(20, '\x01'));
  const std::string pgm = format_error([&] { read_depth((dir.path() / "short.pgm").string(), 1000.0); });
  EXPECT_NE(pgm.find("short.pgm"), std::string::npos) << pgm;
  EXPECT_NE(pgm.find("truncated"), std::string::npos) << pgm;
  write_text(dir.path() / "eight.pgm", "P5 2 2 255 " + std::string(4, 'a'));
  EXPECT_NE(format_error([&] { read_depth((dir.path() / "eight.pgm").string(), 1000.0); }).find("16-bit"), std::string::npos);
  EXPECT_THROW(read_depth((dir.path() / "missing.png").string(), 1000.0), vola::IoError);
}

TEST(SlamSequence, PgmDepthIsBigEndianMillimetres) {
  ScratchDir dir("pgm");
  std::string data = "P5\n2 1\n65535\n";
  data += std::string("\x03\xe8\x00\x00", 4);  // 1000 mm, then a hole
  write_text(dir.path() / "d.pgm", data);
  const DepthImage d = read_depth((dir.path() / "d.pgm").string(), 1000.0);
  ASSERT_EQ(d.metres.size(), 2u);
  EXPECT_FLOAT_EQ(d.metres[0], 1.0f);
  EXPECT_EQ(d.metres[1], 0.0f);
}

TEST(SlamSequence, ListErrorsNameFileAndLine) {
  ScratchDir dir("lists");
  write_text(dir.path() / "depth.txt", "# comment\n1.0 depth/a.png\n\n1.5x depth/b.png\n");
  const std::string bad_time = format_error([&] { read_timed_list((dir.path() / "depth.txt").string()); });
  EXPECT_NE(bad_time.find("depth.txt: line 4"), std::string::npos) << bad_time;
  write_text(dir.path() / "depth.txt", "1.0 depth/a.png extra\n");
  EXPECT_NE(format_error([&] { read_timed_list((dir.path() / "depth.txt").string()); }).find("line 1: expected 'timestamp path'"),
            std::string::npos);
  write_text(dir.path() / "gt.txt", "1 0 0 0 0 0 0 1\n2 0 0 0 0 0 0 2\n");
  const std::string norm = format_error([&] { read_trajectory((dir.path() / "gt.txt").string()); });
  EXPECT_NE(norm.find("gt.txt: line 2: quaternion"), std::string::npos) << norm;
  write_text(dir.path() / "gt.txt", "1 0 0 0 0 0 0\n");
  EXPECT_NE(format_error([&] { read_trajectory((dir.path() / "gt.txt").string()); }).find("line 1"), std::string::npos);
  write_text(dir.path() / "gt.txt", "1 0 0 nan 0 0 0 1\n");
  EXPECT_NE(format_error([&] { read_trajectory((dir.path() / "gt.txt").string()); }).find("tz"), std::string::npos);
  // Lines out of time order come back in time order (the RPE pairs poses by it).
  write_text(dir.path() / "gt.txt", "3 3 0 0 0 0 0 1\n1 1 0 0 0 0 0 1\n2 2 0 0 0 0 0 1\n");
  const auto sorted = read_trajectory((dir.path() / "gt.txt").string());
  ASSERT_EQ(sorted.size(), 3u);
  for (std::size_t i = 0; i < 3; ++i) {
    EXPECT_EQ(sorted[i].timestamp, static_cast<double>(i + 1));
    EXPECT_EQ(sorted[i].pose.translation().x(), static_cast<double>(i + 1));
  }
  write_text(dir.path() / "k.txt", "525 525 319.5\n");
  EXPECT_NE(format_error([&] { read_intrinsics((dir.path() / "k.txt").string()); }).find("k.txt: line 1"), std::string::npos);
}

TEST(SlamSequence, TumLayoutAssociatesColourByNearestTimestamp) {
  ScratchDir dir("tum");
  fs::create_directories(dir.path() / "depth");
  // A byte order mark before the first line's comment (a Windows editor's) is no field.
  write_text(dir.path() / "depth.txt", "\xef\xbb\xbf# depth maps\n1.00 depth/1.png\n1.10 depth/2.png\n1.20 depth/3.png\n");
  write_text(dir.path() / "rgb.txt", "1.005 rgb/1.png\n1.19 rgb/3.png\n1.50 rgb/9.png\n");
  write_text(dir.path() / "groundtruth.txt", "1.0 1 2 3 0 0 0 1\n");
  write_text(dir.path() / "intrinsics.txt", "500 -480 320 240\n");
  // A listed frame that does not exist is named with its list's line.
  const std::string missing = format_error([&] { read_sequence(dir.path().string()); });
  EXPECT_NE(missing.find("depth.txt: line 2: frame file"), std::string::npos) << missing;
  EXPECT_NE(missing.find("does not exist"), std::string::npos) << missing;
  fs::create_directories(dir.path() / "rgb");
  for (const char* f : {"depth/1.png", "depth/2.png", "depth/3.png", "rgb/1.png", "rgb/3.png"}) write_text(dir.path() / f, "");
  const std::string missing_rgb = format_error([&] { read_sequence(dir.path().string()); });
  EXPECT_NE(missing_rgb.find("rgb.txt: line 3: frame file"), std::string::npos) << missing_rgb;
  write_text(dir.path() / "rgb/9.png", "");
  const Sequence s = read_sequence(dir.path().string());
  ASSERT_EQ(s.frames.size(), 3u);
  EXPECT_EQ(s.frames[0].rgb_path, (dir.path() / "rgb/1.png").string());
  EXPECT_EQ(s.frames[1].rgb_path, "");  // 1.10 has no colour frame within 20 ms
  EXPECT_EQ(s.frames[2].rgb_path, (dir.path() / "rgb/3.png").string());
  ASSERT_EQ(s.groundtruth.size(), 1u);
  EXPECT_EQ(s.groundtruth[0].pose.translation(), Eigen::Vector3d(1, 2, 3));
  ASSERT_TRUE(s.intrinsics);
  EXPECT_EQ(s.intrinsics->fy, -480.0);
  // Colour none of whose timestamps meets a depth frame's is refused (colour, and the
  // features tracking uses, were dropped without a word).
  write_text(dir.path() / "rgb.txt", "5.0 rgb/1.png\n6.0 rgb/3.png\n");
  const std::string unmatched = format_error([&] { read_sequence(dir.path().string()); });
  EXPECT_NE(unmatched.find("none of its 2 colour frames lies within 20 ms of a depth frame"), std::string::npos)
      << unmatched;
  // A listed frame that is not a regular file is named as such, not as missing.
  write_text(dir.path() / "rgb.txt", "1.005 rgb\n");
  const std::string folder = format_error([&] { read_sequence(dir.path().string()); });
  EXPECT_NE(folder.find("is not a regular file"), std::string::npos) << folder;
  write_text(dir.path() / "depth.txt", "1.00 depth/1.png\n0.90 depth/2.png\n");
  EXPECT_NE(format_error([&] { read_sequence(dir.path().string()); }).find("timestamps must increase"), std::string::npos);
}

TEST(SlamSequence, AssociateIsGreedyByTimeDifference) {
  // Closest pairs first: (1.02, 1.02) at 0, then (1.0, 0.995) at 0.005; 1.01 is left over.
  const auto m = associate({1.0, 1.02}, {0.995, 1.01, 1.02}, 0.02);
  ASSERT_EQ(m.size(), 2u);
  EXPECT_EQ(m[0], std::make_pair(std::size_t{0}, std::size_t{0}));
  EXPECT_EQ(m[1], std::make_pair(std::size_t{1}, std::size_t{2}));
  // Every pair within the window is a candidate (TUM's associate.py): 15,000 poses at one
  // timestamp make 2.25e8 of them, which ran out of memory at 3 GB. Refused, counted first.
  const std::vector<double> same(15000, 5.0);
  try {
    associate(same, same, 0.02);
    ADD_FAILURE() << "2.25e8 candidate pairs were built";
  } catch (const vola::InvalidArgument& e) {
    EXPECT_NE(std::string(e.what()).find("225000000 pairs lie within"), std::string::npos) << e.what();
  }
}

TEST(SlamSequence, MissingSequenceSaysWhatIsMissing) {
  ScratchDir dir("empty");
  const std::string message = format_error([&] { read_sequence(dir.path().string()); });
  EXPECT_NE(message.find("no depth.txt"), std::string::npos) << message;
}

TEST(SlamSequence, SharedIclNuimAndKinectFrames) {
  VOLA_REQUIRE_RGBD(rgbd);
  const Sequence icl = read_sequence((rgbd / "iclnuim_slambook2_ch12").string());
  ASSERT_EQ(icl.frames.size(), 5u);
  ASSERT_EQ(icl.groundtruth.size(), 5u);
  EXPECT_FALSE(icl.frames[0].rgb_path.empty());
  // EXPECTED.txt: depth/1.png 640x480, min 8215, max 17160, every pixel measured.
  const DepthImage d = read_depth(icl.frames[0].depth_path, 5000.0);
  ASSERT_EQ(d.width, 640u);
  ASSERT_EQ(d.height, 480u);
  const auto [lo, hi] = std::minmax_element(d.metres.begin(), d.metres.end());
  EXPECT_FLOAT_EQ(*lo, static_cast<float>(8215 / 5000.0));
  EXPECT_FLOAT_EQ(*hi, static_cast<float>(17160 / 5000.0));
  EXPECT_NEAR(icl.groundtruth[0].pose.translation().z(), -2.24935, 1e-9);
  const Sequence kinect = read_sequence((rgbd / "kinect_slambook2_ch5").string());
  ASSERT_EQ(kinect.frames.size(), 5u);
  const DepthImage k = read_depth(kinect.frames[0].depth_path, 1000.0);
  EXPECT_EQ(k.width, 640u);
  EXPECT_GT(std::count(k.metres.begin(), k.metres.end(), 0.0f), 1000);  // Kinect holes
}

}  // namespace

namespace {

TEST(SlamSequence, ImplausibleDepthUnitIsWarnedAbout) {
  FusionParams p;
  DepthImage depth{32, 24, std::vector<float>(32 * 24, 2.5f)};
  EXPECT_FALSE(depth_unit_warning(depth, "d.png", 5000.0, p));
  // Millimetres read as TUM's fifths of a millimetre: a room 5 times too deep.
  for (float& d : depth.metres) d *= 5.0f;
  const auto too_far = depth_unit_warning(depth, "d.png", 1000.0, p);
  ASSERT_TRUE(too_far);
  EXPECT_NE(too_far->find("d.png: median depth 12.5 m"), std::string::npos) << *too_far;
  EXPECT_NE(too_far->find("depth factor"), std::string::npos) << *too_far;
  for (float& d : depth.metres) d = 0.02f;
  EXPECT_TRUE(depth_unit_warning(depth, "d.png", 5000.0, p));
  for (float& d : depth.metres) d = 7.0f;  // plausible, but beyond --max-depth 5
  const auto outside = depth_unit_warning(depth, "d.png", 5000.0, p);
  ASSERT_TRUE(outside);
  EXPECT_NE(outside->find("100% of the measured depth lies outside"), std::string::npos) << *outside;
}

TEST(SlamSequence, ColourOfAnotherSizeThanDepthIsAnErrorNamingTheFile) {
  ScratchDir dir("sizes");
  fs::create_directories(dir.path() / "depth");
  fs::create_directories(dir.path() / "color");
  write_depth_png((dir.path() / "depth/1.png").string(), DepthImage{16, 12, std::vector<float>(16 * 12, 1.0f)}, 5000.0);
  write_rgb_png((dir.path() / "color/1.png").string(), RgbImage{8, 6, std::vector<std::uint8_t>(8 * 6 * 3, 100)});
  const Sequence s = read_sequence(dir.path().string());
  FuseOptions o;
  o.params.voxel_size = 0.05;
  o.params.truncation = 0.2;
  SparseTsdfStore store(centred_geometry(Eigen::Vector3d::Zero(), o.params.voxel_size, 64));
  const std::string message = format_error([&] { fuse_sequence(s, o, store); });
  EXPECT_NE(message.find("color/1.png"), std::string::npos) << message;
  EXPECT_NE(message.find("colour frame is 8 x 6, its depth frame 16 x 12"), std::string::npos) << message;
}

}  // namespace
