// OFF meshes (mesh_files.hpp), read line by line.
#include <algorithm>
#include <charconv>
#include <cmath>
#include <string_view>

#include "mesh_files.hpp"
#include "polygon_triangles.hpp"
#include "vola/error.hpp"
#include "vola/io/mesh.hpp"

namespace vola::io {

namespace {

// The file's lines, comments removed, with their numbers and byte offsets.
class OffLines {
 public:
  OffLines(std::string_view text, std::size_t start) : text_(text), at_(start) {}

  // The next line with anything but blanks and a comment on it; false at the end.
  bool next(std::string_view& line) {
    while (at_ < text_.size()) {
      const std::size_t end = std::min(text_.find('\n', at_), text_.size());
      line_at_ = at_;
      ++number_;
      line = text_.substr(at_, end - at_);
      at_ = end + 1;
      if (const std::size_t hash = line.find('#'); hash != std::string_view::npos) line = line.substr(0, hash);
      const std::size_t first = line.find_first_not_of(" \t\r\f\v");
      if (first == std::string_view::npos) continue;
      line = line.substr(first);
      return true;
    }
    return false;
  }
  std::uint64_t number() const noexcept { return number_; }
  std::uint64_t offset() const noexcept { return line_at_; }

 private:
  std::string_view text_;
  std::size_t at_ = 0, line_at_ = 0;
  std::uint64_t number_ = 0;
};

// The whitespace-separated words of a line.
class OffWords {
 public:
  explicit OffWords(std::string_view line) : line_(line) {}
  bool next(std::string_view& word) {
    const std::size_t first = line_.find_first_not_of(" \t\r\f\v");
    if (first == std::string_view::npos) return false;
    const std::size_t end = std::min(line_.find_first_of(" \t\r\f\v", first), line_.size());
    word = line_.substr(first, end - first);
    line_ = line_.substr(end);
    return true;
  }

