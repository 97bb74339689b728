// Fast line output for commands that print one line per voxel (millions of lines):
// numbers formatted with std::to_chars into a large buffer, flushed to a stream
// (stdout, or an OutputFile's). finish() reports a failed write; the destructor must not
// throw (a throwing destructor ends the process with SIGABRT, as `vola generate` did on
// a full disk), so what it flushes on the way out of an error is best effort.
#pragma once

#include <charconv>
#include <cstdint>
#include <cerrno>
#include <cstdio>
#include <cstring>
#include <string>
#include <vector>

#include "vola/error.hpp"
#include "vola/number_text.hpp"

namespace vola::cli {

// The shortest text that reads back as the same double ("1e-09", "0.1"), positional
// for coordinates ("500000", not "5e+05": vola::write_number).
inline std::string shortest_text(double v) {
  char text[kNumberTextSize];
  return std::string(text, write_number(text, v));
}

class TextOutput {
 public:
  TextOutput() : TextOutput(stdout, "standard output") {}
  // `name` labels errors.
  TextOutput(std::FILE* stream, std::string name) : stream_(stream), name_(std::move(name)) { buffer_.reserve(kSize + 128); }
  ~TextOutput() {
    if (!buffer_.empty()) std::fwrite(buffer_.data(), 1, buffer_.size(), stream_);
  }
  TextOutput(const TextOutput&) = delete;
  TextOutput& operator=(const TextOutput&) = delete;
  TextOutput& text(std::string_view s) {
    buffer_.append(s);
    return maybe_flush();
  }
  TextOutput& ch(char c) {
    buffer_.push_back(c);
    return maybe_flush();
  }
  TextOutput& number(std::uint64_t v) { return format(v); }
  // Shortest text that reads back as the same double (vola::write_number: "5000000", "0.1", "1e-09").
  TextOutput& number(double v) {
    char s[kNumberTextSize];
    buffer_.append(s, write_number(s, v));
    return maybe_flush();
  }
  TextOutput& hex64(std::uint64_t v) {
    char s[19] = "0x";
    for (int i = 0; i < 16; ++i) s[2 + i] = "0123456789abcdef"[(v >> (60 - 4 * i)) & 15u];
    buffer_.append(s, 18);
    return maybe_flush();
  }
  void flush() {
    // Cleared even when the write fails, so that the destructor does not write it again.
    const bool written = buffer_.empty() || std::fwrite(buffer_.data(), 1, buffer_.size(), stream_) == buffer_.size();
    buffer_.clear();
    if (!written) throw IoError(failure());
  }
  // Everything written, or IoError.
  void finish() {
    flush();
    if (std::fflush(stream_) != 0 || std::ferror(stream_)) throw IoError(failure());
  }

 private:
  static constexpr std::size_t kSize = 1 << 16;
  template <class T>
  TextOutput& format(T v) {
    char s[32];
    const auto r = std::to_chars(s, s + sizeof s, v);
    buffer_.append(s, r.ptr);
    return maybe_flush();
  }
  TextOutput& maybe_flush() {
    if (buffer_.size() >= kSize) flush();
    return *this;
  }
  std::string failure() const { return name_ + ": write failed: " + std::strerror(errno); }
  std::FILE* stream_;
  std::string name_;
  std::string buffer_;
};

}  // namespace vola::cli
