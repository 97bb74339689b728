// STL meshes, binary and ASCII (mesh_files.hpp).
#include <algorithm>
#include <cctype>
#include <charconv>
#include <cstring>
#include <string_view>

#include "content_kind.hpp"
#include "mesh_files.hpp"
#include "polygon_triangles.hpp"
#include "vola/error.hpp"
#include "vola/io/mesh.hpp"
#include "vola/little_endian.hpp"

namespace vola::io {

namespace {

constexpr std::size_t kStlHeader = 84, kStlTriangle = 50;

bool stl_keyword(std::string_view word, std::string_view keyword) {
  return word.size() == keyword.size() && std::equal(word.begin(), word.end(), keyword.begin(), [](char a, char b) {
           return std::tolower(static_cast<unsigned char>(a)) == b;
         });
}

bool stl_begins_with_solid(std::string_view text) {
  const std::size_t first = text.find_first_not_of(" \t\r\n");
  return first != std::string_view::npos && text.size() - first >= 5 && stl_keyword(text.substr(first, 5), "solid");
}

std::vector<Triangle> stl_binary_triangles(std::span<const std::uint8_t> bytes, std::uint64_t count) {
  std::vector<Triangle> triangles(count);
  for (std::uint64_t t = 0; t < count; ++t) {
    const std::uint8_t* at = bytes.data() + kStlHeader + t * kStlTriangle + 12;  // after the normal
    for (int c = 0; c < 3; ++c)
      for (int a = 0; a < 3; ++a) triangles[t][c][a] = load_le<float>(at + 12 * c + 4 * a);
  }
  return triangles;
}

// ASCII STL: words, with their lines for errors.
class StlWords {
 public:
  explicit StlWords(std::string_view text) : text_(text) {}
  bool next(std::string_view& word) {
    while (at_ < text_.size() && std::isspace(static_cast<unsigned char>(text_[at_]))) {
      if (text_[at_] == '\n') ++line_;
      ++at_;
    }
    if (at_ >= text_.size()) return false;
    const std::size_t start = at_;
    while (at_ < text_.size() && !std::isspace(static_cast<unsigned char>(text_[at_]))) ++at_;
    word_at_ = start;
    word_line_ = line_;
    word = text_.substr(start, at_ - start);
    return true;
  }
  void skip_line() {
    while (at_ < text_.size() && text_[at_] != '\n') ++at_;
  }
  std::uint64_t line() const noexcept { return word_line_; }
  std::uint64_t offset() const noexcept { return word_at_; }

