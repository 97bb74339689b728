#include "vola/io/ptx.hpp"

#include <algorithm>
#include <array>
#include <charconv>
#include <cmath>
#include <fstream>
#include <optional>
#include <string_view>
#include <vector>

#include "point_colours.hpp"
#include "vola/error.hpp"

namespace vola::io {

namespace {

// The file's lines, read in pieces of 8 MiB: each with its number and byte offset.
class PtxLines {
 public:
  explicit PtxLines(const std::string& path) : path_(path), in_(path, std::ios::binary) {
    if (!in_) throw IoError(path + ": cannot open");
    in_.seekg(0, std::ios::end);
    size_ = static_cast<std::uint64_t>(in_.tellg());
    in_.seekg(0);
  }

  // The next line without its end (and without a '\r'), or nothing at the end of the file.
  std::optional<std::string_view> next() {
    for (;;) {
      const std::size_t newline = buffer_.find('\n', start_);
      if (newline != std::string::npos || (eof_ && start_ < buffer_.size())) {
        const std::size_t end = newline == std::string::npos ? buffer_.size() : newline;
        std::string_view line(buffer_.data() + start_, end - start_);
        offset_ = consumed_ + start_;
        start_ = end + 1;
        ++line_;
        if (!line.empty() && line.back() == '\r') line.remove_suffix(1);
        return line;
      }
      if (eof_) return std::nullopt;
      consumed_ += start_;
      buffer_.erase(0, start_);
      start_ = 0;
      // Up to 8 MiB, no more than the file has left (a small file takes a small buffer).
      const std::uint64_t left = size_ > consumed_ + buffer_.size() ? size_ - consumed_ - buffer_.size() : 0;
      const std::size_t want = static_cast<std::size_t>(std::min<std::uint64_t>(left + 1, std::uint64_t{8} << 20));
      const std::size_t had = buffer_.size();
      buffer_.resize(had + want);
      in_.read(buffer_.data() + had, static_cast<std::streamsize>(want));
      const auto got = static_cast<std::size_t>(in_.gcount());
      eof_ = got < want;
      buffer_.resize(had + got);
    }
  }

  std::uint64_t line() const noexcept { return line_; }
  std::uint64_t offset() const noexcept { return offset_; }
  std::uint64_t bytes_done() const noexcept { return consumed_ + start_; }
  std::uint64_t size() const noexcept { return size_; }
  [[noreturn]] void fail(const std::string& why) const {
    throw FormatError(path_, offset_, "line " + std::to_string(line_) + ": " + why);
  }

