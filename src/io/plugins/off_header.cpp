#include "off_header.hpp"

#include <string>

namespace vola::io {

namespace {

// Assimp parses a NUL-terminated copy of the file: these walk the same bytes.
class Cursor {
 public:
  explicit Cursor(std::string_view text) : text_(std::string(text) + '\0') {}

  char at(std::size_t k = 0) const noexcept { return i_ + k < text_.size() ? text_[i_ + k] : '\0'; }
  std::size_t offset() const noexcept { return i_; }
  // Assimp's `car < end - k`, with end one past the NUL.
  bool before_end_minus(std::size_t k) const noexcept { return i_ + k < text_.size(); }
  void advance(std::size_t k) noexcept { i_ += k; }

  // SkipSpacesAndLineEnd, then whole '#' lines (NextToken).
  void next_token() noexcept {
    skip_blanks();
    while (i_ < text_.size() && (at() == '#' || at() == '\n' || at() == '\r')) {
      while (at() != '\r' && at() != '\n' && at() != '\0') ++i_;
      while (at() == '\r' || at() == '\n') ++i_;
      skip_blanks();
    }
  }
  // strtoul10: decimal digits into an unsigned int that wraps.
  std::uint32_t read_count() noexcept {
    std::uint32_t value = 0;
    while (at() >= '0' && at() <= '9') value = value * 10u + static_cast<std::uint32_t>(text_[i_++] - '0');
    return value;
  }

 private:
  void skip_blanks() noexcept {
    while (at() == ' ' || at() == '\t' || at() == '\r' || at() == '\n') ++i_;
  }
  std::string text_;
  std::size_t i_ = 0;
};

}  // namespace

std::optional<OffCounts> off_header_counts(std::string_view text) {
  Cursor c(text);
  c.next_token();
  // The prefixes, each taken whatever follows it (a leading '4' or 'C' of a count too).
  if (c.before_end_minus(2) && c.at() == 'S' && c.at(1) == 'T') c.advance(2);
  if (c.before_end_minus(1) && c.at() == 'C') c.advance(1);
  if (c.before_end_minus(1) && c.at() == 'N') c.advance(1);
  if (c.before_end_minus(1) && c.at() == '4') c.advance(1);
  const bool has_dimension = c.before_end_minus(1) && c.at() == 'n';
  if (has_dimension) c.advance(1);
  if (c.before_end_minus(3) && c.at() == 'O' && c.at(1) == 'F' && c.at(2) == 'F') {
    c.advance(3);
    c.next_token();
  } else {
    c.next_token();
    if (!c.before_end_minus(1) || c.at() < '0' || c.at() > '9') return std::nullopt;  // "Header is invalid"
  }
  if (has_dimension) {
    if (c.read_count() > 3) return std::nullopt;  // more than 3 coordinates: refused
    c.next_token();
  }
  c.next_token();
  OffCounts counts;
  counts.vertices_at = c.offset();
  counts.vertices = c.read_count();
  c.next_token();
  counts.faces = c.read_count();
  if (counts.vertices == 0 || counts.faces == 0) return std::nullopt;  // refused before allocating
  return counts;
}

}  // namespace vola::io
