#include "vola/io/ply.hpp"

#include <algorithm>
#include <cctype>
#include <charconv>
#include <cmath>
#include <cstring>
#include <limits>
#include <optional>
#include <string_view>
#include <unordered_set>
#include <vector>

#include "column_names.hpp"
#include "file_bytes.hpp"
#include "header_words.hpp"
#include "point_colours.hpp"
#include "polygon_triangles.hpp"
#include "vola/error.hpp"
#include "vola/io/mesh.hpp"
#include "vola/little_endian.hpp"

namespace vola::io {

namespace {

enum class PlyType : std::uint8_t { i8, u8, i16, u16, i32, u32, f32, f64 };

std::optional<PlyType> parse_type(std::string_view s) {
  struct Name {
    std::string_view classic, sized;
    PlyType type;
  };
  static constexpr Name names[] = {{"char", "int8", PlyType::i8},     {"uchar", "uint8", PlyType::u8},
                                   {"short", "int16", PlyType::i16},  {"ushort", "uint16", PlyType::u16},
                                   {"int", "int32", PlyType::i32},    {"uint", "uint32", PlyType::u32},
                                   {"float", "float32", PlyType::f32}, {"double", "float64", PlyType::f64}};
  for (const auto& n : names)
    if (s == n.classic || s == n.sized) return n.type;
  // Not a PLY type, but pyntcloud writes numpy's one-byte bools so (read_ply's allow_bool).
  if (s == "bool") return PlyType::u8;
  return std::nullopt;
}

int byte_size(PlyType t) {
  static constexpr int sizes[] = {1, 1, 2, 2, 4, 4, 4, 8};
  return sizes[static_cast<int>(t)];
}

char kind_of(PlyType t) {
  switch (t) {
    case PlyType::f32:
    case PlyType::f64: return 'f';
    case PlyType::i8:
    case PlyType::i16:
    case PlyType::i32: return 'i';
    default: return 'u';
  }
}

struct Property {
  std::string name;
  PlyType type = PlyType::f32;  // a list's item type
  bool list = false;
  PlyType count_type = PlyType::u8;
};

struct Element {
  std::string name;
  std::uint64_t count = 0;
  std::vector<Property> properties;
};

enum class Encoding { ascii, binary_little_endian, binary_big_endian };

struct PlyHeader {
  Encoding encoding = Encoding::ascii;
  std::vector<Element> elements;
  std::size_t body = 0;        // byte offset of the first element's data
  std::uint64_t body_line = 1;  // line number of that offset (ascii)
};

PlyHeader parse_ply_header(std::span<const std::uint8_t> bytes, const std::string& name) {
  const std::string_view text(reinterpret_cast<const char*>(bytes.data()), bytes.size());
  PlyHeader h;
  std::size_t at = 0;
  std::uint64_t line_number = 0;
  bool have_format = false;
  for (;;) {
    const std::size_t end = text.find('\n', at);
    ++line_number;
    auto fail = [&](const std::string& cause) -> void {
      throw FormatError(name, at, "header line " + std::to_string(line_number) + ": " + cause);
    };
    if (end == std::string_view::npos) fail("the header ends without end_header (truncated or not a PLY file)");
    const auto words = split_words(text.substr(at, end - at));
    if (line_number == 1) {
      if (words.size() != 1 || words[0] != "ply") fail("not a PLY file (the first line is not 'ply')");
    } else if (words.empty() || words[0] == "comment" || words[0] == "obj_info") {
      // free text
    } else if (words[0] == "format") {
      if (words.size() != 3) fail("expected 'format ENCODING 1.0'");
      if (words[1] == "ascii") h.encoding = Encoding::ascii;
      else if (words[1] == "binary_little_endian") h.encoding = Encoding::binary_little_endian;
      else if (words[1] == "binary_big_endian") h.encoding = Encoding::binary_big_endian;
      else fail("unknown encoding '" + std::string(words[1]) + "' (ascii, binary_little_endian, binary_big_endian)");
      if (words[2] != "1.0" && words[2] != "1") fail("PLY version " + std::string(words[2]) + " is not known (1.0)");
      have_format = true;
    } else if (words[0] == "element") {
      if (words.size() != 3) fail("expected 'element NAME COUNT'");
      Element e;
      e.name = words[1];
      const auto r = std::from_chars(words[2].data(), words[2].data() + words[2].size(), e.count);
      if (r.ec != std::errc() || r.ptr != words[2].data() + words[2].size())
        fail("element count '" + std::string(words[2]) + "' is not a non-negative integer");
      h.elements.push_back(std::move(e));
    } else if (words[0] == "property") {
      if (h.elements.empty()) fail("a property before any element");
      Property p;
      if (words.size() == 5 && words[1] == "list") {
        const auto count_type = parse_type(words[2]);
        const auto item_type = parse_type(words[3]);
        if (!count_type || !item_type) fail("unknown type in '" + std::string(text.substr(at, end - at)) + "'");
        if (kind_of(*count_type) == 'f') fail("a list count must have an integer type");
        p.list = true;
        p.count_type = *count_type;
        p.type = *item_type;
        p.name = words[4];
      } else if (words.size() == 3 && words[1] != "list") {
        const auto type = parse_type(words[1]);
        if (!type) fail("unknown property type '" + std::string(words[1]) + "'");
        p.type = *type;
        p.name = words[2];
      } else {
        fail("expected 'property TYPE NAME' or 'property list COUNT_TYPE ITEM_TYPE NAME'");
      }
      h.elements.back().properties.push_back(std::move(p));
    } else if (words[0] == "end_header") {
      if (!have_format) fail("end_header before any format line");
      h.body = end + 1;
      h.body_line = line_number + 1;
      return h;
    } else {
      fail("unknown header keyword '" + std::string(words[0]) + "'");
    }
    at = end + 1;
  }
}

// What a property means to vola.
enum class Role : std::uint8_t { x, y, z, red, green, blue, indices, strip, skip, attribute };

ValueType value_type_of(PlyType t) {
  switch (t) {
    case PlyType::i8: return ValueType::i8;
    case PlyType::u8: return ValueType::u8;
    case PlyType::i16: return ValueType::i16;
    case PlyType::u16: return ValueType::u16;
    case PlyType::i32: return ValueType::i32;
    case PlyType::u32: return ValueType::u32;
    case PlyType::f32: return ValueType::f32;
    case PlyType::f64: return ValueType::f64;
  }
  return ValueType::f64;
}

// The vertex's other scalar properties (intensity, normals, scalar fields, labels...)
// as attribute columns: role `attribute`, column[p] their place in cloud.attributes.
// Class-like names and identifiers (point_column_reduction) take the majority of a
// voxel's points, the others the mean.
std::vector<std::size_t> attribute_columns(const std::vector<Property>& properties, std::vector<Role>& roles,
                                           PointCloud& cloud) {
  std::vector<std::size_t> column(properties.size(), 0);
  std::unordered_set<std::string> taken;  // 80,000 properties took seconds with a search per name
  for (const PointAttribute& a : cloud.attributes) taken.insert(a.name);
  for (std::size_t p = 0; p < properties.size(); ++p) {
    if (properties[p].list || roles[p] != Role::skip) continue;
    const std::string name = utf8_name(properties[p].name);
    if (!taken.insert(name).second) continue;  // a second property of one name stays unread
    std::string lower = name;
    for (char& c : lower) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
    const bool label = point_column_reduction(lower, name) == Reduction::majority;
    roles[p] = Role::attribute;
    column[p] = cloud.attributes.size();
    cloud.attributes.push_back({name, value_type_of(properties[p].type), label ? Reduction::majority : Reduction::mean, {}});
  }
  return column;
}

// Binary element data of either byte order; every read is checked against the end.
class BinaryInput {
 public:
  BinaryInput(std::span<const std::uint8_t> bytes, std::size_t at, bool big_endian, const std::string& name)
      : bytes_(bytes), at_(at), big_endian_(big_endian), name_(name) {}

