// Binaural rendering against the SOFA data itself (read here through libmysofa): a source
// 90 degrees to the left or right of the listener gives the interaural time and level
// differences of the HRTF measured from that direction, and a source ahead of a listener
// turned by 90 degrees is a source at the side.
#include <gtest/gtest.h>
#include <mysofa.h>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>

#include "vola/audio/binaural.hpp"
#include "vola/builder.hpp"
#include "vola/error.hpp"

namespace {

using namespace vola;
using namespace vola::audio;

const char* const kSofa = "/usr/share/libmysofa/MIT_KEMAR_normal_pinna.sofa";
constexpr double kRate = 48000.0;

// Interaural time difference (samples, > 0 when the left ear leads) as the lag of the
// cross-correlation's peak, and level difference (dB, left over right).
struct Interaural {
  int itd = 0;
  double ild = 0.0;
};
Interaural interaural(const std::vector<double>& left, const std::vector<double>& right) {
  Interaural r;
  double best = -1.0, el = 0.0, er = 0.0;
  const int n = static_cast<int>(std::min(left.size(), right.size()));
  for (int lag = -60; lag <= 60; ++lag) {
    double sum = 0.0;
    for (int i = 0; i < n; ++i)
      if (i + lag >= 0 && i + lag < n) sum += left[static_cast<std::size_t>(i)] * right[static_cast<std::size_t>(i + lag)];
    if (sum > best) best = sum, r.itd = lag;
  }
  for (const double v : left) el += v * v;
  for (const double v : right) er += v * v;
  r.ild = 10.0 * std::log10(el / er);
  return r;
}

// The SOFA file's own filters from a direction (x ahead, y left, z up), at kRate.
Interaural sofa_reference(float x, float y, float z) {
  int length = 0, error = 0;
  MYSOFA_EASY* easy = mysofa_open(kSofa, static_cast<float>(kRate), &length, &error);
  EXPECT_EQ(error, MYSOFA_OK);
  std::vector<float> l(static_cast<std::size_t>(length)), r(static_cast<std::size_t>(length));
  float dl = 0, dr = 0;
  mysofa_getfilter_float(easy, x, y, z, l.data(), r.data(), &dl, &dr);
  mysofa_close(easy);
  const auto shift_l = static_cast<std::size_t>(std::nearbyint(dl * kRate)), shift_r = static_cast<std::size_t>(std::nearbyint(dr * kRate));
  std::vector<double> left(shift_l + l.size(), 0.0), right(shift_r + r.size(), 0.0);
  for (std::size_t i = 0; i < l.size(); ++i) left[shift_l + i] = l[i];
  for (std::size_t i = 0; i < r.size(); ++i) right[shift_r + i] = r[i];
  return interaural(left, right);
}

TEST(AudioBinaural, SourcesAtTheSidesGiveTheHrtfsTimeAndLevelDifferences) {
  if (!std::filesystem::exists(kSofa)) GTEST_SKIP() << kSofa << " is missing (Debian package libmysofa1)";
  // Free field: one voxel far away in a corner of the grid.
  const std::vector<Voxel> corner{Voxel{0, 0, 0}};
  Tree tree = build_from_voxels(corner, 3);
  tree.set_frame(Frame{Quantization::grid, {0, 0, 0}, 0.25});
  const AcousticScene scene(tree, scene_material(0.0));
  const Room room(scene);
  RoomOptions o;
  o.sample_rate = kRate;
  o.rays = 0;
  o.order = 0;
  const Hrtf hrtf(kSofa, kRate);
  const Point listener{8.0, 8.0, 8.0};
  for (const double side : {1.0, -1.0}) {
    SCOPED_TRACE(side > 0 ? "left" : "right");
    // Facing +x, the source 2 m along +y (left) or -y (right).
    const Point source{8.0, 8.0 + 2.0 * side, 8.0};
    const RoomResponse r = room_response(room, source, listener, o);
    const auto ears = binaural_response(r, hrtf, source, listener, 0.0, o);
    const Interaural got = interaural(ears[0], ears[1]);
    const Interaural expected = sofa_reference(0.0f, static_cast<float>(side), 0.0f);
    EXPECT_LE(std::abs(got.itd - expected.itd), 1) << "ITD " << got.itd << " samples, the SOFA's " << expected.itd;
    EXPECT_NEAR(got.ild, expected.ild, 0.5);
    std::printf("source %s: ITD %+d samples (SOFA %+d), ILD %+.2f dB (SOFA %+.2f dB)\n", side > 0 ? "left" : "right", got.itd,
                expected.itd, got.ild, expected.ild);
    // A head: the near ear leads by 0.5 to 0.9 ms and is louder by several dB.
    EXPECT_GT(side * got.itd, 0.5e-3 * kRate);
    EXPECT_LT(side * got.itd, 0.9e-3 * kRate);
    EXPECT_GT(side * got.ild, 5.0);
    // The ear signals start at the direct sound's arrival, its level 1/d at the head.
    for (int ear = 0; ear < 2; ++ear)
      for (std::size_t i = 0; i + 1 < r.direct_sample; ++i) ASSERT_EQ(ears[ear][i], 0.0);
    // Turning the listener a quarter to the left puts a source ahead of it at its right:
    // the same as the source at the right of a listener facing +x.
    if (side < 0) {
      const Point ahead{10.0, 8.0, 8.0};
      const RoomResponse a = room_response(room, ahead, listener, o);
      const auto turned = binaural_response(a, hrtf, ahead, listener, 90.0, o);
      const Interaural t = interaural(turned[0], turned[1]);
      EXPECT_EQ(t.itd, got.itd);
      EXPECT_NEAR(t.ild, got.ild, 1e-9);
    }
  }
}

TEST(AudioBinaural, AFileThatIsNoSofaGivesAClearError) {
  const std::string path = (std::filesystem::temp_directory_path() / "vola_not_a.sofa").string();
  { std::ofstream(path) << "not an HDF5 file"; }
  try {
    Hrtf(path, kRate);
    FAIL() << "a text file loaded as an HRTF";
  } catch (const IoError& e) {
    EXPECT_NE(std::string(e.what()).find("vola_not_a.sofa: cannot load the HRTF (SOFA file): not a SOFA (HDF5) file"),
              std::string::npos)
        << e.what();
  }
  std::filesystem::remove(path);
  // libmysofa gives errno values for file errors: said as words ("libmysofa error 2" before).
  try {
    Hrtf("/nonexistent/x.sofa", kRate);
    FAIL() << "a missing file loaded";
  } catch (const IoError& e) {
    EXPECT_NE(std::string(e.what()).find("No such file or directory"), std::string::npos) << e.what();
  }
}

}  // namespace
