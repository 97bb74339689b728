#include "vola/io/text_points.hpp"

#include <algorithm>
#include <array>
#include <charconv>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <optional>
#include <string_view>
#include <unordered_set>

#include "column_names.hpp"
#include "content_kind.hpp"
#include "point_colours.hpp"
#include "vola/error.hpp"
#include "vola/io/input.hpp"

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

constexpr std::string_view kByteOrderMark = "\xEF\xBB\xBF";  // UTF-8's, as Excel's "CSV UTF-8" begins

// How many bytes at the start of a line are the UTF-8 byte order mark (only the file's
// first line can begin with one).
std::size_t byte_order_mark(std::string_view line, std::uint64_t line_number) {
  return line_number == 1 && line.starts_with(kByteOrderMark) ? kByteOrderMark.size() : 0;
}

// How the file ends its lines: '\n' (with or without '\r' before it), or '\r' alone as
// classic Mac OS and some instruments write, told from the first 64 KiB.
char line_end_of(std::ifstream& in) {
  std::array<char, 1 << 16> head;
  in.read(head.data(), head.size());
  const std::string_view bytes(head.data(), static_cast<std::size_t>(in.gcount()));
  in.clear();
  in.seekg(0);
  return bytes.find('\n') == std::string_view::npos && bytes.find('\r') != std::string_view::npos ? '\r' : '\n';
}

// Leica's PTS begins each scan with a line holding its point count alone.
bool has_count_lines(const std::string& path) {
  std::string ext = std::filesystem::path(path).extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  return ext == ".pts";
}

