// The parts of auralisation: material tables, surface voxels (against a std::set model),
// FFT convolution (against the O(N*M) sum), per-band kernels, WAV files and the real
// recordings of $VOLA_SHARED/data/audio.
#include <gtest/gtest.h>

#include <tuple>

#include <cmath>
#include <complex>
#include <fstream>
#include <numbers>
#include <random>
#include <set>

#include "audio_test_support.hpp"
#include "vola/audio/convolve.hpp"
#include "vola/audio/materials.hpp"
#include "vola/audio/response.hpp"
#include "vola/audio/surface.hpp"
#include "vola/audio/wav.hpp"
#include "vola/builder.hpp"
#include "vola/error.hpp"

namespace {

using namespace vola;
using namespace vola::audio;
namespace fs = std::filesystem;

// A file in this process's scratch folder, removed with it at exit.
fs::path scratch(const std::string& name) {
  static const vola_test::TempDir dir;
  return dir / name;
}

std::string error_of(const std::function<void()>& f) {
  try {
    f();
  } catch (const vola::Error& e) {
    return e.what();
  }
  return "(no error)";
}

// ---- materials ----

TEST(AudioMaterials, ParsesScalarAndPerBandCoefficients) {
  const MaterialTable t = parse_material_table(
      R"({"attribute": "classification", "default": 0.3,
          "materials": {"2": 0.2, "6": [0.9, 0.8, 0.7, 0.6, 0.5, 0.4], "-4": 1}})",
      "m.json");
  EXPECT_EQ(t.source, MaterialSource::attribute);
  EXPECT_EQ(t.attribute, "classification");
  EXPECT_EQ(t.fallback.bands, std::vector<double>{0.3});
  ASSERT_EQ(t.materials.size(), 3u);
  const MaterialTable p = parse_material_table(R"({"attribute": "payload", "materials": {"7": 0.1}})", "p.json");
  EXPECT_EQ(p.source, MaterialSource::payload_id);
}

TEST(AudioMaterials, BadTablesNameTheFileAndThePlace) {
  EXPECT_NE(error_of([] { parse_material_table("{\n  \"materials\": {\"2\": 0.2,}\n}", "m.json"); }).find("m.json"), std::string::npos);
  EXPECT_NE(error_of([] { parse_material_table("{\n  \"materials\": {\"2\": 0.2,}\n}", "m.json"); }).find("line 2"), std::string::npos);
  EXPECT_NE(error_of([] { parse_material_table(R"({"attribute": "c", "materials": {"6": 1.5}})", "m.json"); })
                .find("materials.\"6\": coefficient 1.5 is not in [0, 1]"),
            std::string::npos);
  EXPECT_NE(error_of([] { parse_material_table(R"({"attribute": "c", "materials": {"6": [0.1, 0.2]}})", "m.json"); })
                .find("6 values"),
            std::string::npos);
  EXPECT_NE(error_of([] { parse_material_table(R"({"attribute": "c", "materials": {"wood": 0.1}})", "m.json"); })
                .find("must be an integer"),
            std::string::npos);
  EXPECT_NE(error_of([] { parse_material_table(R"({"materials": {"1": 0.1}})", "m.json"); }).find("no \"attribute\""),
            std::string::npos);
  EXPECT_NE(error_of([] { parse_material_table(R"({"colour": 1, "materials": {}})", "m.json"); }).find("unknown key"),
            std::string::npos);
  EXPECT_NE(error_of([] { parse_material_table("[1, 2]", "m.json"); }).find("JSON object"), std::string::npos);
  EXPECT_THROW(read_material_table(scratch("missing.json").string()), IoError);
}

