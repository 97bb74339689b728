// Internal to the readers: the words of one line of a text header (PLY, PCD, binvox), and
// whole-word numbers from them.
#pragma once

#include <charconv>
#include <string_view>
#include <system_error>
#include <vector>

namespace vola::io {

inline bool is_header_space(char c) {
  return c == ' ' || c == '\t' || c == '\r' || c == '\n' || c == '\v' || c == '\f';
}

// The whitespace-separated words of `line` into `words` (replaced), viewing `line`.
inline void split_words(std::string_view line, std::vector<std::string_view>& words) {
  words.clear();
  std::size_t i = 0;
  while (i < line.size()) {
    while (i < line.size() && is_header_space(line[i])) ++i;
    const std::size_t start = i;
    while (i < line.size() && !is_header_space(line[i])) ++i;
    if (i > start) words.push_back(line.substr(start, i - start));
  }
}

inline std::vector<std::string_view> split_words(std::string_view line) {
  std::vector<std::string_view> words;
  split_words(line, words);
  return words;
}

// The whole word as a number (no trailing characters; for integers, no overflow).
template <class T>
bool parse_number(std::string_view word, T& value) {
  const auto r = std::from_chars(word.data(), word.data() + word.size(), value);
  return r.ec == std::errc() && r.ptr == word.data() + word.size();
}

}  // namespace vola::io
