// What the option structs of the two acoustic models (response.hpp's paper model,
// room_response.hpp's physical one) check alike.
#pragma once

#include <cmath>
#include <sstream>
#include <string>

#include "vola/error.hpp"

namespace vola::audio::detail {

// InvalidArgument "WHAT (got VALUE)".
[[noreturn]] inline void refuse_option(const std::string& what, double value) {
  std::ostringstream s;
  s << what << " (got " << value << ")";
  throw InvalidArgument(s.str());
}

inline void check_sound_options(double sample_rate, double speed_of_sound) {
  if (!(sample_rate >= 1000.0 && sample_rate <= 768000.0))
    refuse_option("the sample rate must be in [1000, 768000] Hz", sample_rate);
  if (!(speed_of_sound > 0.0 && std::isfinite(speed_of_sound))) refuse_option("the speed of sound must be > 0", speed_of_sound);
}

}  // namespace vola::audio::detail
