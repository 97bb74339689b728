// The SLAM pipeline's parallel stages (bilateral filter, TSDF integration, model
// raycast, ICP sums) run on vola::parallel_for: an error thrown on a worker thread
// reaches the caller of Fusion::process as that same vola::Error.
#include <gtest/gtest.h>

#include <cmath>

#include "slam_test_support.hpp"
#include "parallel_fault.hpp"
#include "vola/slam/fuse_sequence.hpp"
#include "vola/slam/fusion.hpp"

namespace {

using namespace vola::slam;

constexpr std::uint32_t kWidth = 64, kHeight = 48;
const Intrinsics kIntrinsics{50.0, 50.0, 31.5, 23.5};

// A wall 1.5 m ahead with a bump in the middle, seen from the origin along +z.
DepthImage wall() {
  DepthImage d{kWidth, kHeight, std::vector<float>(std::size_t{kWidth} * kHeight)};
  for (std::uint32_t y = 0; y < kHeight; ++y)
    for (std::uint32_t x = 0; x < kWidth; ++x) {
      const double dx = (x - 32.0) / 10.0, dy = (y - 24.0) / 10.0;
      d.metres[y * kWidth + x] = static_cast<float>(1.5 - 0.2 * std::exp(-dx * dx - dy * dy));
    }
  return d;
}

// Two frames through a fresh map: the first integrates (filter, integration, raycast),
// the second also tracks.
void fuse_two_frames() {
  SparseTsdfStore store(centred_geometry(Eigen::Vector3d(0, 0, 1.5), 0.02, 256));
  Fusion<SparseTsdfStore> fusion(store, kIntrinsics, kWidth, kHeight, vola_slam_test::small_scene_params());
  const DepthImage depth = wall();
  fusion.process(depth, nullptr);
  fusion.process(depth, nullptr);
}

TEST(SlamParallel, AWorkerErrorInEveryStageReachesTheCaller) {
  for (const char* stage : {"slam.bilateral_filter", "slam.integrate", "slam.raycast", "slam.track"})
    vola_test::expect_worker_error_reaches_caller(stage, fuse_two_frames);
  fuse_two_frames();  // without a fault it runs
}

// A principal point off the image is a wrong intrinsics file (cx = 1e9 ran for minutes).
TEST(SlamParallel, APrincipalPointOffTheImageIsRefused) {
  SparseTsdfStore store(centred_geometry(Eigen::Vector3d(0, 0, 1.5), 0.02, 256));
  for (const auto& [cx, cy] : {std::pair{1e9, kIntrinsics.cy}, std::pair{-1.0, kIntrinsics.cy},
                               std::pair{kIntrinsics.cx, kHeight + 1.0}}) {
    Intrinsics k = kIntrinsics;
    k.cx = cx;
    k.cy = cy;
    EXPECT_THROW(Fusion<SparseTsdfStore>(store, k, kWidth, kHeight, vola_slam_test::small_scene_params()),
                 vola::InvalidArgument);
  }
  // So are focal lengths no camera has (1e300 ended in "no depth was measured").
  for (const double f : {1e300, 1e-300, -1e300}) {
    Intrinsics k = kIntrinsics;
    k.fx = f;
    EXPECT_THROW(Fusion<SparseTsdfStore>(store, k, kWidth, kHeight, vola_slam_test::small_scene_params()),
                 vola::InvalidArgument);
  }
  EXPECT_NO_THROW(Fusion<SparseTsdfStore>(store, kIntrinsics, kWidth, kHeight, vola_slam_test::small_scene_params()));
}

TEST(SlamParallel, PerPixelStagesDoNotDependOnTheThreadCount) {
  const DepthImage depth = wall();
  const DepthImage one = bilateral_filter(depth, 3, 4.5, 0.03, 1);
  for (const unsigned threads : {2u, 3u, 8u}) EXPECT_EQ(bilateral_filter(depth, 3, 4.5, 0.03, threads).metres, one.metres);

  SparseTsdfStore store(centred_geometry(Eigen::Vector3d(0, 0, 1.5), 0.02, 256));
  Fusion<SparseTsdfStore> fusion(store, kIntrinsics, kWidth, kHeight, vola_slam_test::small_scene_params());
  fusion.process(depth, nullptr);
  FusionParams p = vola_slam_test::small_scene_params();
  p.threads = 1;
  const VertexMap a = raycast(store, kIntrinsics, kWidth, kHeight, Pose::Identity(), p);
  std::size_t valid = 0;
  for (std::size_t i = 0; i < a.vertices.size(); ++i) valid += a.valid(i);
  EXPECT_GT(valid, std::size_t{kWidth} * kHeight / 2);
  for (const unsigned threads : {2u, 5u}) {
    p.threads = threads;
    const VertexMap b = raycast(store, kIntrinsics, kWidth, kHeight, Pose::Identity(), p);
    ASSERT_EQ(b.vertices.size(), a.vertices.size());
    for (std::size_t i = 0; i < a.vertices.size(); ++i) {
      ASSERT_EQ(a.valid(i), b.valid(i)) << i;
      if (a.valid(i)) {
        EXPECT_EQ(a.vertices[i], b.vertices[i]) << i;
        EXPECT_EQ(a.normals[i], b.normals[i]) << i;
      }
    }
  }
}

}  // namespace