bool is_count_line(std::string_view line) {
  while (!line.empty() && (line.front() == ' ' || line.front() == '\t')) line.remove_prefix(1);
  while (!line.empty() && (line.back() == ' ' || line.back() == '\t' || line.back() == '\r')) line.remove_suffix(1);
  return !line.empty() && std::all_of(line.begin(), line.end(), is_digit);
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
  // `header_line`: a line of column names to pass over (0: none), naming `header_columns`.
  // `count_lines`: lines of one integer are a PTS file's point counts, passed over.
  LineParser(const std::string& path, const TextColumns& columns, PointCloud& cloud, std::uint64_t header_line,
             std::size_t header_columns, bool count_lines)
      : path_(path),
        columns_(columns),
        cloud_(cloud),
        header_line_(header_line),
        header_columns_(static_cast<int>(std::min<std::size_t>(header_columns, 1u << 20))),
        count_lines_(count_lines) {
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
    const std::size_t mark = byte_order_mark(line, line_number);
    line.remove_prefix(mark);
    offset += mark;
    std::size_t i = 0;
    while (i < line.size() && (line[i] == ' ' || line[i] == '\t' || line[i] == '\r')) ++i;
    if (i == line.size() || line[i] == '#' || line.substr(i, 2) == "//") return;
    if (line_number <= static_cast<std::uint64_t>(columns_.skip_lines) || line_number == header_line_) return;
    if (count_lines_ && is_count_line(line)) return;
    // Each line says whether its decimal mark is a comma: a file whose first point has
    // whole numbers may write "1,5" further down.
    const bool decimal_comma = uses_decimal_comma(line);
    int column = 0;
    while (i < line.size()) {
      std::size_t end = i;
      while (end < line.size() && !is_separator(line[end], decimal_comma)) ++end;
      if (column <= max_column_) {
        double v = 0;
        if (!parse_number(line.substr(i, end - i), decimal_comma, v)) {
          const std::string word(line.substr(i, end - i));
          // An ESRI ASCII grid (.asc, as the text points are) begins "ncols N".
          const bool grid = column == 0 && (word == "ncols" || word == "NCOLS" || word == "nrows" || word == "NROWS");
          fail(line_number, offset + i,
               "column " + std::to_string(column + 1) + " '" + word + "' is not a number" +
                   (grid ? " (an ESRI ASCII grid? read it as an elevation raster with --format dem)" : ""));
        }
        values_[static_cast<std::size_t>(column)] = v;
      }
      ++column;
      i = end;
      while (i < line.size() && is_separator(line[i], decimal_comma)) ++i;
    }
    if (column <= max_column_)
      fail(line_number, offset, "has " + std::to_string(column) + " columns, column " +
                                    std::to_string(max_column_ + 1) + " is needed");
    // Every point has the columns of the first: a line with more is not read in part
    // (a file of lines ended by something else, commas that are decimal marks).
    if (columns_per_line_ == 0) {
      columns_per_line_ = column;
      first_line_ = line_number;
      first_offset_ = offset;
    } else if (column != columns_per_line_) {
      // The first point is the odd one out: blame it, not every line after it.
      if (column == header_columns_)
        fail(first_line_, first_offset_,
             "the first point has " + std::to_string(columns_per_line_) + " columns where the header (line " +
                 std::to_string(header_line_) + ") names " + std::to_string(header_columns_) + " and line " +
                 std::to_string(line_number) + " has " + std::to_string(column) + " (a stray value on this line?)");
      fail(line_number, offset, "has " + std::to_string(column) + " columns where line " + std::to_string(first_line_) +
                                    ", the first point, has " + std::to_string(columns_per_line_));
    }
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
  int header_columns_;
  bool count_lines_;
  int max_column_ = 2;
  std::vector<double> values_;
  int columns_per_line_ = 0;  // the first point's
  std::uint64_t first_line_ = 0;
  std::uint64_t first_offset_ = 0;
};

// Where the field starting at `i` ends: at the next separator, or, for a quoted field
// (a header name may hold separators: "M3C2 distance", as CloudCompare writes it), at
// the next separator after its closing quote.
std::size_t field_end(std::string_view line, std::size_t i, bool decimal_comma) {
  std::size_t end = i;
  if (end < line.size() && (line[end] == '"' || line[end] == '\'')) {
    const std::size_t close = line.find(line[end], end + 1);
    if (close != std::string_view::npos) end = close + 1;
  }
  while (end < line.size() && !is_separator(line[end], decimal_comma)) ++end;
  return end;
}

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

// Red, green and blue from a header: u16 when every value is a whole 0..65535, else f64.
// Text says nothing of a colour's bit depth, so the values go on as written, as PDAL's
// readers.text and LAStools' txt2las take them: a LAS file written as text and read back
// keeps its colours (typed u8, 0..255 colours were widened to 16 bits by the LAS writer).
// A PLY output still writes colours of 0..255 as uchar. Colours scaled from 0..1
// (`eight_bit`) are 8-bit colours, u8.
void type_colours(PointCloud& cloud, bool eight_bit) {
  for (PointAttribute& a : cloud.attributes) {
    if (a.name != "red" && a.name != "green" && a.name != "blue") continue;
    double most = 0;
    bool whole = true;
    for (const double v : a.values) {
      whole = whole && v >= 0 && v == std::floor(v);
      most = std::max(most, v);
    }
    a.type = !whole || most > 65535 ? ValueType::f64 : eight_bit ? ValueType::u8 : ValueType::u16;
  }
}

// Open3D's text formats name their columns by the extension alone.
std::optional<std::vector<std::string>> names_of_extension(const std::string& path) {
  std::string ext = std::filesystem::path(path).extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  if (ext == ".xyzn") return std::vector<std::string>{"x", "y", "z", "nx", "ny", "nz"};
  if (ext == ".xyzrgb") return std::vector<std::string>{"x", "y", "z", "red", "green", "blue"};
  return std::nullopt;
}

// The names of the header line, if there is one.
std::optional<TextHeader> read_header_line(const std::string& path, int skip_lines) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw IoError(path + ": cannot open");
  const char line_end = line_end_of(in);
  std::string line;
  std::uint64_t number = 0, next_offset = 0;
  std::vector<std::string> names;
  // Leading comment lines may carry the names (CloudCompare, vola export); the first
  // other line ends the search, and is a header itself when it holds names only.
  while (std::getline(in, line, line_end)) {
    std::uint64_t offset = next_offset;
    next_offset += line.size() + 1;
    if (++number <= static_cast<std::uint64_t>(skip_lines)) continue;
    std::string_view rest(line);
    const std::size_t mark = byte_order_mark(rest, number);
    rest.remove_prefix(mark);
    offset += mark;
    if (std::all_of(rest.begin(), rest.end(), [](char c) { return is_separator(c, false); })) continue;  // blank
    while (rest.front() == ' ' || rest.front() == '\t') rest.remove_prefix(1);  // a leading comma is an empty name
    TextHeader header;
    header.line = number;
    header.offset = offset;
    if (rest.substr(0, 2) == "//") header.comment = true, rest.remove_prefix(2);
    else if (rest.front() == '#') header.comment = true, rest.remove_prefix(1);
    names.clear();
    bool all_names = true;
    const bool decimal_comma = uses_decimal_comma(rest);
    if (!header.comment && !decimal_comma && rest.find(',') != std::string_view::npos) {
      // A CSV header: one name between each two commas, an empty one too (pandas writes
      // its unnamed index column first, ",x,y,z", and R `"","x","y","z"`): skipping it
      // as a run of separators put every name one column to the left of its values.
      const std::string_view line_text = rest;
      for (std::size_t i = 0; i <= line_text.size();) {
        std::size_t end = i;
        if (end < line_text.size() && (line_text[end] == '"' || line_text[end] == '\'')) {
          const std::size_t close = line_text.find(line_text[end], end + 1);
          if (close != std::string_view::npos) end = close + 1;
        }
        end = std::min(line_text.find(',', end), line_text.size());
        std::string_view word = line_text.substr(i, end - i);
        while (!word.empty() && is_separator(word.front(), true)) word.remove_prefix(1);
        while (!word.empty() && is_separator(word.back(), true)) word.remove_suffix(1);
        word = unquoted(word);
        all_names = all_names && (word.empty() || !is_number(word, false));
        names.emplace_back(word);
        i = end + 1;
      }
      while (!names.empty() && names.back().empty()) names.pop_back();  // "x,y,z," ends with a separator
      all_names = all_names && std::any_of(names.begin(), names.end(), [](const std::string& n) { return !n.empty(); });
    } else {
      for (std::size_t i = 0; i < rest.size();) {
        while (i < rest.size() && is_separator(rest[i], decimal_comma)) ++i;
        const std::size_t end = field_end(rest, i, decimal_comma);
        if (end > i) {
          const std::string_view word = unquoted(rest.substr(i, end - i));
          all_names = all_names && !word.empty() && !is_number(word, decimal_comma);
          names.emplace_back(word);
        }
        i = end;
      }
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

// Open3D writes .xyzrgb colours in 0..1; other writers of the extension may give 0..255,
// which are kept as they are rather than clamped to white. True when they were scaled.
bool unit_colours_to_bytes(PointCloud& cloud) {
  const auto is_colour = [](const PointAttribute& a) {
    return a.name == "red" || a.name == "green" || a.name == "blue";
  };
  for (const PointAttribute& a : cloud.attributes)
    if (is_colour(a) && std::any_of(a.values.begin(), a.values.end(), [](double v) { return !(v >= 0 && v <= 1); }))
      return false;
  for (PointAttribute& a : cloud.attributes)
    if (is_colour(a))
      for (double& v : a.values) v = colour_attribute(v, ColourScale::unit);
  return true;
}

}  // namespace

namespace {

// A Leica PTS file's columns by their count, as PDAL's readers.pts lays them out:
// x y z, x y z intensity, or x y z intensity red green blue.
std::optional<std::vector<std::string>> pts_names(const std::string& path, int skip_lines) {
  if (!has_count_lines(path)) return std::nullopt;
  const int columns = count_text_columns(path, skip_lines);
  if (columns == 4) return std::vector<std::string>{"x", "y", "z", "intensity"};
  if (columns == 7) return std::vector<std::string>{"x", "y", "z", "intensity", "red", "green", "blue"};
  return std::nullopt;
}

}  // namespace

std::optional<TextHeader> read_text_header(const std::string& path, int skip_lines) {
  if (auto header = read_header_line(path, skip_lines)) return header;
  if (auto names = names_of_extension(path)) return TextHeader{std::move(*names), 0, 0, true};
  if (auto names = pts_names(path, skip_lines)) return TextHeader{std::move(*names), 0, 0, true};
  return std::nullopt;
}

std::optional<std::array<int, 3>> named_xyz_columns(const TextHeader& header) { return xyz_columns(header.names); }

TextColumns text_columns_of(const TextHeader& header) {
  const auto xyz = xyz_columns(header.names);
  if (!xyz) throw InvalidArgument("the header names no x, y and z columns");
  return text_columns_of(header, (*xyz)[0], (*xyz)[1], (*xyz)[2]);
}

TextColumns text_columns_of(const TextHeader& header, int x, int y, int z) {
  TextColumns columns;
  columns.x = x, columns.y = y, columns.z = z;
  const auto named = xyz_columns(header.names);  // columns the header calls x, y, z: never attributes
  std::unordered_set<std::string> taken;  // a header of 80,000 names took seconds with a search per name
  for (std::size_t c = 0; c < header.names.size(); ++c) {
    const int column = static_cast<int>(c);
    if (column == columns.x || column == columns.y || column == columns.z) continue;
    if (named && (column == (*named)[0] || column == (*named)[1] || column == (*named)[2])) continue;
    std::string name = point_column_name(header.names[c]);
    if (name.empty() || !taken.insert(name).second) continue;  // a second column of one name stays unread, as in PLY
    const Reduction reduction = point_column_reduction(name, header.names[c]);
    columns.attributes.push_back({std::move(name), ValueType::f64, reduction, {}});
    columns.attribute_columns.push_back(column);
  }
  return columns;
}

int count_text_columns(const std::string& path, int skip_lines) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw IoError(path + ": cannot open");
  const char line_end = line_end_of(in);
  const bool count_lines = has_count_lines(path);
  std::string line;
  int line_number = 0;
  while (std::getline(in, line, line_end)) {
    if (++line_number <= skip_lines) continue;
    if (line_number == 1) line.erase(0, byte_order_mark(line, 1));
    if (!is_data_line(line) || (count_lines && is_count_line(line))) continue;
    const bool decimal_comma = uses_decimal_comma(line);
    std::size_t i = 0;
    while (i < line.size() && is_separator(line[i], decimal_comma)) ++i;
    int columns = 0;
    while (i < line.size()) {
      ++columns;
      i = field_end(line, i, decimal_comma);  // a header's quoted names count once
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
  // Another format's file read as text (a WAV renamed .xyz, a LAS with --format text) is
  // said as what it is, not as a line of names without x, y and z or a column of bytes.
  if (const auto kind = content_kind_of_file(path))
    throw FormatError(path, 0, "not a text point file: its first bytes are those of " + *kind);
  in.seekg(0, std::ios::end);
  const std::uint64_t total = static_cast<std::uint64_t>(in.tellg());
  in.seekg(0);
  const char line_end = line_end_of(in);
  // A header line is never a point; it lays the columns out when they are left to it.
  const std::optional<TextHeader> header = read_text_header(path, columns.skip_lines);
  TextColumns layout = columns;
  const bool named = header && columns.from_header;
  if (named) {
    if (!columns.xyz_given && !xyz_columns(header->names)) {
      throw FormatError(path, header->offset, "line " + std::to_string(header->line) + " names its columns but none of them x, y and z;"
                                 " say which columns hold them (--columns X Y Z, counted from 1)");
    }
    layout = columns.xyz_given ? text_columns_of(*header, columns.x, columns.y, columns.z) : text_columns_of(*header);
    layout.skip_lines = columns.skip_lines;
    if (!columns.named_attributes) layout.attributes.clear(), layout.attribute_columns.clear();
  }
  PointCloud cloud;
  const bool names_line = header && !header->comment;  // a line of names to pass over
  LineParser parser(path, layout, cloud, names_line ? header->line : 0, names_line ? header->names.size() : 0,
                    has_count_lines(path));
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
      std::size_t newline = buffer.find(line_end, start);
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
  const bool unit_colours =
      named && !header->line && lower_extension(path) == ".xyzrgb" && unit_colours_to_bytes(cloud);
  if (named) type_colours(cloud, unit_colours);
  return cloud;
}

}  // namespace vola::io