 private:
  std::string_view line_;
};

bool off_number(std::string_view word, double& out) {
  const char* end = word.data() + word.size();
  const auto [ptr, ec] = std::from_chars(word.data(), end, out);
  return ec == std::errc() && ptr == end;
}
// A whole number; one too large for 64 bits reads as the largest (a count no file holds).
bool off_count(std::string_view word, std::uint64_t& out) {
  const char* end = word.data() + word.size();
  const auto [ptr, ec] = std::from_chars(word.data(), end, out);
  if (ec == std::errc::result_out_of_range && ptr == end) out = ~std::uint64_t{0};
  return (ec == std::errc() || ec == std::errc::result_out_of_range) && ptr == end;
}

struct OffHeader {
  bool homogeneous = false;  // 4OFF: x y z w
  std::uint64_t dimension = 3;
  std::uint64_t vertices = 0, faces = 0;
};

}  // namespace

std::vector<Triangle> parse_off(std::span<const std::uint8_t> bytes, const std::string& name) {
  const std::string_view text(reinterpret_cast<const char*>(bytes.data()), bytes.size());
  if (text.starts_with("\xff\xfe") || text.starts_with("\xfe\xff"))
    throw FormatError(name, 0, "an OFF file in UTF-16 (OFF is ASCII text)");
  OffLines lines(text, text.starts_with("\xef\xbb\xbf") ? 3 : 0);
  const auto fail = [&](const std::string& what) {
    throw FormatError(name, lines.offset(), "line " + std::to_string(lines.number()) + ": " + what);
  };

  // The keyword, then the counts (on its line or the lines after).
  OffHeader h;
  std::vector<std::uint64_t> counts;
  const std::size_t wanted_counts = 3;  // vertices, faces, edges (the dimension first in nOFF)
  std::string_view line;
  if (!lines.next(line)) throw FormatError(name, 0, "an empty OFF file");
  {
    std::size_t k = 0;
    if (line.substr(k).starts_with("ST")) k += 2;
    if (line.substr(k).starts_with("C")) k += 1;
    if (line.substr(k).starts_with("N")) k += 1;
    if (line.substr(k).starts_with("4")) h.homogeneous = true, k += 1;
    bool has_dimension = line.substr(k).starts_with("n");
    if (has_dimension) k += 1;
    if (line.substr(k).starts_with("OFF")) {
      line = line.substr(k + 3);
    } else {  // no keyword: the line holds the counts ("4" was a digit of one)
      h.homogeneous = has_dimension = false;
    }
    std::string_view word;
    OffWords words(line);
    bool first_word = true;
    while (words.next(word)) {
      if (first_word && (word == "BINARY" || word == "binary"))
        fail("a binary OFF file: vola reads the text form only (convert it with a mesh tool)");
      first_word = false;
      std::uint64_t value = 0;
      if (!off_count(word, value)) fail("'" + std::string(word) + "' is not a count in the OFF header");
      counts.push_back(value);
    }
    const std::size_t needed = wanted_counts + (has_dimension ? 1 : 0);
    while (counts.size() < needed - 1) {  // the edge count may be left out
      if (!lines.next(line)) fail("the OFF header ends before its vertex and face counts");
      OffWords more(line);
      while (more.next(word)) {
        std::uint64_t value = 0;
        if (!off_count(word, value)) fail("'" + std::string(word) + "' is not a count in the OFF header");
        counts.push_back(value);
      }
    }
    if (has_dimension) {
      h.dimension = counts.front();
      counts.erase(counts.begin());
      if (h.dimension != 3) fail("an nOFF file of dimension " + std::to_string(h.dimension) + " (vola reads 3)");
    }
    if (counts.size() > 3) fail("more than three counts in the OFF header");
    h.vertices = counts[0];
    h.faces = counts[1];
  }
  // Each vertex and face takes a line of at least two bytes: counts the file cannot hold
  // are refused before anything is reserved for them.
  if (h.vertices > bytes.size() / 2 || h.faces > bytes.size() / 2)
    fail("the header declares " + std::to_string(h.vertices) + " vertices and " + std::to_string(h.faces) +
         " faces, more than the file's " + std::to_string(bytes.size()) + " bytes can hold");

  std::vector<Point> vertices;
  vertices.reserve(h.vertices);
  const std::size_t coordinates = h.homogeneous ? 4 : 3;
  for (std::uint64_t v = 0; v < h.vertices; ++v) {
    if (!lines.next(line))
      throw FormatError(
          name, bytes.size(),
          "the header declares " + std::to_string(h.vertices) + " vertices, the file ends after " + std::to_string(v));
    OffWords words(line);
    double x[4] = {0.0, 0.0, 0.0, 1.0};
    std::string_view word;
    for (std::size_t k = 0; k < coordinates; ++k) {
      if (!words.next(word))
        fail("vertex " + std::to_string(v) + " has fewer than " + std::to_string(coordinates) + " coordinates");
      if (!off_number(word, x[k]))
        fail("vertex " + std::to_string(v) + ": '" + std::string(word) + "' is not a number");
    }
    if (h.homogeneous) {
      if (x[3] == 0.0) fail("vertex " + std::to_string(v) + " has w = 0 (a point at infinity)");
      for (int k = 0; k < 3; ++k) x[k] /= x[3];
    }
    vertices.push_back({x[0], x[1], x[2]});
  }

  std::vector<Triangle> triangles;
  std::vector<std::uint32_t> corner;
  std::vector<Point> polygon;
  std::vector<std::array<std::uint32_t, 3>> cut;
  for (std::uint64_t f = 0; f < h.faces; ++f) {
    if (!lines.next(line))
      throw FormatError(
          name, bytes.size(),
          "the header declares " + std::to_string(h.faces) + " faces, the file ends after " + std::to_string(f));
    OffWords words(line);
    std::string_view word;
    std::uint64_t n = 0;
    if (!words.next(word) || !off_count(word, n) || n == 0)
      fail("face " + std::to_string(f) + " starts with '" + std::string(word) + "', not a corner count of 1 or more");
    if (n > line.size())
      fail("face " + std::to_string(f) + " declares " + std::to_string(n) + " corners, its line holds fewer");
    corner.clear();
    for (std::uint64_t k = 0; k < n; ++k) {
      std::uint64_t index = 0;
      if (!words.next(word))
        fail("face " + std::to_string(f) + " declares " + std::to_string(n) + " corners and lists " +
             std::to_string(k));
      if (!off_count(word, index))
        fail("face " + std::to_string(f) + ": '" + std::string(word) + "' is not a vertex index");
      if (index >= vertices.size())
        fail("face " + std::to_string(f) + " refers to vertex " + std::to_string(index) + " of " +
             std::to_string(vertices.size()));
      corner.push_back(static_cast<std::uint32_t>(index));
    }
    if (n < 3) {  // a point or a line: a degenerate triangle, as points and lines voxelize
      triangles.push_back({vertices[corner[0]], vertices[corner[n - 1]], vertices[corner[n - 1]]});
      continue;
    }
    polygon.clear();
    for (const std::uint32_t c : corner) polygon.push_back(vertices[c]);
    cut.clear();
    triangulate_polygon(polygon, cut);
    for (const auto& t : cut) triangles.push_back({polygon[t[0]], polygon[t[1]], polygon[t[2]]});
    if (triangles.size() > kMaxMeshTriangles) fail("more than " + std::to_string(kMaxMeshTriangles) + " triangles");
  }
  if (lines.next(line))
    fail("more lines than the header's " + std::to_string(h.vertices) + " vertices and " + std::to_string(h.faces) +
         " faces (a count in the header is wrong)");
  if (triangles.empty()) throw FormatError(name, std::nullopt, "the OFF file holds no faces");
  return triangles;
}

}  // namespace vola::io
