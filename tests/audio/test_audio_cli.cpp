// vola sonify end to end: a shoebox room written as .vol, a real recording in, the wet
// WAV, the impulse response WAV and the plot out; bad inputs give one clear line.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdlib>
#include <fstream>
#include <limits>
#include <sstream>
#include <vector>

#include "audio_test_support.hpp"
#include "vola/audio/wav.hpp"
#include "vola/file.hpp"

namespace {

namespace fs = std::filesystem;

struct CliRun {
  int status = -1;
  std::string output;
};

CliRun run(const std::string& args, const fs::path& dir) {
  const fs::path log = dir / "log.txt";
  const std::string command = std::string(VOLA_CLI) + " sonify " + args + " > " + log.string() + " 2>&1";
  CliRun r;
  const int raw = std::system(command.c_str());
  r.status = WIFEXITED(raw) ? WEXITSTATUS(raw) : -1;
  std::ifstream in(log);
  std::stringstream s;
  s << in.rdbuf();
  r.output = s.str();
  return r;
}

class SonifyCli : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() / ("vola_sonify_cli_" + std::to_string(::getpid()));
    fs::create_directories(dir_);
    vola::write(vola_audio_test::shoebox_tree({{10, 12, 8}, {200, 150, 100}}, 1.0 / 32.0), (dir_ / "room.vol").string());
  }
  void TearDown() override { fs::remove_all(dir_); }
  std::string path(const std::string& name) const { return (dir_ / name).string(); }
  fs::path dir_;
};

// The samples of an arrival rendered as a band-limited impulse around `at` (its 16 taps
// either side): its amplitude, when no other arrival is that close.
double arrival_sum(const std::vector<double>& channel, std::size_t at) {
  double sum = 0.0;
  for (std::size_t i = at - 16; i <= at + 16 && i < channel.size(); ++i) sum += channel[i];
  return sum;
}

TEST_F(SonifyCli, RealRecordingThroughARoom) {
  VOLA_REQUIRE_AUDIO(audio);
  const std::string dry = (audio / "alsa_Front_Center.wav").string();
  // Source at (2, 1.5, 1.25) m, listener at (4, 3, 2) m: 2.6575 m, 372 samples at 48 kHz.
  const CliRun r = run(path("room.vol") + " --source 2 1.5 1.25 --listener 4 3 2 --in " + dry + " --out " + path("wet.wav") +
                        " --ir " + path("ir.wav") + " --plot " + path("ir.png") + " --window 0.03",
                    dir_);
  ASSERT_EQ(r.status, 0) << r.output;
  EXPECT_NE(r.output.find("source 1: direct"), std::string::npos) << r.output;
  const vola::audio::Sound ir = vola::audio::read_sound(path("ir.wav"));
  ASSERT_EQ(ir.channels.size(), 1u);
  const double d = std::sqrt(2.0 * 2.0 + 1.5 * 1.5 + 0.75 * 0.75);
  const auto direct = static_cast<std::size_t>(std::lround(d / 343.0 * 48000.0));
  ASSERT_GT(ir.frames(), direct);
  // The direct sound is a band-limited impulse at its exact time (16 samples either side,
  // taps summing to one), nothing before it.
  EXPECT_NEAR(arrival_sum(ir.channels[0], direct), 1.0 / d, 1e-5);  // float WAV
  for (std::size_t i = 0; i + 16 < direct; ++i) ASSERT_EQ(ir.channels[0][i], 0.0) << i;
  double later = 0.0;
  for (std::size_t i = direct + 1; i < ir.frames(); ++i) later += std::abs(ir.channels[0][i]);
  EXPECT_GT(later, 0.0) << "no reflections";
  const vola::audio::Sound wet = vola::audio::read_sound(path("wet.wav"));
  EXPECT_EQ(wet.frames(), 68545u + ir.frames() - 1);
  std::ifstream png(path("ir.png"), std::ios::binary);
  char magic[8] = {};
  png.read(magic, 8);
  EXPECT_EQ(std::string(magic + 1, 3), "PNG");
}

