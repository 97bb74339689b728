// Fuzz entry point of the sound reader (audio::read_sound, what vola sonify and convolve
// read a WAV with): libsndfile decodes, vola checks a RIFF WAV's chunk sizes against the
// file first and the header's channels and rate after. The input is the file, written to
// a scratch file of this process. Only vola::Error may escape; what reads must have
// 1..256 channels of one length and a positive rate.
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <span>
#include <string>

#include "fuzz_seeds.hpp"
#include "scratch_file.hpp"
#include "vola/audio/wav.hpp"
#include "vola/error.hpp"

namespace {

using vola_fuzz::check;

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string path = vola_fuzz::scratch_file("sound", "wav", std::span(data, size));
  try {
    const vola::audio::Sound sound = vola::audio::read_sound(path);
    check(sound.sample_rate > 0 && !sound.channels.empty() && sound.channels.size() <= 256);
    for (const auto& c : sound.channels) check(c.size() == sound.frames());
    check(sound.mono().size() == sound.frames());
    ++vola_fuzz::stats().parsed;
  } catch (const vola::Error&) {
    ++vola_fuzz::stats().refused;
  }
  return 0;
}
