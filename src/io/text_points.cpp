#include "vola/io/text_points.hpp"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <fstream>
#include <string_view>

#include "vola/error.hpp"

namespace vola::io {

namespace {

bool is_separator(char c) { return c == ' ' || c == '\t' || c == ',' || c == ';' || c == '\r'; }

class LineParser {
 public:
  LineParser(const std::string& path, const TextColumns& columns, PointCloud& cloud)
      : path_(path), columns_(columns), cloud_(cloud) {
    max_column_ = std::max({columns.x, columns.y, columns.z});
    for (int c : columns.payload) max_column_ = std::max(max_column_, c);
    for (int c : columns.attribute_columns) max_column_ = std::max(max_column_, c);
    values_.resize(static_cast<std::size_t>(max_column_) + 1);
    if (columns.payload.size() > 8) throw InvalidArgument("at most 8 payload columns fit a 64-bit payload word");
    if (columns.attribute_columns.size() != columns.attributes.size())
      throw InvalidArgument("one attribute description per attribute column, please");
    if (!columns.payload.empty()) cloud_.payload.clear();
    cloud_.attributes = columns.attributes;
  }

  void parse(std::string_view line, std::uint64_t line_number, std::uint64_t offset) {
    std::size_t i = 0;
    while (i < line.size() && (line[i] == ' ' || line[i] == '\t' || line[i] == '\r')) ++i;
    if (i == line.size() || line[i] == '#' || line.substr(i, 2) == "//") return;
    if (line_number <= static_cast<std::uint64_t>(columns_.skip_lines)) return;
    int column = 0;
    while (i < line.size() && column <= max_column_) {
      std::size_t end = i;
      while (end < line.size() && !is_separator(line[end])) ++end;
      const char* first = line.data() + i;
      const char* last = line.data() + end;
      if (*first == '+') ++first;
      double v = 0;
      const auto result = std::from_chars(first, last, v);
      if (result.ec != std::errc() || result.ptr != last)
        fail(line_number, offset + i, "column " + std::to_string(column + 1) + " '" +
                                          std::string(line.substr(i, end - i)) + "' is not a number");
      values_[static_cast<std::size_t>(column)] = v;
      ++column;
      i = end;
      while (i < line.size() && is_separator(line[i])) ++i;
    }
    if (column <= max_column_)
      fail(line_number, offset, "has " + std::to_string(column) + " columns, column " +
                                    std::to_string(max_column_ + 1) + " is needed");
    cloud_.xyz.push_back(values_[static_cast<std::size_t>(columns_.x)]);
    cloud_.xyz.push_back(values_[static_cast<std::size_t>(columns_.y)]);
    cloud_.xyz.push_back(values_[static_cast<std::size_t>(columns_.z)]);
    if (!columns_.payload.empty()) {
      std::uint64_t word = 0;
      for (std::size_t k = 0; k < columns_.payload.size(); ++k) {
        const double b = values_[static_cast<std::size_t>(columns_.payload[k])];
        if (!(b >= 0 && b <= 255) || b != std::floor(b))
          fail(line_number, offset, "payload byte " + std::to_string(k) + " (column " +
                                        std::to_string(columns_.payload[k] + 1) + ") is " + std::to_string(b) +
                                        ", not an integer 0..255");
        word |= static_cast<std::uint64_t>(b) << (8 * k);
      }
      cloud_.payload.push_back(word);
    }
    for (std::size_t k = 0; k < columns_.attribute_columns.size(); ++k)
      cloud_.attributes[k].values.push_back(values_[static_cast<std::size_t>(columns_.attribute_columns[k])]);
  }

 private:
  [[noreturn]] void fail(std::uint64_t line_number, std::uint64_t offset, const std::string& cause) const {
    throw FormatError(path_, offset, "line " + std::to_string(line_number) + ": " + cause);
  }
  const std::string& path_;
  const TextColumns& columns_;
  PointCloud& cloud_;
  int max_column_ = 2;
  std::vector<double> values_;
};

}  // namespace

int count_text_columns(const std::string& path, int skip_lines) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw IoError(path + ": cannot open");
  std::string line;
  int line_number = 0;
  while (std::getline(in, line)) {
    if (++line_number <= skip_lines) continue;
    std::size_t i = 0;
    while (i < line.size() && is_separator(line[i])) ++i;
    if (i == line.size() || line[i] == '#' || line.compare(i, 2, "//") == 0) continue;
    int columns = 0;
    while (i < line.size()) {
      ++columns;
      while (i < line.size() && !is_separator(line[i])) ++i;
      while (i < line.size() && is_separator(line[i])) ++i;
    }
    return columns;
  }
  return 0;
}

PointCloud read_text_points(const std::string& path, const TextColumns& columns,
                            const std::function<void(std::uint64_t, std::uint64_t)>& progress) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw IoError(path + ": cannot open");
  in.seekg(0, std::ios::end);
  const std::uint64_t total = static_cast<std::uint64_t>(in.tellg());
  in.seekg(0);
  PointCloud cloud;
  LineParser parser(path, columns, cloud);
  constexpr std::size_t kChunk = 8 << 20;
  std::string buffer;
  std::uint64_t consumed = 0;  // file offset of buffer[0]
  std::uint64_t line_number = 0;
  std::vector<char> chunk(kChunk);
  bool eof = false;
  while (!eof) {
    in.read(chunk.data(), static_cast<std::streamsize>(chunk.size()));
    const std::size_t got = static_cast<std::size_t>(in.gcount());
    eof = got < chunk.size();
    buffer.append(chunk.data(), got);
    std::size_t start = 0;
    for (;;) {
      std::size_t newline = buffer.find('\n', start);
      if (newline == std::string::npos) {
        if (!eof) break;
        if (start == buffer.size()) break;
        newline = buffer.size();  // last line without a newline
      }
      ++line_number;
      parser.parse(std::string_view(buffer).substr(start, newline - start), line_number, consumed + start);
      start = newline + 1;
      if (start > buffer.size()) break;
    }
    const std::size_t kept = std::min(start, buffer.size());
    consumed += kept;
    buffer.erase(0, kept);
    if (progress) progress(consumed, total);
  }
  return cloud;
}

}  // namespace vola::io
