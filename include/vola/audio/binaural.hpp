// Binaural rendering: a room response as the two ear signals of a listener, through a
// head-related transfer function (HRTF) read from a SOFA file by libmysofa (Debian ships
// the MIT KEMAR set: /usr/share/libmysofa/MIT_KEMAR_normal_pinna.sofa).
//
// Every arrival the response holds as an impulse (the direct sound and each image source)
// passes through the HRTF pair of the direction it comes from, in the listener's frame:
// the listener stands upright facing `facing_degrees` (counterclockwise from +x about +z;
// SOFA's frame is x ahead, y to the left, z up). The late tail arrives from everywhere
// (a diffuse field): each ear gets the tail's energy as its own noise, the two
// uncorrelated, as in a diffuse field well above the lowest frequencies. Amplitudes are
// broadband (a response made per band is rendered with each arrival's broadband amplitude).
#pragma once

#include <array>
#include <memory>
#include <string>
#include <vector>

#include "vola/audio/room_response.hpp"

namespace vola::audio {

class Hrtf {
 public:
  // Throws IoError naming the file and libmysofa's reason when it does not load. The
  // filters are resampled to `sample_rate`.
  Hrtf(const std::string& path, double sample_rate);
  ~Hrtf();
  Hrtf(const Hrtf&) = delete;
  Hrtf& operator=(const Hrtf&) = delete;

  // The left and right impulse responses for sound from `direction` (listener frame; any
  // length), their delays included (each starts at the sound's arrival at the head centre).
  std::array<std::vector<double>, 2> filters(const Point& direction) const;
  std::size_t length() const noexcept { return length_; }  // taps, delays excluded

 private:
  struct Handle;
  std::unique_ptr<Handle> handle_;
  std::size_t length_ = 0;
  double sample_rate_ = 0.0;
};

// The two ear responses (left, right) of `response`, made for `source` and `listener`.
std::array<std::vector<double>, 2> binaural_response(const RoomResponse& response, const Hrtf& hrtf, const Point& source,
                                                    const Point& listener, double facing_degrees, const RoomOptions& options);

}  // namespace vola::audio