TEST(AudioMaterials, VoxelsGetTheirMaterialFromTheAttribute) {
  const std::vector<Voxel> voxels{{0, 0, 0}, {1, 0, 0}, {2, 0, 0}, {3, 5, 1}};
  Tree tree = build_from_voxels(voxels, 2);
  AttributeColumn cls("classification", ValueType::u8, Reduction::majority, 4);
  // Rank order is key order: (0,0,0) (1,0,0) (2,0,0) then (3,5,1).
  cls.set(0, 2);
  cls.set(1, 6);
  cls.set(2, 9);
  cls.set(3, 2);
  tree.attributes().add(cls);
  const MaterialTable t = parse_material_table(
      R"({"attribute": "classification", "default": 0.3, "materials": {"2": 0.2, "6": [0.9, 0.8, 0.7, 0.6, 0.5, 0.4]}})", "m.json");
  const VoxelMaterials m(t, tree);
  const auto& slots = m.slots();
  EXPECT_EQ(slots[m.slot(0, 0)].bands, std::vector<double>{0.2});
  EXPECT_EQ(slots[m.slot(1, 0)].bands.size(), 6u);
  EXPECT_EQ(slots[m.slot(2, 0)].bands, std::vector<double>{0.3});  // 9 is not listed
  EXPECT_EQ(m.slot(3, 1), m.slot(0, 0));
  MaterialTable missing = t;
  missing.attribute = "intensity";
  EXPECT_NE(error_of([&] { VoxelMaterials(missing, tree); }).find("no attribute \"intensity\""), std::string::npos);
  MaterialTable payload = scene_material(0.5);
  payload.source = MaterialSource::payload_value;
  EXPECT_THROW(VoxelMaterials(payload, tree), InvalidArgument);  // the tree has no payload
}

// ---- surface voxels ----

TEST(AudioSurface, MatchesASetModelOnRandomShapes) {
  std::mt19937_64 rng(11);
  for (int round = 0; round < 6; ++round) {
    std::set<std::array<std::uint32_t, 3>> set;
    std::vector<Voxel> voxels;
    const std::uint32_t side = 64;
    std::uniform_int_distribution<std::uint32_t> c(0, side - 1);
    // Solid boxes (with interiors) plus scattered voxels.
    for (int b = 0; b < 6; ++b) {
      const std::uint32_t x = c(rng), y = c(rng), z = c(rng), n = 2 + c(rng) % 9;
      for (std::uint32_t dz = 0; dz < n && z + dz < side; ++dz)
        for (std::uint32_t dy = 0; dy < n && y + dy < side; ++dy)
          for (std::uint32_t dx = 0; dx < n && x + dx < side; ++dx) set.insert({x + dx, y + dy, z + dz});
    }
    for (int i = 0; i < 500; ++i) set.insert({c(rng), c(rng), c(rng)});
    for (const auto& v : set) voxels.push_back({v[0], v[1], v[2]});
    const Tree tree = build_from_voxels(voxels, 3);
    std::vector<std::pair<std::array<std::uint32_t, 3>, int>> expected;
    for (const auto& v : set) {
      int exposed = 0;
      for (int face = 0; face < 6; ++face) {
        auto n = v;
        n[face / 2] += face % 2 ? 1u : static_cast<std::uint32_t>(-1);
        const bool outside = n[face / 2] >= side;
        if (outside || !set.count(n)) exposed |= 1 << face;
      }
      if (exposed) expected.push_back({v, exposed});
    }
    std::vector<std::pair<std::array<std::uint32_t, 3>, int>> got;
    std::uint64_t previous_rank = 0;
    bool first = true;
    for (const SurfaceVoxel& s : surface_voxels(tree)) {
      got.push_back({{s.voxel.x, s.voxel.y, s.voxel.z}, s.exposed});
      EXPECT_EQ(s.rank, *tree.rank(s.voxel));
      EXPECT_TRUE(first || s.rank > previous_rank);
      previous_rank = s.rank;
      first = false;
    }
    std::sort(got.begin(), got.end());
    EXPECT_EQ(got, expected) << "round " << round;
  }
}

// ---- convolution ----

std::vector<double> slow_convolution(const std::vector<double>& x, const std::vector<double>& h) {
  std::vector<double> y(x.size() + h.size() - 1, 0.0);
  for (std::size_t i = 0; i < x.size(); ++i)
    for (std::size_t j = 0; j < h.size(); ++j) y[i + j] += x[i] * h[j];
  return y;
}

