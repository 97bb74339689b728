#include "vola/audio/air.hpp"

#include <cmath>

namespace vola::audio {

double air_attenuation_db_per_m(double f, double celsius, double relative_humidity, double kilopascal) {
  // ISO 9613-1 equations (B.1), (3) to (5): the two relaxation frequencies of oxygen and
  // nitrogen from the molar concentration of water vapour h (percent), then the classical
  // and rotational absorption plus the two vibrational relaxations.
  const double T = celsius + 273.15, T0 = 293.15, T01 = 273.16;
  const double pa = kilopascal / 101.325;
  const double saturation = std::pow(10.0, -6.8346 * std::pow(T01 / T, 1.261) + 4.6151);
  const double h = relative_humidity * saturation / pa;
  const double fr_o = pa * (24.0 + 4.04e4 * h * (0.02 + h) / (0.391 + h));
  const double fr_n = pa * std::pow(T / T0, -0.5) * (9.0 + 280.0 * h * std::exp(-4.170 * (std::pow(T / T0, -1.0 / 3.0) - 1.0)));
  const double f2 = f * f;
  return 8.686 * f2 *
         (1.84e-11 / pa * std::sqrt(T / T0) +
          std::pow(T / T0, -2.5) * (0.01275 * std::exp(-2239.1 / T) / (fr_o + f2 / fr_o) +
                                    0.1068 * std::exp(-3352.0 / T) / (fr_n + f2 / fr_n)));
}

}  // namespace vola::audio