  double read(PlyType t) {
    const auto n = static_cast<std::size_t>(byte_size(t));
    if (n > bytes_.size() - at_) fail("the data ends in the middle of an element (truncated file)");
    std::uint8_t raw[8];
    for (std::size_t i = 0; i < n; ++i) raw[i] = bytes_[at_ + (big_endian_ ? n - 1 - i : i)];
    at_ += n;
    switch (t) {
      case PlyType::i8: return load_le<std::int8_t>(raw);
      case PlyType::u8: return load_le<std::uint8_t>(raw);
      case PlyType::i16: return load_le<std::int16_t>(raw);
      case PlyType::u16: return load_le<std::uint16_t>(raw);
      case PlyType::i32: return load_le<std::int32_t>(raw);
      case PlyType::u32: return load_le<std::uint32_t>(raw);
      case PlyType::f32: return load_le<float>(raw);
      case PlyType::f64: return load_le<double>(raw);
    }
    return 0.0;
  }
  void skip(PlyType t, std::uint64_t count) {
    const auto n = static_cast<std::uint64_t>(byte_size(t));
    if (count > (bytes_.size() - at_) / n) fail("a list of " + std::to_string(count) + " values runs past the end of the file");
    at_ += static_cast<std::size_t>(count * n);
  }
  // Can `count` values of `t` still follow?
  void expect(PlyType t, std::uint64_t count) {
    if (count > (bytes_.size() - at_) / static_cast<std::uint64_t>(byte_size(t)))
      fail("a list of " + std::to_string(count) + " values runs past the end of the file");
  }
  void end_record(const Element&) {}  // records have no separators
  // Bytes after the last element (a file of more vertices than its header declares gave
  // the declared number); a line end or spaces some writers add are no data.
  void end_data() {
    for (std::size_t i = at_; i < bytes_.size(); ++i)
      if (bytes_[i] != '\n' && bytes_[i] != '\r' && bytes_[i] != ' ') {
        at_ = i;
        fail(std::to_string(bytes_.size() - i) + " bytes after the last element the header declares");
      }
  }
  [[noreturn]] void fail(const std::string& cause) const { throw FormatError(name_, at_, cause); }

