// The photometric term on the known failure of point-to-plane ICP: a camera sliding
// along a single textured wall at an uneven speed. The plane says nothing about the
// slide; the texture does. Frames are rendered analytically (exact plane, exact colour).
#include <gtest/gtest.h>

#include <cmath>

#include "vola/slam/fusion.hpp"

namespace {

using namespace vola::slam;

constexpr std::uint32_t kWidth = 320, kHeight = 240;
const Intrinsics kCamera{262.5, 262.5, 159.5, 119.5};
constexpr double kWall = 1.5;  // metres in front of the camera (the plane z = 1.5)

double texture(double x, double y) {
  return 0.5 + 0.2 * std::sin(2 * M_PI * x / 0.2) * std::cos(2 * M_PI * y / 0.17) +
         0.15 * std::sin(2 * M_PI * (x + 0.6 * y) / 0.07);
}

// The camera at (x, y, 0) looking along +z at the wall.
void render(double cx, double cy, DepthImage& depth, RgbImage& rgb) {
  depth = {kWidth, kHeight, std::vector<float>(std::size_t{kWidth} * kHeight, static_cast<float>(kWall))};
  rgb = {kWidth, kHeight, std::vector<std::uint8_t>(std::size_t{kWidth} * kHeight * 3)};
  for (std::uint32_t v = 0; v < kHeight; ++v)
    for (std::uint32_t u = 0; u < kWidth; ++u) {
      const double x = cx + (u - kCamera.cx) / kCamera.fx * kWall, y = cy + (v - kCamera.cy) / kCamera.fy * kWall;
      const auto grey = static_cast<std::uint8_t>(std::lround(255.0 * std::clamp(texture(x, y), 0.0, 1.0)));
      for (int c = 0; c < 3; ++c) rgb.rgb[(std::size_t{v} * kWidth + u) * 3 + c] = grey;
    }
}

// Positions along the wall: steps of 0 to 1.6 cm, speeding up and slowing down, with a
// little vertical drift, so a constant-velocity guess is wrong on most frames.
std::vector<Eigen::Vector2d> slide(std::size_t frames) {
  std::vector<Eigen::Vector2d> out{Eigen::Vector2d::Zero()};
  for (std::size_t i = 1; i < frames; ++i)
    out.push_back(out.back() + Eigen::Vector2d(0.008 * (1 + std::sin(0.9 * static_cast<double>(i))),
                                               0.003 * std::cos(1.3 * static_cast<double>(i))));
  return out;
}

// The largest position error over the sequence.
double worst_error(const FusionParams& params) {
  const auto truth = slide(20);
  VolumeGeometry g;
  g.voxel_size = params.voxel_size;
  g.bricks_per_side = 64;
  g.origin = Eigen::Vector3d(-2.56, -2.56, -0.5);
  SparseTsdfStore store(g);
  Fusion<SparseTsdfStore> fusion(store, kCamera, kWidth, kHeight, params);
  double worst = 0.0;
  for (const auto& t : truth) {
    DepthImage depth;
    RgbImage rgb;
    render(t.x(), t.y(), depth, rgb);
    const FrameResult r = fusion.process(depth, &rgb);
    const Eigen::Vector3d expected(t.x(), t.y(), 0.0);
    worst = std::max(worst, r.tracked ? (r.pose.translation() - expected).norm() : 1.0);
  }
  return worst;
}

FusionParams wall_params() {
  FusionParams p;
  p.voxel_size = 0.01;
  p.truncation = 0.04;
  p.threads = 2;
  p.features = false;  // the dense terms alone
  return p;
}

TEST(SlamPhotometric, TextureHoldsASlideAlongAPlaneThatIcpAloneLoses) {
  FusionParams with = wall_params();
  ASSERT_GT(with.photometric_weight, 0.0);  // on by default
  const double photometric = worst_error(with);
  FusionParams without = wall_params();
  without.photometric_weight = 0.0;
  const double geometric = worst_error(without);
  EXPECT_LT(photometric, 0.005) << "geometric only: " << geometric;
  EXPECT_GT(geometric, 0.03) << "the plane alone should not hold the slide";
}

TEST(SlamPhotometric, NegativeWeightIsRefused) {
  FusionParams p;
  p.photometric_weight = -1.0;
  EXPECT_THROW(p.check(), std::exception);
}

}  // namespace
