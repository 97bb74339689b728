// Seeds for fuzz_rgbd_read, each prefixed with its selector byte (fuzz_rgbd_read.cpp):
// the depth and colour frames and pose lists of the shared data folder's rgbd/ (beside
// golden/), whole, and 40 x 30 crops of the frames written again by vola (16-bit PNG and
// PGM depth, RGB PNG) so that libFuzzer's inputs stay small; plus TUM lists, a
// trajectory and intrinsics written here. Linked into fuzz_rgbd_read_replay in place of
// fuzz_seeds.cpp.
#include <unistd.h>

#include <algorithm>
#include <fstream>
#include <iterator>
#include <string>

#include "fuzz_seeds.hpp"
#include "vola/slam/image.hpp"

namespace vola_fuzz {
namespace {

namespace fs = std::filesystem;
namespace slam = vola::slam;
using Bytes = std::vector<std::uint8_t>;
enum Kind : std::uint8_t { kDepth = 0, kRgb = 1, kList = 2, kTrajectory = 3, kPoses = 4, kIntrinsics = 5 };

Seed seed(const std::string& name, Kind kind, const Bytes& file) {
  Bytes bytes{kind};
  bytes.insert(bytes.end(), file.begin(), file.end());
  return {name, std::move(bytes)};
}

Seed text(const std::string& name, Kind kind, const std::string& s) { return seed(name, kind, Bytes(s.begin(), s.end())); }

Bytes read_all(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  return Bytes(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
}

fs::path scratch(const std::string& extension) {
  return fs::temp_directory_path() / ("vola_fuzz_rgbd_seed_" + std::to_string(::getpid()) + extension);
}

constexpr std::uint32_t kCropWidth = 40, kCropHeight = 30;

slam::DepthImage crop(const slam::DepthImage& d) {
  slam::DepthImage out;
  out.width = std::min(d.width, kCropWidth);
  out.height = std::min(d.height, kCropHeight);
  const std::uint32_t u0 = (d.width - out.width) / 2, v0 = (d.height - out.height) / 2;
  for (std::uint32_t v = 0; v < out.height; ++v)
    for (std::uint32_t u = 0; u < out.width; ++u) out.metres.push_back(d.at(u0 + u, v0 + v));
  return out;
}

Bytes depth_png(const slam::DepthImage& d) {
  const auto path = scratch(".png");
  slam::write_depth_png(path.string(), d, 1000.0);
  Bytes b = read_all(path);
  fs::remove(path);
  return b;
}

// A 16-bit big-endian PGM of millimetres, with a comment in its header.
Bytes depth_pgm(const slam::DepthImage& d) {
  const std::string head = "P5\n# vola fuzz seed\n" + std::to_string(d.width) + " " + std::to_string(d.height) + "\n65535\n";
  Bytes b(head.begin(), head.end());
  for (float m : d.metres) {
    const auto raw = static_cast<std::uint16_t>(std::min(65535.0, std::max(0.0, m * 1000.0 + 0.5)));
    b.push_back(static_cast<std::uint8_t>(raw >> 8));
    b.push_back(static_cast<std::uint8_t>(raw & 0xff));
  }
  return b;
}

Bytes rgb_png_crop(const slam::RgbImage& image) {
  slam::RgbImage out;
  out.width = std::min(image.width, kCropWidth);
  out.height = std::min(image.height, kCropHeight);
  for (std::uint32_t v = 0; v < out.height; ++v)
    for (std::uint32_t u = 0; u < out.width; ++u)
      for (int c = 0; c < 3; ++c) out.rgb.push_back(image.rgb[(std::size_t{v} * image.width + u) * 3 + static_cast<std::size_t>(c)]);
  const auto path = scratch(".png");
  slam::write_rgb_png(path.string(), out);
  Bytes b = read_all(path);
  fs::remove(path);
  return b;
}

}  // namespace

std::vector<Seed> synthetic_seeds() {
  slam::DepthImage d;
  d.width = 7;
  d.height = 5;
  for (std::uint32_t i = 0; i < d.width * d.height; ++i) d.metres.push_back(i % 4 == 0 ? 0.0f : 0.5f + 0.01f * static_cast<float>(i));
  slam::RgbImage rgb;
  rgb.width = 3;
  rgb.height = 2;
  rgb.rgb = {255, 0, 0, 0, 255, 0, 0, 0, 255, 10, 20, 30, 40, 50, 60, 70, 80, 90};
  const auto rgb_path = scratch(".png");
  slam::write_rgb_png(rgb_path.string(), rgb);
  const Bytes rgb_bytes = read_all(rgb_path);
  fs::remove(rgb_path);
  return {seed("depth7x5.png", kDepth, depth_png(d)),
          seed("depth7x5.pgm", kDepth, depth_pgm(d)),
          seed("rgb3x2.png", kRgb, rgb_bytes),
          text("depth.txt", kList,
               "# depth maps\n# timestamp filename\n1305031102.160407 depth/1305031102.160407.png\n"
               "1305031102.194330 depth/1305031102.194330.png\r\n\n1305031102.226738 depth/1305031102.226738.png\n"),
          text("groundtruth.txt", kTrajectory,
               "# ground truth trajectory\n# timestamp tx ty tz qx qy qz qw\n"
               "1305031098.6659 1.3563 0.6305 1.6380 0.6132 0.5962 -0.3311 -0.3986\n"
               "1305031098.6758 1.3543 0.6306 1.6360 0.6129 0.5966 -0.3316 -0.3980\n"),
          text("intrinsics.txt", kIntrinsics, "# fx fy cx cy (pixels)\n481.2 -480 319.5 239.5\n")};
}

// The frames of every sequence in rgbd/ (whole, and cropped), pose lists and the KITTI
// camera image.
std::vector<Seed> golden_seeds(const fs::path& golden) {
  std::vector<Seed> seeds;
  const auto data = golden.parent_path() / "data";
  const auto folder = shared_data(golden, "rgbd");
  if (folder.empty()) return seeds;
  for (const auto& entry : fs::recursive_directory_iterator(folder)) {
    if (!entry.is_regular_file()) continue;
    const fs::path& p = entry.path();
    const std::string name = fs::relative(p, folder).string();
    std::string flat = name;
    std::replace(flat.begin(), flat.end(), '/', '_');
    const bool depth = p.parent_path().filename() == "depth" || p.stem().string().ends_with("_depth");
    if (p.filename() == "pose.txt") {
      seeds.push_back(seed(flat, kPoses, read_all(p)));
    } else if (p.extension() == ".png" || p.extension() == ".pgm") {
      if (depth) {
        const double factor = p.extension() == ".pgm" ? 1000.0 : 5000.0;
        const auto cropped = crop(slam::read_depth(p.string(), factor));
        seeds.push_back(seed("crop_" + flat, kDepth, p.extension() == ".pgm" ? depth_pgm(cropped) : depth_png(cropped)));
      } else {
        seeds.push_back(seed("crop_" + flat, kRgb, rgb_png_crop(slam::read_rgb_png(p.string()))));
      }
      seeds.push_back(seed(flat, depth ? kDepth : kRgb, read_all(p)));
    }
  }
  const auto kitti = data / "kitti" / "object_training" / "image_2" / "000000.png";
  if (fs::is_regular_file(kitti)) seeds.push_back(seed("crop_kitti_000000.png", kRgb, rgb_png_crop(slam::read_rgb_png(kitti.string()))));
  std::sort(seeds.begin(), seeds.end(), [](const Seed& a, const Seed& b) { return a.name < b.name; });
  return seeds;
}

}  // namespace vola_fuzz
