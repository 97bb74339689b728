#include "vola/audio/binaural.hpp"

#include <mysofa.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <numbers>
#include <random>

#include "vola/error.hpp"

namespace vola::audio {

struct Hrtf::Handle {
  MYSOFA_EASY* easy = nullptr;
  ~Handle() {
    if (easy) mysofa_close(easy);
  }
};

namespace {

// libmysofa's error as words: its own codes from 10000 on, and errno values (a missing
// file gave "libmysofa error 2") below.
std::string sofa_error_text(int error) {
  switch (error) {
    case MYSOFA_INTERNAL_ERROR: return "libmysofa's internal error";
    case MYSOFA_INVALID_FORMAT: return "not a SOFA (HDF5) file, or a damaged one";
    case MYSOFA_UNSUPPORTED_FORMAT: return "a SOFA convention libmysofa does not support";
    case MYSOFA_NO_MEMORY: return "out of memory";
    case MYSOFA_READ_ERROR: return "a read error";
    case MYSOFA_INVALID_ATTRIBUTES: return "SOFA attributes missing or invalid";
    case MYSOFA_INVALID_DIMENSIONS: case MYSOFA_INVALID_DIMENSION_LIST: return "SOFA dimensions invalid";
    case MYSOFA_ONLY_THE_SAME_SAMPLING_RATE_SUPPORTED: return "measurements at more than one sampling rate";
    default: break;
  }
  if (error > 0 && error < MYSOFA_INVALID_FORMAT) return std::strerror(error);
  return "libmysofa error " + std::to_string(error);
}

}  // namespace

Hrtf::Hrtf(const std::string& path, double sample_rate) : handle_(std::make_unique<Handle>()), sample_rate_(sample_rate) {
  int length = 0, error = 0;
  handle_->easy = mysofa_open(path.c_str(), static_cast<float>(sample_rate), &length, &error);
  if (!handle_->easy || error != MYSOFA_OK || length <= 0)
    throw IoError(path + ": cannot load the HRTF (SOFA file): " + sofa_error_text(error));
  length_ = static_cast<std::size_t>(length);
}

Hrtf::~Hrtf() = default;

std::array<std::vector<double>, 2> Hrtf::filters(const Point& direction) const {
  std::vector<float> left(length_), right(length_);
  float delay_left = 0.0f, delay_right = 0.0f;
  // libmysofa's lookup is not thread-safe for one handle; responses are made one at a time.
  mysofa_getfilter_float(handle_->easy, static_cast<float>(direction[0]), static_cast<float>(direction[1]),
                         static_cast<float>(direction[2]), left.data(), right.data(), &delay_left, &delay_right);
  std::array<std::vector<double>, 2> out;
  const float delays[2] = {delay_left, delay_right};
  const std::vector<float>* taps[2] = {&left, &right};
  for (int ear = 0; ear < 2; ++ear) {
    // Delays (seconds) that the file keeps apart from its filters, to the nearest sample.
    const auto shift = static_cast<std::size_t>(std::max(0.0, std::nearbyint(delays[ear] * sample_rate_)));
    out[ear].assign(shift + length_, 0.0);
    for (std::size_t i = 0; i < length_; ++i) out[ear][shift + i] = (*taps[ear])[i];
  }
  return out;
}

std::array<std::vector<double>, 2> binaural_response(const RoomResponse& r, const Hrtf& hrtf, const Point& source,
                                                    const Point& listener, double facing_degrees, const RoomOptions& o) {
  const double yaw = facing_degrees * std::numbers::pi / 180.0;
  const double c = std::cos(yaw), s = std::sin(yaw);
  // World direction -> listener frame (x ahead, y left, z up).
  auto to_head = [&](const Point& from) {
    const Point d{from[0] - listener[0], from[1] - listener[1], from[2] - listener[2]};
    return Point{c * d[0] + s * d[1], -s * d[0] + c * d[1], d[2]};
  };
  struct Arrival {
    std::size_t sample;
    double amplitude;
    Point direction;
  };
  std::vector<Arrival> arrivals;
  if (r.direct_amplitude > 0.0) arrivals.push_back({r.direct_sample, r.direct_amplitude, to_head(source)});
  for (const ImageSource& is : r.early.images)
    arrivals.push_back({static_cast<std::size_t>(std::nearbyint(is.delay * o.sample_rate)), is.amplitude, to_head(is.image)});
  std::size_t length = r.late.energy.size() * r.late.bin_samples;
  std::vector<std::array<std::vector<double>, 2>> pairs;
  for (const Arrival& a : arrivals) {
    pairs.push_back(hrtf.filters(a.direction));
    length = std::max({length, a.sample + pairs.back()[0].size(), a.sample + pairs.back()[1].size()});
  }
  std::array<std::vector<double>, 2> ears;
  for (int ear = 0; ear < 2; ++ear) {
    ears[ear].assign(length, 0.0);
    for (std::size_t i = 0; i < arrivals.size(); ++i)
      for (std::size_t k = 0; k < pairs[i][ear].size(); ++k) ears[ear][arrivals[i].sample + k] += arrivals[i].amplitude * pairs[i][ear][k];
    // The diffuse tail: the response's broadband energy per bin, a noise of its own per ear.
    std::mt19937_64 rng(o.seed * 2 + static_cast<std::uint64_t>(ear) + 0x51ED270Bull);
    for (std::size_t b = 0; b < r.late.energy.size(); ++b) {
      const std::size_t begin = std::max(b * r.late.bin_samples, r.late.first_sample);
      const std::size_t end = std::min(length, (b + 1) * r.late.bin_samples);
      if (begin >= end || r.late.energy[b] == 0.0) continue;
      const double a = std::sqrt(r.late.energy[b] / static_cast<double>(end - begin));
      for (std::size_t i = begin; i < end; ++i) ears[ear][i] += (rng() & 1) ? a : -a;
    }
  }
  return ears;
}

}  // namespace vola::audio
