// Sound absorption by the atmosphere (ISO 9613-1:1993, pure tones): what a path of a given
// length loses on top of spreading, strongly rising with frequency (at 20 degrees C and 50%
// relative humidity: 0.44 dB/km at 125 Hz, 29 dB/km at 4 kHz).
#pragma once

namespace vola::audio {

// Attenuation in dB per metre of a tone of `frequency` Hz in air at `celsius` degrees,
// `relative_humidity` percent and `kilopascal` ambient pressure.
double air_attenuation_db_per_m(double frequency, double celsius, double relative_humidity, double kilopascal = 101.325);

}  // namespace vola::audio
