// Seed inputs for fuzzing: the golden reference files plus files written by vola
// itself that reach what the reference never produces (extension records, attribute
// columns, compressed levels, dense payloads, depth 10).
#pragma once

#include <cstdint>
#include <cstdlib>
#include <filesystem>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

namespace vola_fuzz {

struct Seed {
  std::string name;
  std::vector<std::uint8_t> bytes;
};

// Outcomes of LLVMFuzzerTestOneInput so far.
struct Stats {
  std::uint64_t parsed = 0;
  std::uint64_t refused = 0;
};
// One counter per program (inline: every target and its replay share it).
inline Stats& stats() {
  static Stats s;
  return s;
}

// A broken invariant of what a reader returned: abort, so that libFuzzer keeps the input.
inline void check(bool invariant) {
  if (!invariant) std::abort();
}

// Files written by the library.
std::vector<Seed> synthetic_seeds();
// Every .vol / .dvol / .dvol.gz below `golden` (gunzipped with gzip -dc). Throws
// std::runtime_error when a file cannot be read.
std::vector<Seed> golden_seeds(const std::filesystem::path& golden);

// `golden`'s sibling data/<sub> (the shared data folder's files), or an empty path when it
// is missing; with CI set a missing folder throws std::runtime_error instead.
inline std::filesystem::path shared_data(const std::filesystem::path& golden, const std::string& sub) {
  const auto path = golden.parent_path() / "data" / sub;
  if (std::filesystem::exists(path)) return path;
  if (std::getenv("CI")) throw std::runtime_error("shared data " + path.string() + " is missing (CI is set; set VOLA_SHARED)");
  return {};
}

}  // namespace vola_fuzz
