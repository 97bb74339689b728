// Fast line output for commands that print one line per voxel (millions of lines):
// numbers formatted with std::to_chars into a large buffer, flushed to stdout.
#pragma once

#include <charconv>
#include <cstdint>
#include <cstdio>
#include <string>
#include <vector>

#include "vola/error.hpp"

namespace vola::cli {

class TextOutput {
 public:
  TextOutput() { buffer_.reserve(kSize + 128); }
  ~TextOutput() { flush(); }
  TextOutput& text(std::string_view s) {
    buffer_.append(s);
    return maybe_flush();
  }
  TextOutput& ch(char c) {
    buffer_.push_back(c);
    return maybe_flush();
  }
  TextOutput& number(std::uint64_t v) { return format(v); }
  // Shortest text that reads back as the same double.
  TextOutput& number(double v) { return format(v); }
  TextOutput& hex64(std::uint64_t v) {
    char s[19] = "0x";
    for (int i = 0; i < 16; ++i) s[2 + i] = "0123456789abcdef"[(v >> (60 - 4 * i)) & 15u];
    buffer_.append(s, 18);
    return maybe_flush();
  }
  void flush() {
    if (!buffer_.empty() && std::fwrite(buffer_.data(), 1, buffer_.size(), stdout) != buffer_.size())
      throw IoError("cannot write to standard output");
    buffer_.clear();
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
  std::string buffer_;
};

}  // namespace vola::cli