TEST(AudioConvolve, MatchesTheDirectSumForManyLengths) {
  std::mt19937_64 rng(3);
  std::normal_distribution<double> noise;
  for (const auto& [n, m] : {std::pair{1, 1}, {5, 1}, {1, 7}, {100, 37}, {4095, 1024}, {20000, 3000}, {9000, 5000}}) {
    std::vector<double> x(static_cast<std::size_t>(n)), h(static_cast<std::size_t>(m));
    for (double& v : x) v = noise(rng);
    for (double& v : h) v = noise(rng);
    const std::vector<double> fast = Convolver(h).apply(x, 1);
    const std::vector<double> slow = slow_convolution(x, h);
    ASSERT_EQ(fast.size(), slow.size());
    double worst = 0.0;
    for (std::size_t i = 0; i < fast.size(); ++i) worst = std::max(worst, std::abs(fast[i] - slow[i]));
    EXPECT_LT(worst, 1e-9 * std::sqrt(static_cast<double>(m))) << n << " x " << m;
    EXPECT_EQ(Convolver(h).apply(x, 3), fast) << "threads changed the result, " << n << " x " << m;
    // Sized for this signal (blocks that may overlap several neighbours), into a buffer.
    const Convolver sized(h, FftPlanning::estimate, x.size());
    std::vector<double> into(fast.size(), 7.0);
    sized.apply_into(x, into, 2);
    double worst_sized = 0.0;
    for (std::size_t i = 0; i < into.size(); ++i) worst_sized = std::max(worst_sized, std::abs(into[i] - slow[i]));
    EXPECT_LT(worst_sized, 1e-9 * std::sqrt(static_cast<double>(m))) << n << " x " << m << ", size " << sized.fft_size();
    EXPECT_EQ(sized.apply(x, 1), into) << "threads changed the result, " << n << " x " << m;
    // Single precision: errors of float rounding, relative to the output's scale (the
    // inputs are unit normal, so the output's is sqrt(m)).
    const Convolver single(h, FftPlanning::estimate, x.size(), SamplePrecision::float32);
    const std::vector<double> rounded = single.apply(x, 1);
    double worst_single = 0.0;
    for (std::size_t i = 0; i < rounded.size(); ++i) worst_single = std::max(worst_single, std::abs(rounded[i] - slow[i]));
    EXPECT_LT(worst_single, 1e-5 * std::sqrt(static_cast<double>(m))) << n << " x " << m << " in single precision";
    EXPECT_GT(worst_single, 0.0) << "single precision gave double's result";
    EXPECT_EQ(single.apply(x, 3), rounded) << "threads changed the result, " << n << " x " << m;
  }
  EXPECT_TRUE(Convolver(std::vector<double>{1.0}).apply(std::vector<double>{}, 1).empty());
  std::vector<double> wrong(10);
  EXPECT_THROW(Convolver(std::vector<double>{1.0, 2.0}).apply_into(std::vector<double>(10, 1.0), wrong), InvalidArgument);
  EXPECT_THROW(Convolver(std::vector<double>{}), InvalidArgument);
}

// The transform size: four times the filter for long signals; for a known signal the size
// with the least FFT work (a 1 s, 48 kHz signal through a 0.86 s response: two blocks of
// 65,536 points, not one of 262,144 that is mostly padding).
TEST(AudioConvolve, TheTransformFitsTheSignal) {
  EXPECT_EQ(Convolver::transform_size(41392, 0), std::size_t{262144});
  EXPECT_EQ(Convolver::transform_size(41392, 48000), std::size_t{65536});
  EXPECT_EQ(Convolver::transform_size(300, 48000), std::size_t{4096});
  EXPECT_EQ(Convolver::transform_size(300, 0), std::size_t{4096});
  EXPECT_EQ(Convolver::transform_size(5000, 1'000'000), std::size_t{32768});
}

