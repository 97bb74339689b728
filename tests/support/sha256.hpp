// SHA-256 (FIPS 180-4) of a byte span as 64 lower-case hex digits: the tests compare
// decoded data with digests an independent tool recorded (EXPECTED.txt).
#pragma once

#include <cstdint>
#include <span>
#include <string>

namespace vola_test {

std::string sha256_hex(std::span<const std::uint8_t> bytes);

}  // namespace vola_test
