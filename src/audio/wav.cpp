#include "vola/audio/wav.hpp"

#include <sndfile.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <fstream>
#include <memory>
#include <string_view>

#include "vola/error.hpp"
#include "vola/output_file.hpp"

namespace vola::audio {

namespace {

struct SndfileCloser {
  void operator()(SNDFILE* f) const noexcept { sf_close(f); }
};
using SndfilePtr = std::unique_ptr<SNDFILE, SndfileCloser>;

constexpr sf_count_t kChunkFrames = 65536;

std::uint32_t le32(const unsigned char* p) {
  return std::uint32_t{p[0]} | std::uint32_t{p[1]} << 8 | std::uint32_t{p[2]} << 16 | std::uint32_t{p[3]} << 24;
}

// libsndfile reads a cut WAV as a shorter sound and says nothing: its header's data
// chunk size is clamped to what the file holds. A RIFF WAV states that size, so a file
// shorter than the chunks it declares is refused, naming the size field's offset.
// Other formats (and streamed WAVs, whose size is 0 or ~0) are left to libsndfile.
void check_wav_not_cut(const std::string& path) {
  std::ifstream in(path, std::ios::binary | std::ios::ate);
  if (!in) return;  // sf_open reports it
  const auto file_size = static_cast<std::uint64_t>(in.tellg());
  unsigned char head[12];
  in.seekg(0);
  if (!in.read(reinterpret_cast<char*>(head), 12) || std::string_view(reinterpret_cast<char*>(head), 4) != "RIFF" ||
      std::string_view(reinterpret_cast<char*>(head) + 8, 4) != "WAVE")
    return;
  std::uint64_t at = 12;
  unsigned char chunk[8];
  while (at + 8 <= file_size) {
    in.seekg(static_cast<std::streamoff>(at));
    if (!in.read(reinterpret_cast<char*>(chunk), 8)) return;
    const std::uint64_t size = le32(chunk + 4);
    const bool data = std::string_view(reinterpret_cast<char*>(chunk), 4) == "data";
    if (data && (size == 0 || size == 0xFFFFFFFFu)) return;
    if (at + 8 + size > file_size)
      throw FormatError(path, at + 4,
                        "the \"" + std::string(reinterpret_cast<char*>(chunk), 4) + "\" chunk declares " +
                            std::to_string(size) + " bytes but the file ends " + std::to_string(file_size - at - 8) +
                            " bytes after its start: the file is cut");
    if (data) return;
    at += 8 + size + (size & 1);
  }
}

}  // namespace

std::vector<double> Sound::mono() const {
  std::vector<double> out(frames(), 0.0);
  if (channels.empty()) return out;
  for (const auto& c : channels)
    for (std::size_t i = 0; i < out.size(); ++i) out[i] += c[i];
  const double scale = 1.0 / static_cast<double>(channels.size());
  for (double& v : out) v *= scale;
  return out;
}

Sound read_sound(const std::string& path) {
  SF_INFO info{};
  SndfilePtr file(sf_open(path.c_str(), SFM_READ, &info));
  if (!file) throw IoError(path + ": cannot read sound: " + sf_strerror(nullptr));
  if ((info.format & SF_FORMAT_TYPEMASK) == SF_FORMAT_WAV) check_wav_not_cut(path);
  if (info.channels <= 0 || info.channels > 256 || info.samplerate <= 0)
    throw FormatError(path, std::nullopt, "implausible sound header (" + std::to_string(info.channels) + " channels, " +
                                              std::to_string(info.samplerate) + " Hz)");
  // Normalised doubles: integer PCM maps to [-1, 1).
  sf_command(file.get(), SFC_SET_NORM_DOUBLE, nullptr, SF_TRUE);
  Sound s;
  s.sample_rate = info.samplerate;
  const auto channels = static_cast<std::size_t>(info.channels);
  s.channels.resize(channels);
  // 64K samples a read whatever the header's channel count: a header claiming 256
  // channels costs no more buffer than a mono one (it took 128 MiB before any sample).
  const sf_count_t chunk_frames = std::max<sf_count_t>(1, kChunkFrames / static_cast<sf_count_t>(channels));
  std::vector<double> chunk(static_cast<std::size_t>(chunk_frames) * channels);
  for (;;) {
    const sf_count_t got = sf_readf_double(file.get(), chunk.data(), chunk_frames);
    if (got < 0) throw IoError(path + ": " + sf_strerror(file.get()));
    for (sf_count_t f = 0; f < got; ++f)
      for (std::size_t c = 0; c < channels; ++c) {
        const double sample = chunk[static_cast<std::size_t>(f) * channels + c];
        // A float file may hold NaN or infinity: one such sample made every output sample
        // NaN (or -32768 as PCM) through the convolution and the normalisation.
        if (!std::isfinite(sample))
          throw FormatError(path, std::nullopt,
                            "sample " + std::to_string(s.channels[c].size()) + " of channel " + std::to_string(c) +
                                " is not a finite number");
        s.channels[c].push_back(sample);
      }
    if (got < chunk_frames) break;
  }
  if (sf_error(file.get()) != SF_ERR_NO_ERROR) throw IoError(path + ": " + sf_strerror(file.get()));
  return s;
}

void write_wav(const std::string& path, const Sound& sound, SampleFormat format) {
  if (sound.channels.empty()) throw InvalidArgument(path + ": nothing to write (no channel)");
  for (const auto& c : sound.channels)
    if (c.size() != sound.frames()) throw InvalidArgument(path + ": channels of different lengths");
  SF_INFO info{};
  info.samplerate = sound.sample_rate;
  info.channels = static_cast<int>(sound.channels.size());
  info.format = SF_FORMAT_WAV | (format == SampleFormat::pcm16   ? SF_FORMAT_PCM_16
                                 : format == SampleFormat::pcm24 ? SF_FORMAT_PCM_24
                                                                 : SF_FORMAT_FLOAT);
  if (!sf_format_check(&info))
    throw InvalidArgument(path + ": libsndfile cannot write this WAV (" + std::to_string(info.channels) + " channels, " +
                          std::to_string(info.samplerate) + " Hz)");
  OutputFile output(path);
  // libsndfile seeks back to finish the header: it writes the descriptor itself.
  SndfilePtr file(sf_open_fd(output.descriptor(), SFM_WRITE, &info, SF_FALSE));
  if (!file) throw IoError(path + ": cannot create: " + sf_strerror(nullptr));
  // PCM output clips instead of wrapping around.
  sf_command(file.get(), SFC_SET_CLIPPING, nullptr, SF_TRUE);
  const std::size_t channels = sound.channels.size();
  std::vector<double> chunk(static_cast<std::size_t>(kChunkFrames) * channels);
  for (std::size_t begin = 0; begin < sound.frames(); begin += static_cast<std::size_t>(kChunkFrames)) {
    const std::size_t n = std::min<std::size_t>(static_cast<std::size_t>(kChunkFrames), sound.frames() - begin);
    for (std::size_t f = 0; f < n; ++f)
      for (std::size_t c = 0; c < channels; ++c) chunk[f * channels + c] = sound.channels[c][begin + f];
    if (sf_writef_double(file.get(), chunk.data(), static_cast<sf_count_t>(n)) != static_cast<sf_count_t>(n))
      throw IoError(path + ": cannot write: " + sf_strerror(file.get()));
  }
  if (sf_close(file.release()) != 0) throw IoError(path + ": cannot finish writing");
  output.commit();
}

}  // namespace vola::audio