 private:
  std::span<const std::uint8_t> bytes_;
  std::size_t at_;
  bool big_endian_;
  const std::string& name_;
};

// Whitespace-separated ascii values; lines only matter for error messages.
class AsciiInput {
 public:
  AsciiInput(std::span<const std::uint8_t> bytes, std::size_t at, std::uint64_t line, const std::string& name)
      : text_(reinterpret_cast<const char*>(bytes.data()), bytes.size()), at_(at), line_(line), name_(name) {}

  // A value as its declared type holds it: the text of a float property is rounded to
  // float, as the binary encodings would store it.
  double read(PlyType t) {
    const std::string_view token = next();
    const char* first = token.data();
    const char* last = token.data() + token.size();
    if (first != last && *first == '+') ++first;
    double v = 0.0;
    const auto r = std::from_chars(first, last, v);
    if (r.ec != std::errc() || r.ptr != last) fail("'" + std::string(token) + "' is not a number");
    return t == PlyType::f32 ? static_cast<double>(static_cast<float>(v)) : v;
  }
  void skip(PlyType, std::uint64_t count) {
    for (std::uint64_t i = 0; i < count; ++i) next();
  }
  void expect(PlyType, std::uint64_t) {}  // values are read one by one
  // One element a line. Values left on the line after the element's properties are not
  // described by the header and are skipped, so that they cannot shift the next element
  // ("x y z 99" under three properties). MeshLab (VCGlib) writes such lines: trimesh's
  // fuze_ascii.ply has an undeclared list after each face's colour; MeshLab, Assimp and
  // trimesh read them the same way. But as many values as a whole further element of
  // fixed size may be one: several elements on a line are an error, not skipped.
  void end_record(const Element& element) {
    bool fixed_size = true;
    for (const auto& p : element.properties) fixed_size = fixed_size && !p.list;
    std::size_t extra = 0;
    const std::size_t extra_at = at_;
    while (at_ < text_.size() && text_[at_] != '\n') {
      while (at_ < text_.size() && text_[at_] != '\n' && is_header_space(text_[at_])) ++at_;
      if (at_ == text_.size() || text_[at_] == '\n') break;
      ++extra;
      while (at_ < text_.size() && !is_header_space(text_[at_])) ++at_;
    }
    if (fixed_size && extra >= element.properties.size()) {
      token_start_ = extra_at;
      token_line_ = line_;
      fail(std::to_string(extra) + " values after the " + std::to_string(element.properties.size()) +
           " properties of a " + element.name + ": several elements on one line?");
    }
    in_record_ = false;
  }
  // Nothing but white space may follow the last element (a file of more vertices than its
  // header declares gave the declared number, the rest unread).
  void end_data() {
    while (at_ < text_.size() && is_header_space(text_[at_])) {
      if (text_[at_] == '\n') ++line_;
      ++at_;
    }
    if (at_ < text_.size()) {
      token_start_ = at_;
      token_line_ = line_;
      fail("values after the last element the header declares");
    }
  }
  [[noreturn]] void fail(const std::string& cause) const {
    throw FormatError(name_, token_start_, "line " + std::to_string(token_line_) + ": " + cause);
  }