// Partitioned overlap-save against the direct sum: filters shorter and longer than the
// signal, one partition or many, a partial last partition.
TEST(AudioConvolve, PartitionedMatchesTheDirectSum) {
  std::mt19937_64 rng(4);
  std::normal_distribution<double> noise;
  for (const auto& [n, m, b] : {std::tuple{1, 1, 64}, {100, 37, 64}, {37, 1000, 64}, {5000, 20000, 1024}, {20000, 3000, 256},
                                 {9000, 9000, 8192}, {300, 70000, 4096}}) {
    std::vector<double> x(static_cast<std::size_t>(n)), h(static_cast<std::size_t>(m));
    for (double& v : x) v = noise(rng);
    for (double& v : h) v = noise(rng);
    const PartitionedConvolver c(h, static_cast<std::size_t>(b));
    EXPECT_EQ(c.partitions(), static_cast<std::size_t>((m + b - 1) / b));
    const std::vector<double> fast = c.apply(x, 1);
    const std::vector<double> slow = slow_convolution(x, h);
    ASSERT_EQ(fast.size(), slow.size());
    double worst = 0.0;
    for (std::size_t i = 0; i < fast.size(); ++i) worst = std::max(worst, std::abs(fast[i] - slow[i]));
    EXPECT_LT(worst, 1e-9 * std::sqrt(static_cast<double>(m))) << n << " x " << m << " in " << b;
    EXPECT_EQ(c.apply(x, 3), fast) << "threads changed the result, " << n << " x " << m;
  }
  EXPECT_THROW(PartitionedConvolver(std::vector<double>{1.0}, 100), InvalidArgument);
  EXPECT_THROW(PartitionedConvolver(std::vector<double>{}), InvalidArgument);
}

TEST(AudioConvolve, BandKernelFollowsTheBandCoefficientsAndStartsAtOnce) {
  const Material m{{0.9, 0.8, 0.6, 0.5, 0.3, 0.2}};
  for (const double rate : {16000.0, 48000.0}) {
    const std::vector<double> k = band_kernel(m, rate);
    double total = 0.0, early = 0.0;
    for (std::size_t n = 0; n < k.size(); ++n) {
      total += k[n] * k[n];
      if (static_cast<double>(n) < rate * 0.002) early += k[n] * k[n];
    }
    EXPECT_GT(early / total, 0.9) << "minimum phase: the energy comes first, at " << rate << " Hz";
    for (std::size_t b = 0; b < kOctaveBands.size(); ++b) {
      std::complex<double> sum = 0;
      for (std::size_t n = 0; n < k.size(); ++n)
        sum += k[n] * std::polar(1.0, -2.0 * std::numbers::pi * kOctaveBands[b] / rate * static_cast<double>(n));
      EXPECT_NEAR(std::abs(sum), m.bands[b], 0.03) << kOctaveBands[b] << " Hz at " << rate << " Hz";
    }
  }
  // A flat magnitude is a scaled impulse.
  const std::vector<double> flat = minimum_phase_fir(std::vector<double>(513, 0.25), 64);
  EXPECT_NEAR(flat[0], 0.25, 1e-12);
  for (std::size_t n = 1; n < flat.size(); ++n) EXPECT_NEAR(flat[n], 0.0, 1e-12);
  EXPECT_THROW(minimum_phase_fir(std::vector<double>(100, 1.0), 10), InvalidArgument);
}

// ---- WAV ----

TEST(AudioWav, RoundTripsFloatAndPcm) {
  Sound s;
  s.sample_rate = 22050;
  s.channels = {{0.0, 0.5, -0.25, 0.999, -1.0}, {0.1, 0.2, 0.3, 0.4, 0.5}};
  const fs::path f = scratch("round.wav");
  write_wav(f.string(), s, SampleFormat::float32);
  const Sound back = read_sound(f.string());
  EXPECT_EQ(back.sample_rate, 22050);
  ASSERT_EQ(back.channels.size(), 2u);
  for (std::size_t c = 0; c < 2; ++c)
    for (std::size_t i = 0; i < 5; ++i) EXPECT_EQ(back.channels[c][i], static_cast<double>(static_cast<float>(s.channels[c][i])));
  write_wav(f.string(), s, SampleFormat::pcm16);
  const Sound pcm = read_sound(f.string());
  for (std::size_t c = 0; c < 2; ++c)
    for (std::size_t i = 0; i < 5; ++i) EXPECT_NEAR(pcm.channels[c][i], s.channels[c][i], 1.0 / 32768 + 1e-12);
  EXPECT_NEAR(back.mono()[1], (0.5 + 0.2) / 2, 1e-7);  // float samples
}

