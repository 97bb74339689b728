// Seeds for fuzz_wav_read: the WAVs of the shared data folder (beside golden/), whole
// and with their data chunk cut to 4 KiB (sizes rewritten, so that libFuzzer's inputs
// stay small and still decode), plus WAVs written by write_wav (16-bit, 24-bit and float
// samples; one to three channels). Linked into fuzz_wav_read_replay in place of
// fuzz_seeds.cpp.
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <fstream>
#include <iterator>
#include <string>

#include "fuzz_seeds.hpp"
#include "vola/audio/wav.hpp"

namespace vola_fuzz {
namespace {

namespace audio = vola::audio;
using Bytes = std::vector<std::uint8_t>;

Bytes read_all(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  return Bytes(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
}

std::uint32_t le32(const Bytes& b, std::size_t at) {
  return std::uint32_t{b[at]} | std::uint32_t{b[at + 1]} << 8 | std::uint32_t{b[at + 2]} << 16 |
         std::uint32_t{b[at + 3]} << 24;
}

void put32(Bytes& b, std::size_t at, std::uint32_t v) {
  for (int i = 0; i < 4; ++i) b[at + i] = static_cast<std::uint8_t>(v >> (8 * i));
}

// The RIFF file with its "data" chunk cut to `keep` bytes (the chunk and RIFF sizes
// rewritten), or nothing when it has no data chunk.
Bytes shortened(const Bytes& wav, std::uint32_t keep) {
  if (wav.size() < 12 || std::memcmp(wav.data(), "RIFF", 4) != 0) return {};
  for (std::size_t at = 12; at + 8 <= wav.size();) {
    const std::uint32_t size = le32(wav, at + 4);
    if (std::memcmp(wav.data() + at, "data", 4) == 0) {
      const auto n = static_cast<std::uint32_t>(std::min<std::uint64_t>({keep, size, wav.size() - at - 8}));
      Bytes out(wav.begin(), wav.begin() + static_cast<std::ptrdiff_t>(at + 8 + n));
      put32(out, at + 4, n);
      put32(out, 4, static_cast<std::uint32_t>(out.size() - 8));
      return out;
    }
    at += 8 + std::size_t{size} + (size & 1);
  }
  return {};
}

Bytes written(const audio::Sound& sound, audio::SampleFormat format) {
  const auto path = std::filesystem::temp_directory_path() / ("vola_fuzz_wav_seed_" + std::to_string(::getpid()) + ".wav");
  audio::write_wav(path.string(), sound, format);
  Bytes b = read_all(path);
  std::filesystem::remove(path);
  return b;
}

audio::Sound tone(int channels, std::size_t frames, int rate) {
  audio::Sound s;
  s.sample_rate = rate;
  s.channels.assign(static_cast<std::size_t>(channels), std::vector<double>(frames));
  for (int c = 0; c < channels; ++c)
    for (std::size_t i = 0; i < frames; ++i)
      s.channels[static_cast<std::size_t>(c)][i] = 0.8 * std::sin(0.05 * static_cast<double>(i) * (c + 1));
  return s;
}

}  // namespace

std::vector<Seed> synthetic_seeds() {
  return {{"pcm16_mono.wav", written(tone(1, 200, 48000), audio::SampleFormat::pcm16)},
          {"pcm24_stereo.wav", written(tone(2, 120, 44100), audio::SampleFormat::pcm24)},
          {"float_3ch.wav", written(tone(3, 64, 16000), audio::SampleFormat::float32)},
          {"pcm16_empty.wav", written(tone(1, 0, 8000), audio::SampleFormat::pcm16)}};
}

// Every .wav of the shared data folder's audio/, whole and shortened.
std::vector<Seed> golden_seeds(const std::filesystem::path& golden) {
  std::vector<Seed> seeds;
  const auto folder = shared_data(golden, "audio");
  if (folder.empty()) return seeds;
  for (const auto& entry : std::filesystem::directory_iterator(folder)) {
    if (!entry.is_regular_file() || entry.path().extension() != ".wav") continue;
    Bytes whole = read_all(entry.path());
    Bytes cut = shortened(whole, 4096);
    if (!cut.empty()) seeds.push_back({"short_" + entry.path().filename().string(), std::move(cut)});
    seeds.push_back({entry.path().filename().string(), std::move(whole)});
  }
  std::sort(seeds.begin(), seeds.end(), [](const Seed& a, const Seed& b) { return a.name < b.name; });
  return seeds;
}

}  // namespace vola_fuzz
