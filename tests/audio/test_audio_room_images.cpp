// The physical response's early part against the image-source method (Allen and Berkley
// 1979) computed here: a floor and a shoebox room at 0.2, 0.1 and 0.05 m voxels. The
// first-order reflections must carry the image source's energy (within +-1 dB) at its
// arrival (within one sample) whatever the voxel size: the voxel-by-voxel model's level
// grew each time the voxel size halved.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>

#include "audio_test_support.hpp"
#include "vola/audio/room_response.hpp"
#include "vola/builder.hpp"

namespace test_audio_room_images {
namespace {

using namespace vola;
using namespace vola::audio;
using vola_audio_test::Shoebox;
using vola_audio_test::shoebox_tree;

constexpr double kC = 343.0;
constexpr double kRate = 48000.0;
constexpr double kAbsorption = 0.3;
constexpr double kScattering = 0.1;

double dist(const Point& a, const Point& b) {
  return std::sqrt((a[0] - b[0]) * (a[0] - b[0]) + (a[1] - b[1]) * (a[1] - b[1]) + (a[2] - b[2]) * (a[2] - b[2]));
}

RoomOptions early_only(int order) {
  RoomOptions o;
  o.sample_rate = kRate;
  o.speed_of_sound = kC;
  o.order = order;
  o.scattering = kScattering;
  o.rays = 0;
  o.max_length = 0.2;
  o.threads = 1;
  return o;
}

// The image-source reflection of the plane `axis` = plane: arrival (samples) and energy.
struct Expected {
  double sample = 0.0, energy = 0.0;
};
Expected image_reflection(const Point& s, const Point& l, int axis, double plane) {
  Point image = s;
  image[axis] = 2.0 * plane - s[axis];
  const double path = dist(image, l);
  // Pressure reflection sqrt(1 - absorption), the specular part sqrt(1 - scattering).
  const double amplitude = std::sqrt(1.0 - kAbsorption) * std::sqrt(1.0 - kScattering) / path;
  return {path / kC * kRate, amplitude * amplitude};
}

double db(double ratio) { return 10.0 * std::log10(ratio); }

// The response's energy in the samples within one of `sample`.
double energy_near(const std::vector<double>& ir, double sample) {
  const auto n = static_cast<std::size_t>(std::nearbyint(sample));
  double e = 0.0;
  for (std::size_t i = n - 1; i <= n + 1 && i < ir.size(); ++i) e += ir[i] * ir[i];
  return e;
}

// A floor 6.4 m square, one voxel thick, its top face at z = 0.4 m.
Tree floor_tree(double voxel) {
  const auto n = static_cast<std::uint32_t>(std::lround(6.4 / voxel));
  const auto k = static_cast<std::uint32_t>(std::lround(0.4 / voxel)) - 1;
  std::vector<Voxel> voxels;
  for (std::uint32_t y = 0; y < n; ++y)
    for (std::uint32_t x = 0; x < n; ++x) voxels.push_back({x, y, k});
  Tree tree = build_from_voxels(voxels, 4);
  tree.set_frame(Frame{Quantization::grid, {0, 0, 0}, voxel});
  return tree;
}

TEST(AudioRoomImages, FloorReflectionHasTheImageSourceEnergyAtEveryVoxelSize) {
  const Point s{1.7, 2.3, 1.6}, l{4.1, 3.3, 1.2};
  const Expected expected = image_reflection(s, l, 2, 0.4);
  for (const double voxel : {0.2, 0.1, 0.05}) {
    SCOPED_TRACE("voxel " + std::to_string(voxel));
    const Tree tree = floor_tree(voxel);
    const AcousticScene scene(tree, scene_material(std::sqrt(1.0 - kAbsorption)));
    const Room room(scene);
    const RoomResponse r = room_response(room, s, l, early_only(1));
    ASSERT_EQ(r.early.images.size(), 1u);
    const ImageSource& is = r.early.images[0];
    EXPECT_LE(std::abs(is.delay * kRate - expected.sample), 1.0);
    EXPECT_NEAR(db(is.amplitude * is.amplitude / expected.energy), 0.0, 1.0);
    EXPECT_NEAR(is.points[0][2], 0.4, 1e-9);  // on the floor's surface
    // In the response: the direct sound, then the reflection's energy at its sample.
    // The direct sound is a band-limited impulse (16 samples either side, taps summing to
    // one): its samples add up to its amplitude.
    double direct = 0.0;
    for (std::size_t i = r.direct_sample - 16; i <= r.direct_sample + 16; ++i) direct += r.ir[i];
    EXPECT_NEAR(direct, 1.0 / dist(s, l), 1e-12);
    EXPECT_NEAR(db(energy_near(r.ir, expected.sample) / expected.energy), 0.0, 1.0);
    // With the ray-traced tail too: the energy within 1 ms of the arrival.
    RoomOptions full = early_only(1);
    full.rays = 20000;
    const RoomResponse with_tail = room_response(room, s, l, full);
    const auto first = static_cast<std::size_t>(std::nearbyint(expected.sample));
    double e = 0.0;
    for (std::size_t i = first - 1; i < first + 48 && i < with_tail.ir.size(); ++i) e += with_tail.ir[i] * with_tail.ir[i];
    EXPECT_NEAR(db(e / expected.energy), 0.0, 1.0) << "with the tail";
    std::printf("floor, %.2f m voxels: reflection %+.3f dB (with the tail, 1 ms: %+.3f dB), arrival %+.2f samples\n", voxel,
                db(energy_near(r.ir, expected.sample) / expected.energy), db(e / expected.energy),
                is.delay * kRate - expected.sample);
  }
}

TEST(AudioRoomImages, ShoeboxFirstOrderReflectionsMatchImageSourcesAtEveryVoxelSize) {
  // The room's inside faces: x in [0.4, 4.4], y in [0.4, 3.6], z in [0.4, 2.8] m.
  const double lo[3] = {0.4, 0.4, 0.4}, hi[3] = {4.4, 3.6, 2.8};
  const Point s{1.13, 1.27, 1.51}, l{3.05, 2.41, 1.17};
  for (const double voxel : {0.2, 0.1, 0.05}) {
    SCOPED_TRACE("voxel " + std::to_string(voxel));
    Shoebox box{};
    for (int a = 0; a < 3; ++a) {
      box.lo[a] = static_cast<std::uint32_t>(std::lround(lo[a] / voxel)) - 1;
      box.hi[a] = static_cast<std::uint32_t>(std::lround(hi[a] / voxel));
    }
    const Tree tree = shoebox_tree(box, voxel);
    const AcousticScene scene(tree, scene_material(std::sqrt(1.0 - kAbsorption)));
    const Room room(scene);
    const RoomResponse r = room_response(room, s, l, early_only(1));
    EXPECT_EQ(r.early.images.size(), 6u) << "one image per wall, none from the outside faces";
    double worst_db = 0.0, worst_samples = 0.0;
    for (int axis = 0; axis < 3; ++axis)
      for (const double plane : {lo[axis], hi[axis]}) {
        const Expected expected = image_reflection(s, l, axis, plane);
        const ImageSource* found = nullptr;
        for (const ImageSource& is : r.early.images)
          if (std::abs(is.points[0][axis] - plane) < 1e-9) found = &is;
        ASSERT_NE(found, nullptr) << "no reflection from the wall at " << plane << " on axis " << axis;
        EXPECT_LE(std::abs(found->delay * kRate - expected.sample), 1.0) << "axis " << axis << " plane " << plane;
        EXPECT_NEAR(db(found->amplitude * found->amplitude / expected.energy), 0.0, 1.0);
        EXPECT_NEAR(db(energy_near(r.ir, expected.sample) / expected.energy), 0.0, 1.0)
            << "axis " << axis << " plane " << plane;
        worst_db = std::max(worst_db, std::abs(db(energy_near(r.ir, expected.sample) / expected.energy)));
        worst_samples = std::max(worst_samples, std::abs(found->delay * kRate - expected.sample));
      }
    std::printf("shoebox, %.2f m voxels: six first-order reflections, worst %.3f dB, worst arrival %.2f samples\n", voxel,
                worst_db, worst_samples);
  }
}

TEST(AudioRoomImages, SecondOrderImagesOfAShoeboxAreTheMirroredMirrors) {
  // Order 2 in a shoebox (Allen and Berkley): 4 n^2 + 2 = 18 images. Opposite walls give
  // one path in each order (6); two walls meeting at an edge give one image whichever is
  // taken first, and only one of the two orders is a real path (12 edges). Each has the
  // amplitude (R sqrt(1 - s))^2 / |image - listener|.
  const double voxel = 0.1;
  const double lo[3] = {0.4, 0.4, 0.4}, hi[3] = {4.4, 3.6, 2.8};
  Shoebox box{};
  for (int a = 0; a < 3; ++a) {
    box.lo[a] = static_cast<std::uint32_t>(std::lround(lo[a] / voxel)) - 1;
    box.hi[a] = static_cast<std::uint32_t>(std::lround(hi[a] / voxel));
  }
  const Tree tree = shoebox_tree(box, voxel);
  const AcousticScene scene(tree, scene_material(std::sqrt(1.0 - kAbsorption)));
  const Room room(scene);
  const Point s{1.13, 1.27, 1.51}, l{3.05, 2.41, 1.17};
  const RoomResponse r = room_response(room, s, l, early_only(2));
  EXPECT_EQ(r.early.order, 2);
  std::size_t second = 0;
  for (const ImageSource& is : r.early.images) {
    if (is.patches.size() != 2) continue;
    ++second;
    // The image: the source mirrored in the first wall, then in the second.
    Point image = s;
    for (const Point& p : is.points) {
      int axis = -1;
      double plane = 0.0;
      for (int a = 0; a < 3; ++a)
        for (const double c : {lo[a], hi[a]})
          if (std::abs(p[a] - c) < 1e-9) axis = a, plane = c;
      ASSERT_GE(axis, 0) << "a reflection point not on a wall";
      image[axis] = 2.0 * plane - image[axis];
    }
    const double path = dist(image, l);
    EXPECT_NEAR(is.path, path, 1e-9);
    const double amplitude = (1.0 - kAbsorption) * (1.0 - kScattering) / path;
    EXPECT_NEAR(db(is.amplitude * is.amplitude / (amplitude * amplitude)), 0.0, 1e-9);
  }
  EXPECT_EQ(second, 18u);
}

}  // namespace
}  // namespace test_audio_room_images