 private:
  std::string path_;
  std::ifstream in_;
  std::uint64_t size_ = 0;
  std::string buffer_;
  std::size_t start_ = 0;
  std::uint64_t consumed_ = 0;  // file offset of buffer_[0]
  bool eof_ = false;
  std::uint64_t line_ = 0, offset_ = 0;
};

// The numbers of a line (at most 8; a ninth is an error).
std::size_t numbers(std::string_view line, std::array<double, 8>& out, const PtxLines& lines) {
  std::size_t n = 0;
  std::size_t i = 0;
  while (true) {
    while (i < line.size() && (line[i] == ' ' || line[i] == '\t')) ++i;
    if (i == line.size()) return n;
    if (n == out.size()) lines.fail("more than 7 values");
    const char* first = line.data() + i;
    const auto [end, error] = std::from_chars(first, line.data() + line.size(), out[n]);
    if (error != std::errc{} || (end != line.data() + line.size() && *end != ' ' && *end != '\t'))
      lines.fail("'" + std::string(line.substr(i, 24)) + "' is not a number");
    ++n;
    i = static_cast<std::size_t>(end - line.data());
  }
}

// A header count: a whole number 0..1e9 (checked before it is converted to an integer).
bool is_count(double v) { return v >= 0 && v <= 1e9 && v == std::floor(v); }

std::uint64_t count_line(PtxLines& lines, const char* what) {
  const auto line = lines.next();
  if (!line) lines.fail(std::string("the file ends where a scan's ") + what + " should be");
  std::array<double, 8> v{};
  if (numbers(*line, v, lines) != 1 || !is_count(v[0]))
    lines.fail(std::string("a scan's ") + what + " must be one whole number (PTX's header)");
  return static_cast<std::uint64_t>(v[0]);
}

}  // namespace

Input read_ptx(const std::string& path, const InputOptions& options) {
  PtxLines lines(path);
  Input in;
  in.format = "ptx";
  PointCloud& cloud = in.cloud;
  std::optional<std::size_t> values;  // per point line: 4, or 7 with colour (the first scan says)
  std::optional<ColourColumns> colour;
  std::array<double, 8> v{};
  for (;;) {
    // Skip blank lines between scans; the end of the file after a whole scan is the end.
    std::optional<std::string_view> first;
    while ((first = lines.next()) && first->find_first_not_of(" \t") == std::string_view::npos) {
    }
    if (!first) break;
    if (numbers(*first, v, lines) != 1)
      lines.fail("a scan's number of columns must be one whole number (PTX's header)");
    const double columns = v[0];
    if (!is_count(columns)) lines.fail("a scan's number of columns must be one whole number (PTX's header)");
    const std::uint64_t rows = count_line(lines, "number of rows");
    for (int k = 0; k < 4; ++k) {  // the scanner's registered position and axes: not needed for the points
      const auto line = lines.next();
      if (!line || numbers(*line, v, lines) != 3)
        lines.fail("a scan header's lines 3-6 hold three numbers each (the scanner's position and axes)");
    }
    std::array<std::array<double, 4>, 4> m{};
    for (auto& row : m) {
      const auto line = lines.next();
      if (!line || numbers(*line, v, lines) != 4)
        lines.fail("a scan header's lines 7-10 hold four numbers each (its 4 x 4 transformation matrix)");
      for (std::size_t c = 0; c < 4; ++c) row[c] = v[c];
    }
    // A rigid transformation's last column is 0 0 0 1; anything else is damage or a
    // projective transformation, whose last column was dropped without a word.
    for (std::size_t r = 0; r < 4; ++r)
      if (std::fabs(m[r][3] - (r == 3 ? 1.0 : 0.0)) > 1e-9)
        lines.fail("the transformation matrix's last column is not 0 0 0 1 (row " + std::to_string(r + 1) +
                   " ends in " + std::to_string(m[r][3]) + ")");
    const std::uint64_t points = static_cast<std::uint64_t>(columns) * rows;
    for (std::uint64_t p = 0; p < points; ++p) {
      const auto line = lines.next();
      if (!line)
        lines.fail("the file ends after " + std::to_string(p) + " of the scan's " + std::to_string(points) +
                   " points (" + std::to_string(static_cast<std::uint64_t>(columns)) + " columns x " +
                   std::to_string(rows) + " rows)");
      const std::size_t n = numbers(*line, v, lines);
      const bool no_return = v[0] == 0 && v[1] == 0 && v[2] == 0;
      if (!values && n == 4 && no_return) {  // a miss written short: it says nothing of the lines' width
        ++in.not_finite;
        continue;
      }
      if (!values) {
        if (n != 4 && n != 7) lines.fail("a point line holds x y z intensity [red green blue]: 4 or 7 values");
        values = n;
        if (options.attributes) cloud.attributes.push_back({"intensity", ValueType::f32, Reduction::mean, {}});
        if (n == 7 && (options.attributes || options.payload))
          colour.emplace(cloud, ColourScale::bits8, options.attributes, options.payload);
      } else if (n != *values && !(n == 4 && *values == 7 && no_return)) {
        lines.fail(std::to_string(n) + " values where the file's point lines hold " + std::to_string(*values));
      }
      if (no_return) {
        ++in.not_finite;
        continue;
      }
      for (std::size_t a = 0; a < 3; ++a)
        cloud.xyz.push_back(v[0] * m[0][a] + v[1] * m[1][a] + v[2] * m[2][a] + m[3][a]);
      if (options.attributes) cloud.attributes.front().values.push_back(v[3]);
      if (colour) colour->add(v[4], v[5], v[6]);
      if (options.progress && (p & 0xFFFF) == 0) options.progress(lines.bytes_done(), lines.size());
    }
  }
  if (colour) colour->finish();
  if (options.progress) options.progress(lines.size(), lines.size());
  return in;
}

}  // namespace vola::io
