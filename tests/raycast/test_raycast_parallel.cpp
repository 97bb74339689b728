// The ray caster's parallel stages (cast over many rays, render) run on
// vola::parallel_for: an error thrown on a worker thread reaches the caller as that same
// vola::Error, and the results do not depend on the thread count.
#include <gtest/gtest.h>

#include <random>

#include "parallel_fault.hpp"
#include "raycast_test_scenes.hpp"
#include "vola/raycast/ray_caster.hpp"
#include "vola/raycast/render.hpp"

namespace {

using namespace vola::raycast;

TEST(RaycastParallel, AWorkerErrorInEveryStageReachesTheCaller) {
  const vola::Tree tree = raycast_test::random_tree(7, 4);
  const RayCaster caster(tree);
  std::mt19937_64 rng(11);
  const std::vector<Ray> rays = raycast_test::mixed_rays(tree, 3000, rng);
  std::vector<std::optional<RayHit>> hits(rays.size());
  vola_test::expect_worker_error_reaches_caller("raycast.cast", [&] { caster.cast(rays, hits, 2); });

  PinholeCamera camera;
  const double side = tree.side();
  camera.eye = {-0.5 * side, -0.4 * side, 1.3 * side};
  camera.look_at = {0.5 * side, 0.5 * side, 0.5 * side};
  camera.width = 64;
  camera.height = 48;
  vola_test::expect_worker_error_reaches_caller("raycast.render", [&] { render(caster, camera, 2); });

  // Without a fault: every thread count gives the same hits and pixels as one thread.
  std::vector<std::optional<RayHit>> one(rays.size());
  caster.cast(rays, one, 1);
  const Rendering image = render(caster, camera, 1);
  EXPECT_GT(image.hits, 0u);
  for (const unsigned threads : {0u, 2u, 3u, 7u}) {
    std::vector<std::optional<RayHit>> many(rays.size());
    caster.cast(rays, many, threads);
    EXPECT_TRUE(many == one) << threads << " threads";
    const Rendering again = render(caster, camera, threads);
    EXPECT_EQ(again.depth, image.depth);
    EXPECT_EQ(again.rgb, image.rgb);
    EXPECT_EQ(again.hits, image.hits);
  }
}

}  // namespace