TEST(AudioWav, BadFilesGiveErrorsNamingThem) {
  const std::string missing = scratch("nothing-here.wav").string();
  EXPECT_NE(error_of([&] { read_sound(missing); }).find("nothing-here.wav"), std::string::npos);
  const fs::path junk = scratch("junk.wav");
  std::ofstream(junk) << "RIFF....WAVEfmt this is not a sound file";
  EXPECT_THROW(read_sound(junk.string()), IoError);
  // A header claiming far more samples than the file holds is a cut file: refused with
  // the file and the chunk's offset (a silently shortened sound was the old behaviour).
  Sound s;
  s.sample_rate = 8000;
  s.channels = {std::vector<double>(1000, 0.25)};
  const fs::path cut = scratch("cut.wav");
  write_wav(cut.string(), s, SampleFormat::pcm16);
  fs::resize_file(cut, 44 + 400);
  const std::string why = error_of([&] { read_sound(cut.string()); });
  EXPECT_NE(why.find("cut.wav"), std::string::npos) << why;
  EXPECT_NE(why.find("the file is cut"), std::string::npos) << why;
  Sound empty;
  EXPECT_THROW(write_wav(scratch("e.wav").string(), empty, SampleFormat::pcm16), InvalidArgument);
}

TEST(AudioWav, RealRecordingsReadAndFilterThroughARoom) {
  VOLA_REQUIRE_AUDIO(dir);
  // README of the data folder: mono 16-bit WAV at 48, 16 and 16 kHz.
  const Sound alsa = read_sound((dir / "alsa_Front_Center.wav").string());
  EXPECT_EQ(alsa.sample_rate, 48000);
  EXPECT_EQ(alsa.channels.size(), 1u);
  EXPECT_EQ(alsa.frames(), 68545u);
  const Sound speech = read_sound((dir / "codec2_speech_orig_16k.wav").string());
  EXPECT_EQ(speech.sample_rate, 16000);
  EXPECT_EQ(speech.frames(), 172800u);

  // The room's response at 16 kHz through the speech: the wet signal is the dry one
  // delayed by the direct path and scaled by 1/d, plus reflections, which the slow sum
  // reproduces.
  const vola::Tree room = vola_audio_test::shoebox_tree({{10, 12, 8}, {200, 150, 100}}, 1.0 / 32.0);
  const AcousticScene scene(room, scene_material(0.7));
  ResponseOptions o;
  o.sample_rate = speech.sample_rate;
  o.reflection_window = 0.03;
  const Point s{60.0 / 32, 50.0 / 32, 40.0 / 32}, l{130.0 / 32, 90.0 / 32, 60.0 / 32};
  const Thresholded t = threshold(scene, s, l, o);
  const std::vector<double> ir = make_filter(scene, t, o);
  const std::vector<double> dry(speech.channels[0].begin(), speech.channels[0].begin() + 4000);
  const std::vector<double> wet = Convolver(ir).apply(dry, 2);
  const std::vector<double> slow = slow_convolution(dry, ir);
  ASSERT_EQ(wet.size(), slow.size());
  for (std::size_t i = 0; i < wet.size(); i += 7) EXPECT_NEAR(wet[i], slow[i], 1e-9);
  // Before the direct sound: silence.
  for (std::size_t i = 0; i < t.direct_sample; ++i) EXPECT_EQ(std::abs(wet[i]) < 1e-12, true) << i;
}

}  // namespace
