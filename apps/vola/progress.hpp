// A one-line progress bar on stderr for long work, drawn only when stderr is a
// terminal (or VOLA_PROGRESS=1), at most ten times a second.
#pragma once

#include <chrono>
#include <cstdint>
#include <string>

namespace vola::cli {

class Progress {
 public:
  explicit Progress(std::string label);
  ~Progress();
  void update(std::uint64_t done, std::uint64_t total);
  void finish();

 private:
  std::string label_;
  bool enabled_;
  bool drawn_ = false;
  std::chrono::steady_clock::time_point last_{};
};

}  // namespace vola::cli
