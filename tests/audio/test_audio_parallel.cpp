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

}  // namespace
