#include "vola/io/text_points.hpp"

#include <algorithm>
#include <array>
#include <charconv>
#include <cmath>
#include <fstream>
#include <optional>
#include <string_view>

#include "column_names.hpp"
#include "vola/error.hpp"

namespace vola::io {

namespace {

bool is_digit(char c) { return c >= '0' && c <= '9'; }

// Whether a line is written with decimal commas, as spreadsheets in most of Europe write
// it: "1,5;2,25;3" (their CSV separates fields by semicolons for this reason) or
// "1,5<TAB>2,25 3". A line with a semicolon is; a line whose fields are separated by
// spaces or tabs is when its commas each stand alone in a field, between digits. Plain
// CSV ("1.5,2.25,3", "1, 2, 3") is not.
bool uses_decimal_comma(std::string_view line) {
  if (line.find(';') != std::string_view::npos) return true;
  int fields = 0;
  bool comma = false;
  for (std::size_t i = 0; i < line.size();) {
    while (i < line.size() && (line[i] == ' ' || line[i] == '\t' || line[i] == '\r')) ++i;
    if (i == line.size()) break;
    ++fields;
    int commas = 0;
    for (; i < line.size() && line[i] != ' ' && line[i] != '\t' && line[i] != '\r'; ++i) {
      if (line[i] != ',') continue;
      if (++commas > 1 || i == 0 || i + 1 == line.size() || !is_digit(line[i - 1]) || !is_digit(line[i + 1]))
        return false;
      comma = true;
    }
  }
  return comma && fields >= 2;
}

// Field separators: spaces, tabs, semicolons and, unless it is the decimal mark, commas.
bool is_separator(char c, bool decimal_comma) {
  return c == ' ' || c == '\t' || c == ';' || c == '\r' || (c == ',' && !decimal_comma);
}

bool is_data_line(std::string_view line) {
  std::size_t i = 0;
  while (i < line.size() && is_separator(line[i], false)) ++i;
  return i < line.size() && line[i] != '#' && line.substr(i, 2) != "//";
}

// A number as from_chars reads it, a leading '+' allowed, a decimal comma read as a point.
bool parse_number(std::string_view text, bool decimal_comma, double& value) {
  if (!text.empty() && text.front() == '+') text.remove_prefix(1);
  std::array<char, 64> copy;
  if (decimal_comma && text.find(',') != std::string_view::npos && text.size() <= copy.size()) {
    std::replace_copy(text.begin(), text.end(), copy.begin(), ',', '.');
    text = std::string_view(copy.data(), text.size());
  }
  const auto result = std::from_chars(text.data(), text.data() + text.size(), value);
  return result.ec == std::errc() && result.ptr == text.data() + text.size();
}

class LineParser {
 public:
  // `header_line`: a line of column names to pass over (0: none).
  LineParser(const std::string& path, const TextColumns& columns, PointCloud& cloud, std::uint64_t header_line)
      : path_(path), columns_(columns), cloud_(cloud), header_line_(header_line) {
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
    if (line_number <= static_cast<std::uint64_t>(columns_.skip_lines) || line_number == header_line_) return;
    // The file's first data line says whether its decimal mark is a comma, for every line.
    if (!decimal_comma_) decimal_comma_ = uses_decimal_comma(line);
    int column = 0;
    while (i < line.size() && column <= max_column_) {
      std::size_t end = i;
      while (end < line.size() && !is_separator(line[end], *decimal_comma_)) ++end;
      double v = 0;
      if (!parse_number(line.substr(i, end - i), *decimal_comma_, v))
        fail(line_number, offset + i, "column " + std::to_string(column + 1) + " '" +
                                          std::string(line.substr(i, end - i)) + "' is not a number");
      values_[static_cast<std::size_t>(column)] = v;
      ++column;
      i = end;
      while (i < line.size() && is_separator(line[i], *decimal_comma_)) ++i;
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
  std::uint64_t header_line_;
  int max_column_ = 2;
  std::vector<double> values_;
  std::optional<bool> decimal_comma_;
};

std::string_view unquoted(std::string_view w) {
  if (w.size() >= 2 && (w.front() == '"' || w.front() == '\'') && w.back() == w.front()) return w.substr(1, w.size() - 2);
  return w;
}

bool is_number(std::string_view w, bool decimal_comma) {
  double v = 0;
  return parse_number(w, decimal_comma, v);
}

// The column of each of x, y, z among the names (any case), or nothing.
std::optional<std::array<int, 3>> xyz_columns(const std::vector<std::string>& names) {
  std::array<int, 3> at{-1, -1, -1};
  for (std::size_t c = 0; c < names.size(); ++c)
    for (int a = 0; a < 3; ++a)
      if (names[c].size() == 1 && std::tolower(static_cast<unsigned char>(names[c][0])) == 'x' + a && at[a] < 0)
        at[a] = static_cast<int>(c);
  if (at[0] < 0 || at[1] < 0 || at[2] < 0) return std::nullopt;
  return at;
}

// Red, green and blue from a header hold 8-bit or 16-bit colours: the narrowest type
// that holds every value (u8 is what the LAS writer scales to 16 bits), else f64.
void type_colours(PointCloud& cloud) {
  for (PointAttribute& a : cloud.attributes) {
    if (a.name != "red" && a.name != "green" && a.name != "blue") continue;
    double most = 0;
    bool whole = true;
    for (const double v : a.values) {
      whole = whole && v >= 0 && v == std::floor(v);
      most = std::max(most, v);
    }
    a.type = !whole || most > 65535 ? ValueType::f64 : most > 255 ? ValueType::u16 : ValueType::u8;
  }
}

}  // namespace

std::optional<TextHeader> read_text_header(const std::string& path, int skip_lines) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw IoError(path + ": cannot open");
  std::string line;
  std::uint64_t number = 0, next_offset = 0;
  std::vector<std::string> names;
  // Leading comment lines may carry the names (CloudCompare, vola export); the first
  // other line ends the search, and is a header itself when it holds names only.
  while (std::getline(in, line)) {
    const std::uint64_t offset = next_offset;
    next_offset += line.size() + 1;
    if (++number <= static_cast<std::uint64_t>(skip_lines)) continue;
    std::string_view rest(line);
    while (!rest.empty() && is_separator(rest.front(), false)) rest.remove_prefix(1);
    if (rest.empty()) continue;
    TextHeader header;
    header.line = number;
    header.offset = offset;
    if (rest.substr(0, 2) == "//") header.comment = true, rest.remove_prefix(2);
    else if (rest.front() == '#') header.comment = true, rest.remove_prefix(1);
    names.clear();
    bool all_names = true;
    const bool decimal_comma = uses_decimal_comma(rest);
    for (std::size_t i = 0; i < rest.size();) {
      while (i < rest.size() && is_separator(rest[i], decimal_comma)) ++i;
      std::size_t end = i;
      while (end < rest.size() && !is_separator(rest[end], decimal_comma)) ++end;
      if (end > i) {
        const std::string_view word = unquoted(rest.substr(i, end - i));
        all_names = all_names && !word.empty() && !is_number(word, decimal_comma);
        names.emplace_back(word);
      }
      i = end;
    }
    const bool named = all_names && !names.empty();
    if (header.comment) {
      if (named && xyz_columns(names)) return TextHeader{names, header.line, header.offset, true};
      continue;
    }
    if (named) return TextHeader{names, header.line, header.offset, false};
    return std::nullopt;
  }
  return std::nullopt;
}

TextColumns text_columns_of(const TextHeader& header) {
  TextColumns columns;
  const auto xyz = xyz_columns(header.names);
  if (!xyz) throw InvalidArgument("the header names no x, y and z columns");
  columns.x = (*xyz)[0], columns.y = (*xyz)[1], columns.z = (*xyz)[2];
  for (std::size_t c = 0; c < header.names.size(); ++c) {
    const int column = static_cast<int>(c);
    if (column == columns.x || column == columns.y || column == columns.z) continue;
    std::string name = point_column_name(header.names[c]);
    const bool taken = std::any_of(columns.attributes.begin(), columns.attributes.end(),
                                   [&](const PointAttribute& a) { return a.name == name; });
    if (taken || name.empty()) continue;  // a second column of one name stays unread, as in PLY
    const Reduction reduction = point_column_reduction(name);
    columns.attributes.push_back({std::move(name), ValueType::f64, reduction, {}});
    columns.attribute_columns.push_back(column);
  }
  return columns;
}

int count_text_columns(const std::string& path, int skip_lines) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw IoError(path + ": cannot open");
  std::string line;
  int line_number = 0;
  while (std::getline(in, line)) {
    if (++line_number <= skip_lines) continue;
    if (!is_data_line(line)) continue;
    const bool decimal_comma = uses_decimal_comma(line);
    std::size_t i = 0;
    while (i < line.size() && is_separator(line[i], decimal_comma)) ++i;
    int columns = 0;
    while (i < line.size()) {
      ++columns;
      while (i < line.size() && !is_separator(line[i], decimal_comma)) ++i;
      while (i < line.size() && is_separator(line[i], decimal_comma)) ++i;
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
  // A header line is never a point; it lays the columns out when they are left to it.
  const std::optional<TextHeader> header = read_text_header(path, columns.skip_lines);
  TextColumns layout = columns;
  const bool named = header && columns.from_header;
  if (named) {
    if (!xyz_columns(header->names))
      throw FormatError(path, header->offset, "line " + std::to_string(header->line) + " names its columns but none of them x, y and z;"
                                 " say which columns hold them (--columns X Y Z, counted from 1)");
    layout = text_columns_of(*header);
    layout.skip_lines = columns.skip_lines;
  }
  PointCloud cloud;
  LineParser parser(path, layout, cloud, header && !header->comment ? header->line : 0);
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
  if (named) type_colours(cloud);
  return cloud;
}

}  // namespace vola::io