 private:
  std::string_view next() {
    while (at_ < text_.size() && is_header_space(text_[at_])) {
      if (text_[at_] == '\n') {
        // One element a line: a value of this element on the next line would shift every
        // element after it.
        if (in_record_) {
          token_start_ = at_;
          token_line_ = line_;
          fail("the line ends before the element's last property (fewer values than the header declares)");
        }
        ++line_;
      }
      ++at_;
    }
    token_start_ = at_;
    token_line_ = line_;
    if (at_ == text_.size()) fail("the data ends before every element was read (truncated file)");
    while (at_ < text_.size() && !is_header_space(text_[at_])) ++at_;
    in_record_ = true;
    return text_.substr(token_start_, at_ - token_start_);
  }
  std::string_view text_;
  std::size_t at_;
  std::uint64_t line_;
  std::size_t token_start_ = 0;
  std::uint64_t token_line_ = 0;
  bool in_record_ = false;  // a value of the current element was read from this line
  const std::string& name_;
};

// A list length or a vertex index: a non-negative integer.
template <class In>
std::uint64_t whole_number(In& in, double v, const char* what) {
  if (!(v >= 0.0) || v != std::floor(v) || v > 4294967295.0)
    in.fail(std::string(what) + " " + std::to_string(v) + " is not an integer 0..4294967295");
  return static_cast<std::uint64_t>(v);
}

struct Mesh {
  std::vector<std::uint32_t> corners;  // the vertex indices of every polygon, one after another
  std::vector<std::uint32_t> sizes;    // the corners of each polygon (3 or more)
};

// A triangle strip: each index after the first two makes a triangle with the two before
// it, every second one with its first two corners swapped so that all face the same way;
// -1 restarts the strip. Triangles with a repeated corner (strips use them to turn) are
// no surface and are left out.
template <class In>
void read_strip(In& in, PlyType type, std::uint64_t n, std::uint64_t vertices, Mesh& mesh) {
  in.expect(type, n);
  std::uint32_t run[3] = {0, 0, 0};
  std::size_t length = 0;  // indices of the current strip so far
  for (std::uint64_t k = 0; k < n; ++k) {
    const double v = in.read(type);
    if (v == -1) {
      length = 0;
      continue;
    }
    if (!(v >= 0) || v != std::floor(v) || v >= static_cast<double>(vertices))
      in.fail("strip index " + std::to_string(v) + " is neither -1 nor the index of one of the " +
              std::to_string(vertices) + " vertices");
    run[0] = run[1];
    run[1] = run[2];
    run[2] = static_cast<std::uint32_t>(v);
    if (++length < 3) continue;
    if (run[0] == run[1] || run[1] == run[2] || run[0] == run[2]) continue;
    if ((length - 3) % 2 == 0)
      mesh.corners.insert(mesh.corners.end(), {run[0], run[1], run[2]});
    else
      mesh.corners.insert(mesh.corners.end(), {run[1], run[0], run[2]});
    mesh.sizes.push_back(3);
  }
}

template <class In>
void read_body(In& in, const PlyHeader& h, const InputOptions& options, Input& out, Mesh& mesh,
               std::size_t remaining_bytes) {
  const Element* vertex = nullptr;
  const Element* face = nullptr;
  const Element* strips = nullptr;  // triangle strips ("tristrips", as in tinyply's test models)
  for (const auto& e : h.elements) {
    if (e.name == "vertex" && !vertex) vertex = &e;
    if (e.name == "face" && !face) face = &e;
    if (e.name == "tristrips" && !strips) strips = &e;
  }
  for (const auto& e : h.elements) {
    // An element without properties has no bytes: nothing to read, however large its count.
    if (e.properties.empty()) continue;
    std::vector<Role> roles(e.properties.size(), Role::skip);
    std::vector<std::size_t> column;  // Role::attribute: the property's column
    std::optional<ColourColumns> colours;
    if (&e == vertex) {
      std::optional<ColourScale> scale[3];
      for (std::size_t p = 0; p < e.properties.size(); ++p) {
        const Property& prop = e.properties[p];
        if (prop.list) continue;
        static constexpr std::string_view names[] = {"x", "y", "z", "red", "green", "blue"};
        static constexpr std::string_view diffuse[] = {"", "", "", "diffuse_red", "diffuse_green", "diffuse_blue"};
        for (std::size_t r = 0; r < 6; ++r)
          if (prop.name == names[r] || prop.name == diffuse[r]) {
            roles[p] = static_cast<Role>(r);
            if (r >= 3) scale[r - 3] = colour_scale(kind_of(prop.type), byte_size(prop.type));
          }
      }
      const bool coloured = scale[0] && scale[0] == scale[1] && scale[0] == scale[2];
      if (!coloured)
        for (auto& r : roles)
          if (r == Role::red || r == Role::green || r == Role::blue) r = Role::skip;
      // A bound the file justifies: every vertex takes at least one byte per property.
      const std::uint64_t reservable = std::min<std::uint64_t>(e.count, remaining_bytes / e.properties.size());
      out.cloud.xyz.reserve(3 * static_cast<std::size_t>(reservable));
      if (coloured && (options.attributes || options.payload)) {
        colours.emplace(out.cloud, *scale[0], options.attributes, options.payload);
        colours->reserve(static_cast<std::size_t>(reservable));
      }
      if (options.attributes) column = attribute_columns(e.properties, roles, out.cloud);
    } else if (&e == face || &e == strips) {
      for (std::size_t p = 0; p < e.properties.size(); ++p)
        if (e.properties[p].list && (e.properties[p].name == "vertex_indices" || e.properties[p].name == "vertex_index")) {
          roles[p] = &e == face ? Role::indices : Role::strip;
          break;
        }
    }

    std::vector<std::uint32_t> polygon;
    for (std::uint64_t i = 0; i < e.count; ++i) {
      double v[6] = {0, 0, 0, 0, 0, 0};
      for (std::size_t p = 0; p < e.properties.size(); ++p) {
        const Property& prop = e.properties[p];
        const Role role = roles[p];
        if (!prop.list) {
          if (role == Role::skip) in.skip(prop.type, 1);
          else if (role == Role::attribute) out.cloud.attributes[column[p]].values.push_back(in.read(prop.type));
          else v[static_cast<int>(role)] = in.read(prop.type);
          continue;
        }
        const std::uint64_t n = whole_number(in, in.read(prop.count_type), "list length");
        if (role == Role::strip) {
          read_strip(in, prop.type, n, vertex->count, mesh);
          continue;
        }
        if (role != Role::indices) {
          in.skip(prop.type, n);
          continue;
        }
        in.expect(prop.type, n);
        polygon.clear();
        for (std::uint64_t k = 0; k < n; ++k) {
          const std::uint64_t index = whole_number(in, in.read(prop.type), "vertex index");
          if (index >= vertex->count)
            in.fail("face " + std::to_string(i) + " refers to vertex " + std::to_string(index) + " of " +
                    std::to_string(vertex->count));
          polygon.push_back(static_cast<std::uint32_t>(index));
        }
        // Polygons are cut into triangles once every vertex is read (a face element may
        // come first); fewer than 3 corners make no triangle.
        if (polygon.size() >= 3) {
          mesh.corners.insert(mesh.corners.end(), polygon.begin(), polygon.end());
          mesh.sizes.push_back(static_cast<std::uint32_t>(polygon.size()));
        }
      }
      if (&e == vertex) {
        out.cloud.xyz.insert(out.cloud.xyz.end(), {v[0], v[1], v[2]});
        if (colours) colours->add(v[3], v[4], v[5]);
      }
      in.end_record(e);
    }
    if (colours) colours->finish();  // float channels: 0..1, or 0..255 when any is above 1
  }
  in.end_data();
}

}  // namespace

Input parse_ply(std::span<const std::uint8_t> bytes, const std::string& name, const InputOptions& options) {
  const PlyHeader h = parse_ply_header(bytes, name);
  const Element* vertex = nullptr;
  for (const auto& e : h.elements)
    if (e.name == "vertex") {
      vertex = &e;
      break;
    }
  if (!vertex) throw FormatError(name, h.body, "the PLY header declares no vertex element");
  for (const char* axis : {"x", "y", "z"}) {
    const bool found = std::any_of(vertex->properties.begin(), vertex->properties.end(),
                                   [&](const Property& p) { return !p.list && p.name == axis; });
    if (!found) throw FormatError(name, h.body, std::string("the vertex element has no scalar property ") + axis);
  }
  const std::size_t remaining = bytes.size() - h.body;
  if (h.encoding != Encoding::ascii) {
    // Every element's fixed part must fit before anything is allocated.
    std::uint64_t needed = 0;
    for (const auto& e : h.elements) {
      std::uint64_t fixed = 0;
      for (const auto& p : e.properties) fixed += static_cast<std::uint64_t>(byte_size(p.list ? p.count_type : p.type));
      if (fixed && e.count > (remaining - std::min<std::uint64_t>(needed, remaining)) / fixed)
        throw FormatError(name, bytes.size(), "element '" + e.name + "' of " + std::to_string(e.count) +
                                                  " entries needs more bytes than the file has (truncated file)");
      needed += fixed * e.count;
    }
  }
  Input out;
  out.format = "ply";
  Mesh mesh;
  if (h.encoding == Encoding::ascii) {
    AsciiInput in(bytes, h.body, h.body_line, name);
    read_body(in, h, options, out, mesh, remaining);
  } else {
    BinaryInput in(bytes, h.body, h.encoding == Encoding::binary_big_endian, name);
    read_body(in, h, options, out, mesh, remaining);
  }
  // Polygons of n corners make n - 2 triangles of 72 bytes: one face of 40 M one-byte
  // indices asked for 2.9 GB. The same bound as every other mesh reader, before any is made.
  const std::uint64_t triangles = mesh.corners.size() - 2 * mesh.sizes.size();
  if (triangles > kMaxMeshTriangles)
    throw FormatError(
        name, h.body,
        "the faces make " + std::to_string(triangles) + " triangles, more than " + std::to_string(kMaxMeshTriangles));
  const auto& xyz = out.cloud.xyz;
  out.triangles.reserve(static_cast<std::size_t>(triangles));
  std::vector<Point> polygon;
  std::vector<std::array<std::uint32_t, 3>> cut;
  std::size_t at = 0;
  for (const std::uint32_t n : mesh.sizes) {
    polygon.clear();
    for (std::size_t k = 0; k < n; ++k) {
      const std::size_t v = mesh.corners[at + k];
      polygon.push_back({xyz[3 * v], xyz[3 * v + 1], xyz[3 * v + 2]});
    }
    at += n;
    cut.clear();
    triangulate_polygon(polygon, cut);  // concave polygons by their ears (polygon_triangles.hpp)
    for (const auto& t : cut) out.triangles.push_back({polygon[t[0]], polygon[t[1]], polygon[t[2]]});
  }
  if (options.progress) options.progress(bytes.size(), bytes.size());
  return out;
}

Input read_ply(const std::string& path, const InputOptions& options) {
  return parse_ply(read_file_bytes(path), path, options);
}

}  // namespace vola::io
