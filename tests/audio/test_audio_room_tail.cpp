// The late tail against room acoustics computed here: in a closed shoebox the response's
// reverberation time T30 (Schroeder backward integration, a line fitted from -5 to -35 dB)
// must be within 10% of Eyring's formula, T = 24 ln(10) V / (c S (-ln(1 - alpha))); an
// open scene must decay without ringing.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <tuple>
#include <utility>
#include <string>

#include "audio_test_support.hpp"
#include "vola/audio/room_response.hpp"
#include "vola/builder.hpp"

namespace test_audio_room_tail {
namespace {

using namespace vola;
using namespace vola::audio;
using vola_audio_test::Shoebox;
using vola_audio_test::shoebox_tree;
using vola_audio_test::t30;

constexpr double kC = 343.0;
constexpr double kRate = 16000.0;  // the decay's shape, not its bandwidth, is under test

double eyring(double lx, double ly, double lz, double absorption) {
  const double volume = lx * ly * lz, surface = 2.0 * (lx * ly + ly * lz + lz * lx);
  return 24.0 * std::log(10.0) * volume / (kC * surface * -std::log(1.0 - absorption));
}

struct Case {
  double size[3];
  double absorption;
};

TEST(AudioRoomTail, ClosedShoeboxT30FollowsEyring) {
  const double voxel = 0.1;
  for (const Case& c : {Case{{3.0, 2.4, 2.0}, 0.5}, Case{{6.0, 4.8, 3.0}, 0.2}, Case{{5.0, 4.0, 2.8}, 0.35},
                        Case{{4.0, 3.2, 2.4}, 0.05}}) {
    const std::string name = std::to_string(c.size[0]) + " x " + std::to_string(c.size[1]) + " x " +
                             std::to_string(c.size[2]) + " m, absorption " + std::to_string(c.absorption);
    SCOPED_TRACE(name);
    // Inside faces from 0.4 m to 0.4 m + size.
    Shoebox box{};
    for (int a = 0; a < 3; ++a) {
      box.lo[a] = 3;
      box.hi[a] = 4 + static_cast<std::uint32_t>(std::lround(c.size[a] / voxel));
    }
    const Tree tree = shoebox_tree(box, voxel);
    const AcousticScene scene(tree, scene_material(std::sqrt(1.0 - c.absorption)));
    const Room room(scene);
    RoomOptions o;
    o.sample_rate = kRate;
    o.speed_of_sound = kC;
    o.rays = 16000;
    o.threads = 2;
    const double expected = eyring(c.size[0], c.size[1], c.size[2], c.absorption);
    o.max_length = 1.5 * expected;
    const Point s{0.4 + 0.31 * c.size[0], 0.4 + 0.37 * c.size[1], 0.4 + 0.45 * c.size[2]};
    const Point l{0.4 + 0.72 * c.size[0], 0.4 + 0.61 * c.size[1], 0.4 + 0.52 * c.size[2]};
    const RoomResponse r = room_response(room, s, l, o);
    const double measured = t30(r.ir, kRate);
    std::printf("%s: T30 %.3f s, Eyring %.3f s (%+.1f%%), %zu images of order <= %d, receiver %.2f m\n", name.c_str(),
                measured, expected, 100.0 * (measured / expected - 1.0), r.early.images.size(), r.early.order,
                r.late.receiver_radius);
    EXPECT_NEAR(measured / expected, 1.0, 0.10);
  }
}

TEST(AudioRoomTail, OpenSceneDecaysWithoutRinging) {
  // Rolling ground with houses, open to the sky (a survey's kind of scene, 50 m across in
  // 0.25 m voxels): the sound leaves. After the direct sound, the energy in 10 ms windows
  // never climbs back more than 3 dB above what came in the windows before it (no flutter,
  // no recurring bursts), the Schroeder curve falls 60 dB, and 100 ms after the direct
  // sound the response is 20 dB below it.
  const double voxel = 0.25;
  std::vector<Voxel> voxels;
  for (std::uint32_t y = 0; y < 200; ++y)
    for (std::uint32_t x = 0; x < 200; ++x) {
      const auto ground = static_cast<std::uint32_t>(std::lround(8.0 + 4.0 * std::sin(x / 23.0) * std::cos(y / 17.0)));
      for (std::uint32_t z = 0; z <= ground; ++z) voxels.push_back({x, y, z});
      // Four houses, 6 m x 8 m x 5 m.
      for (const auto& [hx, hy] : {std::pair{40u, 50u}, {120u, 60u}, {70u, 130u}, {150u, 150u}})
        if (x >= hx && x < hx + 24 && y >= hy && y < hy + 32)
          for (std::uint32_t z = ground + 1; z <= 30; ++z) voxels.push_back({x, y, z});
    }
  std::sort(voxels.begin(), voxels.end(), [](const Voxel& a, const Voxel& b) { return std::tie(a.x, a.y, a.z) < std::tie(b.x, b.y, b.z); });
  Tree tree = build_from_voxels(voxels, 4);
  tree.set_frame(Frame{Quantization::grid, {0, 0, 0}, voxel});
  const AcousticScene scene(tree, scene_material(std::sqrt(1.0 - 0.1)));
  const Room room(scene);
  RoomOptions o;
  o.sample_rate = kRate;
  o.rays = 8000;
  o.threads = 2;
  o.max_length = 2.0;
  // Between the first two houses, 1.7 m and 1.2 m above the ground there.
  auto above_ground = [&](double x, double y, double h) {
    const auto g = static_cast<double>(std::lround(8.0 + 4.0 * std::sin(std::floor(x / voxel) / 23.0) * std::cos(std::floor(y / voxel) / 17.0)));
    return Point{x, y, (g + 1.0) * voxel + h};
  };
  const RoomResponse r = room_response(room, above_ground(22.0, 15.0, 1.7), above_ground(29.0, 19.0, 1.2), o);
  ASSERT_FALSE(r.direct_blocked);
  ASSERT_GT(r.late.energy.size(), 30u) << "no tail to judge";
  const std::size_t window = static_cast<std::size_t>(0.01 * kRate);
  std::vector<double> energy;
  for (std::size_t i = 0; i < r.ir.size(); i += window) {
    double e = 0.0;
    for (std::size_t j = i; j < std::min(r.ir.size(), i + window); ++j) e += r.ir[j] * r.ir[j];
    energy.push_back(e);
  }
  const std::size_t direct = r.direct_sample / window;
  double loudest = energy[direct];
  for (std::size_t k = direct + 1; k < energy.size(); ++k) {
    EXPECT_LE(10.0 * std::log10(energy[k] / loudest), 3.0) << "window " << k << " rises above the windows before it";
    loudest = std::max(loudest, energy[k]);
  }
  std::vector<double> edc(r.ir.size() + 1, 0.0);
  for (std::size_t i = r.ir.size(); i-- > 0;) edc[i] = edc[i + 1] + r.ir[i] * r.ir[i];
  EXPECT_LT(edc[r.ir.size() - 1] / edc[0], 1e-6);
  const std::size_t later = direct + 10;
  ASSERT_LT(later, energy.size());
  EXPECT_LT(energy[later], energy[direct] * 1e-2);
  std::printf("open scene: %zu patches, %zu images of order <= %d, tail %zu ms, window +100 ms at %.1f dB re direct\n",
              room.patches().patches().size(), r.early.images.size(), r.early.order, r.late.energy.size(),
              10.0 * std::log10(energy[later] / energy[direct]));
}

}  // namespace
}  // namespace test_audio_room_tail