 private:
  std::string_view text_;
  std::size_t at_ = 0, word_at_ = 0;
  std::uint64_t line_ = 1, word_line_ = 1;
};

std::vector<Triangle> stl_ascii_triangles(std::span<const std::uint8_t> bytes, const std::string& name) {
  StlWords words(std::string_view(reinterpret_cast<const char*>(bytes.data()), bytes.size()));
  const auto fail = [&](const std::string& what) {
    throw FormatError(name, words.offset(), "line " + std::to_string(words.line()) + ": " + what);
  };
  std::vector<Triangle> triangles;
  std::vector<Point> polygon;
  std::vector<std::array<std::uint32_t, 3>> cut;
  std::string_view word;
  const auto expect = [&](std::string_view keyword, std::uint64_t facet_line) {
    if (!words.next(word))
      throw FormatError(name, bytes.size(),
                        "the facet of line " + std::to_string(facet_line) +
                            " is cut short (the file ends before its '" + std::string(keyword) + "')");
    if (!stl_keyword(word, keyword)) fail("'" + std::string(word) + "' where '" + std::string(keyword) + "' belongs");
  };
  const auto number = [&](std::uint64_t facet_line) {
    if (!words.next(word))
      throw FormatError(name, bytes.size(), "the facet of line " + std::to_string(facet_line) + " is cut short");
    float x = 0.0f;
    const auto [ptr, ec] = std::from_chars(word.data(), word.data() + word.size(), x);
    if (ec != std::errc() || ptr != word.data() + word.size()) fail("'" + std::string(word) + "' is not a number");
    return static_cast<double>(x);
  };
  while (words.next(word)) {
    if (stl_keyword(word, "solid") || stl_keyword(word, "endsolid")) {
      words.skip_line();  // the solid's name
      continue;
    }
    if (!stl_keyword(word, "facet")) fail("'" + std::string(word) + "' where a facet or endsolid belongs");
    const std::uint64_t facet_line = words.line();
    if (!words.next(word))
      throw FormatError(name, bytes.size(), "the facet of line " + std::to_string(facet_line) + " is cut short");
    if (stl_keyword(word, "normal")) {
      for (int a = 0; a < 3; ++a) number(facet_line);
      expect("outer", facet_line);
    } else if (!stl_keyword(word, "outer")) {
      fail("'" + std::string(word) + "' where 'normal' or 'outer' belongs");
    }
    expect("loop", facet_line);
    polygon.clear();
    for (;;) {
      if (!words.next(word))
        throw FormatError(
            name, bytes.size(),
            "the facet of line " + std::to_string(facet_line) + " is cut short (the file ends before its 'endloop')");
      if (stl_keyword(word, "endloop")) break;
      if (!stl_keyword(word, "vertex")) fail("'" + std::string(word) + "' where 'vertex' or 'endloop' belongs");
      Point p;
      for (int a = 0; a < 3; ++a) p[static_cast<std::size_t>(a)] = number(facet_line);
      polygon.push_back(p);
    }
    expect("endfacet", facet_line);
    if (polygon.size() < 3)
      fail("the facet of line " + std::to_string(facet_line) + " has " + std::to_string(polygon.size()) + " vertices");
    cut.clear();
    triangulate_polygon(polygon, cut);
    for (const auto& t : cut) triangles.push_back({polygon[t[0]], polygon[t[1]], polygon[t[2]]});
    if (triangles.size() > kMaxMeshTriangles) fail("more than " + std::to_string(kMaxMeshTriangles) + " triangles");
  }
  return triangles;
}

}  // namespace

std::vector<Triangle> parse_stl(std::span<const std::uint8_t> bytes, const std::string& name) {
  const std::string_view text(reinterpret_cast<const char*>(bytes.data()), bytes.size());
  const std::uint64_t size = bytes.size();
  const std::uint64_t declared = size >= kStlHeader ? load_le<std::uint32_t>(bytes.data() + 80) : 0;
  // A binary STL's header is free text, but not another format's signature: a WAV renamed
  // .stl whose size fit 50-byte triangles read as 2,741 triangles of +-3.4e38.
  if (const auto kind = content_kind(bytes.first(std::min<std::size_t>(bytes.size(), 16))))
    throw FormatError(name, 0, "not an STL mesh: its first bytes are those of " + *kind);
  std::vector<Triangle> triangles;
  if (size >= kStlHeader && size == kStlHeader + kStlTriangle * declared) {
    triangles = stl_binary_triangles(bytes, declared);
  } else if (stl_begins_with_solid(text)) {
    // A binary file whose header begins with "solid" (many writers put the solid's name
    // there) and whose size is not exact reads as no ASCII facet: binary, when its count fits.
    const bool binary_fits = declared != 0 && size >= kStlHeader + kStlTriangle * declared;
    try {
      triangles = stl_ascii_triangles(bytes, name);
    } catch (const FormatError&) {
      if (!binary_fits) throw;
    }
    if (triangles.empty() && binary_fits) triangles = stl_binary_triangles(bytes, declared);
  } else if (size < kStlHeader) {
    throw FormatError(name, size,
                      "a binary STL has an 84-byte header; the file has " + std::to_string(size) + " bytes");
  } else if (declared == 0 && (size - kStlHeader) % kStlTriangle == 0) {
    triangles = stl_binary_triangles(bytes, (size - kStlHeader) / kStlTriangle);  // a writer that left the count 0
  } else if (declared != 0 && size > kStlHeader + kStlTriangle * declared) {
    triangles = stl_binary_triangles(bytes, declared);  // bytes after the triangles: padding
  } else {
    throw FormatError(name, 80,
                      "the binary STL header declares " + std::to_string(declared) + " triangles (" +
                          std::to_string(kStlHeader + kStlTriangle * declared) + " bytes), the file has " +
                          std::to_string(size) + " (truncated?)");
  }
  if (triangles.empty()) throw FormatError(name, std::nullopt, "the STL file holds no triangles");
  return triangles;
}

}  // namespace vola::io
