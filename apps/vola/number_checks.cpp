#include "number_checks.hpp"

#include <cmath>
#include <cstdlib>
#include <string>

namespace vola::cli {

namespace {

CLI::Validator sign_check(bool zero_allowed) {
  const std::string wanted = zero_allowed ? "a finite number of 0 or more" : "a positive finite number";
  return CLI::Validator(
      [zero_allowed, wanted](std::string& text) -> std::string {
        char* end = nullptr;
        const double value = std::strtod(text.c_str(), &end);
        if (end == text.c_str() || *end != '\0') return "must be " + wanted + "; '" + text + "' is not a number";
        if (!std::isfinite(value) || value < 0.0 || (value == 0.0 && !zero_allowed)) return "must be " + wanted + ", not " + text;
        return {};
      },
      zero_allowed ? "NONNEGATIVE" : "POSITIVE");
}

}  // namespace

CLI::Validator positive_number() { return sign_check(false); }
CLI::Validator non_negative_number() { return sign_check(true); }

}  // namespace vola::cli
