// Sound files through libsndfile: WAV (and whatever else libsndfile reads) in, WAV out.
#pragma once

#include <string>
#include <vector>

namespace vola::audio {

struct Sound {
  int sample_rate = 48000;
  std::vector<std::vector<double>> channels;  // samples in [-1, 1] for PCM input
  std::size_t frames() const noexcept { return channels.empty() ? 0 : channels[0].size(); }
  // The channels averaged into one.
  std::vector<double> mono() const;
};

enum class SampleFormat { pcm16, pcm24, float32 };

// Throws IoError naming the file and libsndfile's reason when it cannot be opened or
// decoded. Memory grows with the samples actually decoded, not with the header's claims.
Sound read_sound(const std::string& path);
// Writes a WAV file; PCM formats clip at +-1. Throws IoError / InvalidArgument (no channel,
// channels of different lengths, a sample rate libsndfile refuses).
void write_wav(const std::string& path, const Sound& sound, SampleFormat format);

}  // namespace vola::audio