TEST_F(SonifyCli, TwoSourcesOneChannelEach) {
  VOLA_REQUIRE_AUDIO(audio);
  const CliRun r = run(path("room.vol") + " --source 2 1.5 1.25 --source 5 3 2 --listener 4 3 2.5 --in " +
                        (audio / "codec2_speech_orig_16k.wav").string() + " --in " +
                        (audio / "soundicons_xylofon.wav").string() + " --out " + path("duo.wav") +
                        " --channels per-source --ir " + path("ir2.wav") + " -q",
                    dir_);
  ASSERT_EQ(r.status, 0) << r.output;
  EXPECT_TRUE(r.output.empty()) << r.output;
  EXPECT_EQ(vola::audio::read_sound(path("duo.wav")).channels.size(), 2u);
  EXPECT_EQ(vola::audio::read_sound(path("ir2.wav")).channels.size(), 2u);
}

TEST_F(SonifyCli, BadInputsFailWithOneClearLine) {
  VOLA_REQUIRE_AUDIO(audio);
  const std::string dry = (audio / "alsa_Front_Center.wav").string();
  const std::string base = path("room.vol") + " --listener 4 3 2 --out " + path("o.wav");
  CliRun r = run(base + " --source 2 1.5 1.25 --in " + path("missing.wav"), dir_);
  EXPECT_NE(r.status, 0);
  EXPECT_NE(r.output.find("missing.wav"), std::string::npos) << r.output;
  std::ofstream(path("bad.json")) << "{\n  \"attribute\": \"classification\",\n  \"materials\": {\"2\": 0.2,,}\n}\n";
  r = run(base + " --source 2 1.5 1.25 --in " + dry + " --materials " + path("bad.json"), dir_);
  EXPECT_EQ(r.status, 1);
  EXPECT_NE(r.output.find("bad.json"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("line 3"), std::string::npos) << r.output;
  // x = 10.5 / 32 m is inside the wall at voxel x = 10.
  r = run(base + " --source 0.328125 1.5 1.25 --in " + dry, dir_);
  EXPECT_EQ(r.status, 1);
  EXPECT_NE(r.output.find("the source"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("inside occupied voxel"), std::string::npos) << r.output;
  std::ofstream(path("ids.json")) << R"({"attribute": "classification", "materials": {"2": 0.2}})";
  r = run(base + " --source 2 1.5 1.25 --in " + dry + " --materials " + path("ids.json"), dir_);
  EXPECT_EQ(r.status, 1);
  EXPECT_NE(r.output.find("no attribute \"classification\""), std::string::npos) << r.output;
  r = run(base + " --source 2 1.5 1.25 --source 3 2 2 --in " + dry + " --in " + dry + " --in " + dry, dir_);
  EXPECT_EQ(r.status, 1);
  EXPECT_NE(r.output.find("one per --source"), std::string::npos) << r.output;
  // Recordings at 48 and 16 kHz.
  r = run(base + " --source 2 1.5 1.25 --source 3 2 2 --in " + dry + " --in " + (audio / "codec2_speech_orig_16k.wav").string(),
          dir_);
  EXPECT_EQ(r.status, 1);
  EXPECT_NE(r.output.find("resample them to one rate"), std::string::npos) << r.output;
  r = run(base + " --source 2 1.5 1.25 --in " + dry + " --absorption 1.5", dir_);
  EXPECT_EQ(r.status, 1);
  EXPECT_NE(r.output.find("--absorption must be in [0, 1]"), std::string::npos) << r.output;
  r = run(base + " --source 2 1.5 1.25 --in " + dry + " --absorption -0.1", dir_);
  EXPECT_EQ(r.status, 1);
  EXPECT_NE(r.output.find("--absorption must be in [0, 1]"), std::string::npos) << r.output;
  // The room's grid is 256 voxels of 1/32 m: 8 m.
  r = run(path("room.vol") + " --listener 9 3 2 --out " + path("o.wav") + " --source 2 1.5 1.25 --in " + dry, dir_);
  EXPECT_EQ(r.status, 1);
  EXPECT_NE(r.output.find("the listener (9, 3, 2) is outside the scene's grid"), std::string::npos) << r.output;
  // One NaN in a float recording made every output sample NaN (-32768 as PCM), exit 0.
  vola::audio::Sound tone;
  tone.sample_rate = 16000;
  tone.channels.assign(1, std::vector<double>(2000, 0.25));
  tone.channels[0][100] = std::numeric_limits<double>::quiet_NaN();
  vola::audio::write_wav(path("nan.wav"), tone, vola::audio::SampleFormat::float32);
  r = run(base + " --source 2 1.5 1.25 --in " + path("nan.wav"), dir_);
  EXPECT_EQ(r.status, 1);
  EXPECT_NE(r.output.find("nan.wav: sample 100 of channel 0 is not a finite number"), std::string::npos) << r.output;
  EXPECT_FALSE(fs::exists(path("o.wav")));
}

// The physical model's flags: a wall between source and listener silences the direct sound
// unless --no-occlusion; --model paper keeps the paper's voxel-by-voxel model.
TEST_F(SonifyCli, OcclusionAndModels) {
  VOLA_REQUIRE_AUDIO(audio);
  const std::string dry = (audio / "alsa_Front_Center.wav").string();
  // Listener outside the closed room (x = 7 m, beyond the wall at voxel 200 = 6.25 m).
  const std::string base = path("room.vol") + " --source 2 1.5 1.25 --listener 7 1.5 1.25 --in " + dry +
                           " --absorption 0.2 --rays 2000 --out " + path("w.wav") + " --ir " + path("ir.wav");
  const double d = 5.0;
  const auto direct = static_cast<std::size_t>(std::lround(d / 343.0 * 48000.0));
  CliRun r = run(base, dir_);
  ASSERT_EQ(r.status, 0) << r.output;
  EXPECT_NE(r.output.find("blocked by the scene"), std::string::npos) << r.output;
  EXPECT_EQ(vola::audio::read_sound(path("ir.wav")).channels[0][direct], 0.0);
  r = run(base + " --no-occlusion", dir_);
  ASSERT_EQ(r.status, 0) << r.output;
  EXPECT_EQ(r.output.find("blocked"), std::string::npos) << r.output;
  EXPECT_NEAR(arrival_sum(vola::audio::read_sound(path("ir.wav")).channels[0], direct), 1.0 / d, 1e-5);
  r = run(base + " --model paper --window 0.02", dir_);
  ASSERT_EQ(r.status, 0) << r.output;
  EXPECT_NE(r.output.find("reflecting voxels in"), std::string::npos) << r.output;
  r = run(base + " --reflection 0.5", dir_);
  EXPECT_NE(r.status, 0) << "--reflection and --absorption both given";
}

TEST_F(SonifyCli, BinauralWritesTheTwoEars) {
  VOLA_REQUIRE_AUDIO(audio);
  if (!fs::exists("/usr/share/libmysofa/MIT_KEMAR_normal_pinna.sofa")) GTEST_SKIP() << "no MIT KEMAR SOFA file";
  const std::string dry = (audio / "alsa_Front_Center.wav").string();
  // The source 1.5 m to the left of a listener facing +x.
  const std::string base = path("room.vol") + " --source 3 4 1.5 --listener 3 2.5 1.5 --in " + dry +
                           " --absorption 0.3 --rays 2000 --binaural --out " + path("b.wav") + " --ir " + path("bir.wav");
  CliRun r = run(base, dir_);
  ASSERT_EQ(r.status, 0) << r.output;
  const vola::audio::Sound ir = vola::audio::read_sound(path("bir.wav"));
  ASSERT_EQ(ir.channels.size(), 2u);
  EXPECT_EQ(vola::audio::read_sound(path("b.wav")).channels.size(), 2u);
  // The left ear hears the direct sound first and louder.
  const auto direct = static_cast<std::size_t>(std::lround(1.5 / 343.0 * 48000.0));
  double left = 0.0, right = 0.0;
  std::size_t first_left = 0, first_right = 0;
  for (std::size_t i = direct; i < direct + 96; ++i) {
    left += ir.channels[0][i] * ir.channels[0][i];
    right += ir.channels[1][i] * ir.channels[1][i];
  }
  while (std::abs(ir.channels[0][first_left]) < 1e-3) ++first_left;
  while (std::abs(ir.channels[1][first_right]) < 1e-3) ++first_right;
  EXPECT_GT(left, 2.0 * right);
  EXPECT_LT(first_left, first_right);
  std::ofstream(path("bad.sofa")) << "not a SOFA file";
  r = run(base + " --hrtf " + path("bad.sofa"), dir_);
  EXPECT_EQ(r.status, 1);
  EXPECT_NE(r.output.find("bad.sofa: cannot load the HRTF"), std::string::npos) << r.output;
  r = run(base + " --model paper", dir_);
  EXPECT_EQ(r.status, 1);
  EXPECT_NE(r.output.find("--binaural renders the physical model"), std::string::npos) << r.output;
}

}  // namespace
