// The auralisation's parallel stages (binning reflections in threshold(), the block
// convolution) run on vola::parallel_for: an error thrown on a worker thread reaches
// the caller as that same vola::Error.
#include <gtest/gtest.h>

#include <cmath>

#include "audio_test_support.hpp"
#include "parallel_fault.hpp"
#include "vola/audio/convolve.hpp"
#include "vola/audio/materials.hpp"
#include "vola/audio/response.hpp"
#include "vola/audio/room_response.hpp"

namespace {

using namespace vola;
using namespace vola::audio;

TEST(AudioParallel, AWorkerErrorInEveryStageReachesTheCaller) {
  const Tree room = vola_audio_test::shoebox_tree({{10, 12, 8}, {200, 150, 100}}, 1.0 / 32.0);
  const AcousticScene scene(room, scene_material(0.7));
  ResponseOptions o;
  o.reflection_window = 0.03;
  o.threads = 2;
  const Point s{60.0 / 32, 50.0 / 32, 40.0 / 32}, l{130.0 / 32, 90.0 / 32, 60.0 / 32};
  vola_test::expect_worker_error_reaches_caller("audio.threshold", [&] { threshold(scene, s, l, o); });

  std::vector<double> filter(300), signal(40000);  // 4096-point FFTs: 11 blocks
  for (std::size_t i = 0; i < filter.size(); ++i) filter[i] = std::exp(-0.01 * static_cast<double>(i));
  for (std::size_t i = 0; i < signal.size(); ++i) signal[i] = std::sin(0.001 * static_cast<double>(i * i));
  const Convolver convolver(filter);
  vola_test::expect_worker_error_reaches_caller("audio.convolve", [&] { convolver.apply(signal, 2); });

  // Without a fault both run, and the convolution does not depend on the threads.
  EXPECT_GT(threshold(scene, s, l, o).reflectors, 0u);
  const std::vector<double> one = convolver.apply(signal, 1);
  EXPECT_EQ(convolver.apply(signal, 2), one);
  EXPECT_EQ(convolver.apply(signal, 5), one);
}

// The physical response's stages (image-source tracing, the traced tail, the partitioned
// convolution): a worker's error reaches the caller, and without one the response is the
// same on any number of threads (chunks are fixed and joined in order; each has its own
// random numbers).
TEST(AudioParallel, ThePhysicalResponseIsTheSameOnAnyThreadCount) {
  const Tree tree = vola_audio_test::shoebox_tree({{3, 3, 3}, {44, 36, 28}}, 0.1);
  const AcousticScene scene(tree, scene_material(std::sqrt(0.7)));
  const Room room(scene);
  RoomOptions o;
  o.rays = 3000;
  o.max_length = 0.4;
  o.threads = 2;
  const Point s{1.3, 1.4, 1.1}, l{3.1, 2.2, 1.7};
  // Order 5: thousands of images, so the tracing has chunks for a worker (256 a chunk).
  RoomOptions deep = o;
  deep.order = 5;
  vola_test::expect_worker_error_reaches_caller("audio.image_sources", [&] { image_sources(room, s, l, deep); });
  vola_test::expect_worker_error_reaches_caller("audio.late_energy", [&] { late_energy(room, s, l, 3, o); });
  std::vector<double> filter(40000), signal(20000);
  for (std::size_t i = 0; i < filter.size(); ++i) filter[i] = std::exp(-0.0001 * static_cast<double>(i));
  for (std::size_t i = 0; i < signal.size(); ++i) signal[i] = std::sin(0.001 * static_cast<double>(i * i));
  const PartitionedConvolver partitioned(filter, 4096);
  vola_test::expect_worker_error_reaches_caller("audio.convolve_partitioned", [&] { partitioned.apply(signal, 2); });

  o.threads = 1;
  const RoomResponse one = room_response(room, s, l, o);
  ASSERT_GT(one.early.images.size(), 10u);
  ASSERT_FALSE(one.late.energy.empty());
  for (const unsigned threads : {2u, 3u, 8u}) {
    o.threads = threads;
    const RoomResponse many = room_response(room, s, l, o);
    EXPECT_EQ(many.ir, one.ir) << threads << " threads";
    EXPECT_EQ(many.early.images.size(), one.early.images.size());
  }
}

}  // namespace
