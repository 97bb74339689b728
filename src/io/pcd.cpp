#include "vola/io/pcd.hpp"

#include <lzf.h>

#include <algorithm>
#include <bit>
#include <cctype>
#include <charconv>
#include <cmath>
#include <cstring>
#include <limits>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <tuple>
#include <utility>
#include <unordered_set>
#include <vector>

#include "column_names.hpp"
#include "content_kind.hpp"
#include "file_bytes.hpp"
#include "header_words.hpp"
#include "point_colours.hpp"
#include "vola/error.hpp"
#include "vola/little_endian.hpp"

namespace vola::io {

namespace {

struct Field {
  std::string name;  // lower case
  char type = 'F';   // F, I or U
  int size = 4;
  std::uint64_t count = 1;
  std::uint64_t offset = 0;     // byte offset inside a point record
  std::uint64_t component = 0;  // index of its first value on an ascii line
  std::string spelled;          // as the file spells it: treeID names an identifier, treeid does not
};

enum class DataKind { ascii, binary, binary_compressed };

struct Header {
  std::vector<Field> fields;
  std::uint64_t points = 0;
  std::uint64_t point_size = 0;  // bytes per point record
  std::uint64_t components = 0;  // values per ascii line
  DataKind data = DataKind::ascii;
  std::size_t body = 0;
  std::uint64_t body_line = 1;
};

std::string lower(std::string_view s) {
  std::string out(s);
  std::transform(out.begin(), out.end(), out.begin(), [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  return out;
}

// What the header's lines say, before it is checked as a whole.
struct HeaderLines {
  std::vector<std::string> fields;   // lower case
  std::vector<std::string> spelled;  // as written
  std::vector<int> sizes;
  std::vector<char> types;
  std::vector<std::uint64_t> counts;
  std::optional<std::uint64_t> width, height, points;
};

// The header lines up to DATA into `lines`; the data kind and where the body starts into h.
HeaderLines read_header_lines(std::string_view text, const std::string& name, Header& h) {
  HeaderLines lines;
  std::vector<std::string_view> words;
  std::size_t at = 0;
  std::uint64_t line_number = 0;
  for (;; at = text.find('\n', at) + 1) {
    const std::size_t end = text.find('\n', at);
    ++line_number;
    auto fail = [&](const std::string& cause) -> void {
      throw FormatError(name, at, "header line " + std::to_string(line_number) + ": " + cause);
    };
    if (end == std::string_view::npos) fail("the header ends without a DATA line (truncated or not a PCD file)");
    split_words(text.substr(at, end - at), words);
    if (words.empty() || words[0].front() == '#') continue;
    const std::string key = lower(words[0]);
    const std::size_t n = words.size() - 1;
    auto numbers = [&](auto& out, const char* what) {
      out.clear();
      for (std::size_t i = 1; i <= n; ++i) {
        typename std::remove_reference_t<decltype(out)>::value_type v{};
        if (!parse_number(words[i], v)) fail(std::string(what) + " '" + std::string(words[i]) + "' is not a number");
        out.push_back(v);
      }
    };
    auto single = [&](std::optional<std::uint64_t>& out) {
      std::uint64_t v = 0;
      if (n != 1 || !parse_number(words[1], v)) fail(std::string(words[0]) + " takes one non-negative integer");
      out = v;
    };
    if (key == "version" || key == "viewpoint") {
      // Nothing to check: the layout lines say everything the data needs.
    } else if (key == "fields" || key == "columns") {
      lines.fields.clear();
      lines.spelled.clear();
      for (std::size_t i = 1; i <= n; ++i) {
        lines.fields.push_back(lower(words[i]));
        lines.spelled.emplace_back(words[i]);
      }
    } else if (key == "size") {
      numbers(lines.sizes, "SIZE");
    } else if (key == "type") {
      lines.types.clear();
      for (std::size_t i = 1; i <= n; ++i) {
        if (words[i].size() != 1) fail("TYPE '" + std::string(words[i]) + "' is not F, I or U");
        lines.types.push_back(static_cast<char>(std::toupper(static_cast<unsigned char>(words[i][0]))));
      }
    } else if (key == "count") {
      numbers(lines.counts, "COUNT");
    } else if (key == "width") {
      single(lines.width);
    } else if (key == "height") {
      single(lines.height);
    } else if (key == "points") {
      single(lines.points);
    } else if (key == "data") {
      if (n != 1) fail("expected 'DATA ascii', 'DATA binary' or 'DATA binary_compressed'");
      const std::string kind = lower(words[1]);
      if (kind == "ascii") h.data = DataKind::ascii;
      else if (kind == "binary") h.data = DataKind::binary;
      else if (kind == "binary_compressed") h.data = DataKind::binary_compressed;
      else fail("DATA '" + std::string(words[1]) + "' is not ascii, binary or binary_compressed");
      h.body = end + 1;
      h.body_line = line_number + 1;
      return lines;
    } else {
      fail("unknown header line '" + std::string(words[0]) + "'");
    }
  }
}

Header parse_header(std::span<const std::uint8_t> bytes, const std::string& name) {
  Header h;
  const HeaderLines lines = read_header_lines(std::string_view(reinterpret_cast<const char*>(bytes.data()), bytes.size()),
                                              name, h);
  auto fail = [&](const std::string& cause) -> void { throw FormatError(name, h.body, "PCD header: " + cause); };
  if (lines.fields.empty()) fail("no FIELDS line");
  const std::size_t fields = lines.fields.size();
  if (lines.sizes.size() != fields || lines.types.size() != fields)
    fail("FIELDS, SIZE and TYPE must name the same number of fields (" + std::to_string(fields) + ", " +
         std::to_string(lines.sizes.size()) + ", " + std::to_string(lines.types.size()) + ")");
  if (!lines.counts.empty() && lines.counts.size() != fields) fail("COUNT does not name every field");
  for (std::size_t f = 0; f < fields; ++f) {
    Field field;
    field.name = lines.fields[f];
    field.type = lines.types[f];
    field.size = lines.sizes[f];
    field.count = lines.counts.empty() ? 1 : lines.counts[f];
    field.spelled = lines.spelled[f];
    const bool valid = (field.type == 'F' && (field.size == 4 || field.size == 8)) ||
                       ((field.type == 'I' || field.type == 'U') &&
                        (field.size == 1 || field.size == 2 || field.size == 4 || field.size == 8));
    if (!valid)
      fail("field '" + field.name + "' has TYPE " + std::string(1, field.type) + " of SIZE " + std::to_string(field.size) +
           " (F 4/8, I or U 1/2/4/8)");
    // A count this large cannot describe a point any file holds; it also keeps the sums below exact.
    if (field.count == 0 || field.count > (std::uint64_t{1} << 32))
      fail("field '" + field.name + "' has COUNT " + std::to_string(field.count));
    field.offset = h.point_size;
    field.component = h.components;
    h.point_size += field.count * static_cast<std::uint64_t>(field.size);
    h.components += field.count;
    h.fields.push_back(std::move(field));
  }
  const auto& [width, height, points] = std::tie(lines.width, lines.height, lines.points);
  std::optional<std::uint64_t> grid_points;  // WIDTH x HEIGHT, when it does not overflow
  if (width && (!height || *height == 0 || *width <= std::numeric_limits<std::uint64_t>::max() / *height))
    grid_points = *width * height.value_or(1);
  if (points && grid_points && *grid_points != *points)
    fail("POINTS " + std::to_string(*points) + " is not WIDTH x HEIGHT (" + std::to_string(*width) + " x " +
         std::to_string(height.value_or(1)) + ")");
  if (!points && !grid_points) fail("neither POINTS nor WIDTH says how many points there are");
  h.points = points ? *points : *grid_points;
  return h;
}

double field_value(const std::uint8_t* p, const Field& f) {
  auto load = [p](auto type) { return static_cast<double>(load_le<decltype(type)>(p)); };
  switch (f.type) {
    case 'F': return f.size == 4 ? load(float{}) : load(double{});
    case 'I':
      switch (f.size) {
        case 1: return load(std::int8_t{});
        case 2: return load(std::int16_t{});
        case 4: return load(std::int32_t{});
        default: return load(std::int64_t{});
      }
    default:
      switch (f.size) {
        case 1: return load(std::uint8_t{});
        case 2: return load(std::uint16_t{});
        case 4: return load(std::uint32_t{});
        default: return load(std::uint64_t{});
      }
  }
}

// Any other scalar field, kept as an attribute column of its own type.
struct OtherField {
  const Field* field;
  std::string name;
  ValueType type;
  Reduction reduction;
  std::uint64_t element = 0;  // of a field with COUNT > 1: which of its values
};

// A field of COUNT > 1 up to this many values (a normal's 3, a colour's 4, a short
// histogram) becomes one column per value, name_0, name_1, ... as LAS arrays do;
// descriptors (FPFH's 33, SHOT's 352) are not read.
constexpr std::uint64_t kMaxFieldElements = 16;

// The fields vola uses, found by (lower-case) name.
struct Layout {
  const Field* xyz[3] = {nullptr, nullptr, nullptr};
  const Field* packed_rgb = nullptr;                   // rgb or rgba: 0x(AA)RRGGBB in 4 bytes
  const Field* channels[3] = {nullptr, nullptr, nullptr};  // red, green, blue fields
  std::optional<ColourScale> channel_scale;
  const Field* intensity = nullptr;
  std::vector<OtherField> others;
};

ValueType field_value_type(const Field& f) {
  switch (f.type) {
    case 'F': return f.size == 4 ? ValueType::f32 : ValueType::f64;
    case 'I': return f.size == 1 ? ValueType::i8 : f.size == 2 ? ValueType::i16 : f.size == 4 ? ValueType::i32 : ValueType::i64;
    default: return f.size == 1 ? ValueType::u8 : f.size == 2 ? ValueType::u16 : f.size == 4 ? ValueType::u32 : ValueType::u64;
  }
}


Layout find_layout(const Header& h, const std::string& name) {
  Layout l;
  auto scalar = [](const Field& f) { return f.count == 1; };
  for (const Field& f : h.fields) {
    for (int a = 0; a < 3; ++a)
      if (f.name == std::string(1, static_cast<char>('x' + a))) {
        if (!scalar(f)) throw FormatError(name, h.body, "PCD field " + f.name + " has COUNT " + std::to_string(f.count) + ", expected 1");
        l.xyz[a] = &f;
      }
    if ((f.name == "rgb" || f.name == "rgba") && scalar(f) && f.size == 4 && !l.packed_rgb) l.packed_rgb = &f;
    static constexpr std::string_view channel_names[] = {"red", "green", "blue"};
    for (int c = 0; c < 3; ++c)
      if (f.name == channel_names[c] && scalar(f)) l.channels[c] = &f;
    if (f.name == "intensity" && scalar(f)) l.intensity = &f;
  }
  for (int a = 0; a < 3; ++a)
    if (!l.xyz[a]) throw FormatError(name, h.body, std::string("PCD header has no field ") + static_cast<char>('x' + a));
  if (l.channels[0] && l.channels[1] && l.channels[2]) {
    const auto kind = [](const Field* f) { return static_cast<char>(std::tolower(static_cast<unsigned char>(f->type))); };
    const auto scale = colour_scale(kind(l.channels[0]), l.channels[0]->size);
    if (scale && scale == colour_scale(kind(l.channels[1]), l.channels[1]->size) &&
        scale == colour_scale(kind(l.channels[2]), l.channels[2]->size))
      l.channel_scale = scale;
  }
  // Every other field (normals, curvature, labels, ring, time, ...), one column per value
  // of a field of COUNT 2..kMaxFieldElements; longer ones (descriptors) and PCL's "_"
  // padding are not read. A second field of a name already taken stays unread, as in PLY.
  std::unordered_set<std::string> taken = {"x", "y", "z"};  // 80,000 fields took seconds with a search per name
  if (l.packed_rgb || l.channel_scale) taken.insert({"red", "green", "blue"});
  if (l.intensity) taken.insert("intensity");
  for (const Field& f : h.fields) {
    const bool used = &f == l.xyz[0] || &f == l.xyz[1] || &f == l.xyz[2] || &f == l.packed_rgb || &f == l.intensity ||
                      (l.channel_scale && (&f == l.channels[0] || &f == l.channels[1] || &f == l.channels[2]));
    if (used || f.count > kMaxFieldElements || f.name.find_first_not_of('_') == std::string::npos) continue;
    const std::string base = point_column_name(f.name);
    for (std::uint64_t element = 0; element < f.count; ++element) {
      std::string column = scalar(f) ? base : base + "_" + std::to_string(element);
      if (!taken.insert(column).second) continue;
      const Reduction reduction = point_column_reduction(column, f.spelled);
      l.others.push_back({&f, std::move(column), field_value_type(f), reduction, element});
    }
  }
  return l;
}

// Appends the finite points with their colours and intensity, and counts the others.
class PointSink {
 public:
  PointSink(const Layout& layout, const InputOptions& options, PointCloud& cloud, std::uint64_t reservable)
      : cloud_(cloud) {
    const auto points = static_cast<std::size_t>(reservable);
    cloud.xyz.reserve(3 * points);
    const bool wanted = options.attributes || options.payload;
    if (wanted && (layout.packed_rgb || layout.channel_scale)) {
      colours_.emplace(cloud, layout.packed_rgb ? ColourScale::bits8 : *layout.channel_scale, options.attributes,
                       options.payload);
      colours_->reserve(points);
    }
    if (options.attributes && layout.intensity) {
      intensity_column_ = cloud.attributes.size();
      cloud.attributes.push_back({"intensity", ValueType::f32, Reduction::mean, {}});
      cloud.attributes.back().values.reserve(points);
    }
    if (options.attributes) {
      first_other_ = cloud.attributes.size();
      others_ = layout.others.size();
      for (const OtherField& o : layout.others) {
        cloud.attributes.push_back({o.name, o.type, o.reduction, {}});
        cloud.attributes.back().values.reserve(points);
      }
    }
  }
  // `others`: the value of each of the layout's other fields.
  void add(const double (&xyz)[3], const double (&rgb)[3], double intensity, std::span<const double> others) {
    if (!std::isfinite(xyz[0]) || !std::isfinite(xyz[1]) || !std::isfinite(xyz[2])) {
      ++not_finite_;
      return;
    }
    cloud_.xyz.insert(cloud_.xyz.end(), {xyz[0], xyz[1], xyz[2]});
    if (colours_) colours_->add(rgb[0], rgb[1], rgb[2]);
    if (intensity_column_) cloud_.attributes[*intensity_column_].values.push_back(intensity);
    for (std::size_t k = 0; k < others_; ++k) cloud_.attributes[first_other_ + k].values.push_back(others[k]);
  }
  std::uint64_t not_finite() const noexcept { return not_finite_; }
  // After the last point: float colour channels become 0..1, or 0..255 when any is above 1.
  void finish() {
    if (colours_) colours_->finish();
  }

 private:
  PointCloud& cloud_;
  std::optional<ColourColumns> colours_;
  std::optional<std::size_t> intensity_column_;
  std::size_t first_other_ = 0, others_ = 0;  // columns of the other fields (none without attributes)
  std::uint64_t not_finite_ = 0;
};

void unpack_rgb(std::uint32_t packed, double (&rgb)[3]) {
  rgb[0] = (packed >> 16) & 0xFFu;
  rgb[1] = (packed >> 8) & 0xFFu;
  rgb[2] = packed & 0xFFu;
}

// Binary records (one point after the other) or binary_compressed columns (one field
// after the other): value j of field f of point i sits at
// base + f.offset * column_scale + i * stride(f) + j * f.size.
void read_records(const std::uint8_t* base, bool columns, const Header& h, const Layout& l, PointSink& sink) {
  const std::uint64_t column_scale = columns ? h.points : 1;
  auto at = [&](const Field& f, std::uint64_t i) {
    const std::uint64_t stride = columns ? f.count * static_cast<std::uint64_t>(f.size) : h.point_size;
    return base + f.offset * column_scale + i * stride;
  };
  std::vector<double> others(l.others.size());
  for (std::uint64_t i = 0; i < h.points; ++i) {
    const double xyz[3] = {field_value(at(*l.xyz[0], i), *l.xyz[0]), field_value(at(*l.xyz[1], i), *l.xyz[1]),
                           field_value(at(*l.xyz[2], i), *l.xyz[2])};
    double rgb[3] = {0, 0, 0};
    if (l.packed_rgb) {
      std::uint32_t packed;
      std::memcpy(&packed, at(*l.packed_rgb, i), 4);
      unpack_rgb(packed, rgb);
    } else if (l.channel_scale) {
      for (int c = 0; c < 3; ++c) rgb[c] = field_value(at(*l.channels[c], i), *l.channels[c]);
    }
    for (std::size_t k = 0; k < l.others.size(); ++k) {
      const OtherField& o = l.others[k];
      others[k] = field_value(at(*o.field, i) + o.element * o.field->size, *o.field);
    }
    sink.add(xyz, rgb, l.intensity ? field_value(at(*l.intensity, i), *l.intensity) : 0.0, others);
  }
}

void read_ascii(std::string_view text, const Header& h, const Layout& l, PointSink& sink, const std::string& name) {
  std::vector<std::string_view> words;
  std::vector<double> others(l.others.size());
  std::size_t at = h.body;
  std::uint64_t line = h.body_line - 1;
  for (std::uint64_t i = 0; i < h.points;) {
    if (at >= text.size())
      throw FormatError(name, text.size(), "the data ends after " + std::to_string(i) + " of " + std::to_string(h.points) +
                                               " points (truncated file)");
    std::size_t end = text.find('\n', at);
    if (end == std::string_view::npos) end = text.size();
    ++line;
    const std::size_t line_start = at;
    split_words(text.substr(at, end - at), words);
    at = end + 1;
    if (words.empty()) continue;
    auto fail = [&](const std::string& cause) -> void {
      throw FormatError(name, line_start, "line " + std::to_string(line) + ": " + cause);
    };
    if (words.size() != h.components)
      fail(std::to_string(words.size()) + " values, the header's fields need " + std::to_string(h.components));
    auto number = [&](const Field& f, std::uint64_t element = 0) {
      std::string_view w = words[static_cast<std::size_t>(f.component + element)];
      if (!w.empty() && w.front() == '+') w.remove_prefix(1);
      double v = 0.0;
      const auto r = std::from_chars(w.data(), w.data() + w.size(), v);
      // (append, not "'" + string: GCC 12 warns falsely of overlapping copies when inlined)
      if (r.ec != std::errc() || r.ptr != w.data() + w.size())
        fail(std::string(1, '\'').append(w).append("' is not a number"));
      // As the binary kinds would store it: a SIZE 4 float field holds a float.
      return f.type == 'F' && f.size == 4 ? static_cast<double>(static_cast<float>(v)) : v;
    };
    const double xyz[3] = {number(*l.xyz[0]), number(*l.xyz[1]), number(*l.xyz[2])};
    double rgb[3] = {0, 0, 0};
    if (l.packed_rgb) {
      const std::string_view w = words[static_cast<std::size_t>(l.packed_rgb->component)];
      std::uint32_t packed = 0;
      // PCL writes a float rgb field as its 32-bit pattern in decimal (a float would
      // print some colours as nan); other writers print the float itself.
      if (!parse_number(w, packed)) {
        const double v = number(*l.packed_rgb);
        if (l.packed_rgb->type == 'F') packed = std::bit_cast<std::uint32_t>(static_cast<float>(v));
        else if (v >= std::numeric_limits<std::int32_t>::min() && v < 0) packed = static_cast<std::uint32_t>(static_cast<std::int32_t>(v));
        else fail("'" + std::string(w) + "' is not a packed colour");
      }
      unpack_rgb(packed, rgb);
    } else if (l.channel_scale) {
      for (int c = 0; c < 3; ++c) rgb[c] = number(*l.channels[c]);
    }
    for (std::size_t k = 0; k < l.others.size(); ++k) others[k] = number(*l.others[k].field, l.others[k].element);
    sink.add(xyz, rgb, l.intensity ? number(*l.intensity) : 0.0, others);
    ++i;
  }
}

// LZF expands a 2-byte back reference to at most 8 bytes and a 3-byte one to at most
// 264, so no valid stream inflates more than 88 times.
constexpr std::uint64_t kLzfMaxRatio = 88;

}  // namespace

PointCloud parse_pcd(std::span<const std::uint8_t> bytes, const std::string& name, const InputOptions& options,
                     std::uint64_t* not_finite) {
  // Another format's file (a LAS with --format pcd) is said as what it is, not by its
  // bytes quoted as a header line.
  if (const auto kind = content_kind(bytes.first(std::min<std::size_t>(bytes.size(), 16)));
      kind && kind->find("PCD") == std::string::npos)
    throw FormatError(name, 0, "not a PCD point file: its first bytes are those of " + *kind);
  const Header h = parse_header(bytes, name);
  const Layout layout = find_layout(h, name);
  const std::uint64_t remaining = bytes.size() - h.body;
  PointCloud cloud;
  if (h.data == DataKind::ascii) {
    // Every point takes at least one character and a separator per value.
    PointSink sink(layout, options, cloud, std::min<std::uint64_t>(h.points, remaining / (2 * h.components)));
    read_ascii(std::string_view(reinterpret_cast<const char*>(bytes.data()), bytes.size()), h, layout, sink, name);
    sink.finish();
    if (not_finite) *not_finite = sink.not_finite();
  } else if (h.data == DataKind::binary) {
    if (h.points > remaining / h.point_size)
      throw FormatError(name, h.body, std::to_string(h.points) + " points of " + std::to_string(h.point_size) +
                                          " bytes need more than the " + std::to_string(remaining) +
                                          " bytes after the header (truncated file)");
    PointSink sink(layout, options, cloud, h.points);
    read_records(bytes.data() + h.body, false, h, layout, sink);
    sink.finish();
    if (not_finite) *not_finite = sink.not_finite();
  } else {
    if (remaining < 8) throw FormatError(name, h.body, "binary_compressed data lacks its two 32-bit sizes (truncated file)");
    std::uint32_t compressed = 0, raw = 0;
    std::memcpy(&compressed, bytes.data() + h.body, 4);
    std::memcpy(&raw, bytes.data() + h.body + 4, 4);
    if (h.points > std::numeric_limits<std::uint32_t>::max() / h.point_size || raw != h.points * h.point_size)
      throw FormatError(name, h.body + 4, "binary_compressed data says " + std::to_string(raw) + " bytes uncompressed, " +
                                              std::to_string(h.points) + " points of " + std::to_string(h.point_size) +
                                              " bytes need " + std::to_string(h.points * h.point_size));
    if (compressed > remaining - 8)
      throw FormatError(name, h.body, "binary_compressed data of " + std::to_string(compressed) + " bytes runs past the end (truncated file)");
    if (raw > 0 && (compressed == 0 || raw > kLzfMaxRatio * compressed))
      throw FormatError(name, h.body, std::to_string(compressed) + " LZF bytes cannot hold " + std::to_string(raw) + " bytes");
    // Each value becomes an 8-byte double: one-byte fields packed 88:1 made 4.5 MB take
    // 3.6 GB. As for .npz members, 2^25 + 8 values per compressed byte.
    const std::uint64_t values = h.points * h.components,
                        allowed = (std::uint64_t{1} << 25) + 8 * std::uint64_t{compressed};
    if (values > allowed)
      throw FormatError(name, h.body,
                        std::to_string(h.points) + " points of " + std::to_string(h.components) + " values from " +
                            std::to_string(compressed) + " LZF bytes: more than the " + std::to_string(allowed) +
                            " values vola reads from them (2^25 + 8 per byte)");
    std::vector<std::uint8_t> columns(raw);
    if (raw > 0 && lzf_decompress(bytes.data() + h.body + 8, compressed, columns.data(), raw) != raw)
      throw FormatError(name, h.body + 8, "the LZF data is corrupt (it does not decompress to " + std::to_string(raw) + " bytes)");
    PointSink sink(layout, options, cloud, h.points);
    read_records(columns.data(), true, h, layout, sink);
    sink.finish();
    if (not_finite) *not_finite = sink.not_finite();
  }
  if (options.progress) options.progress(bytes.size(), bytes.size());
  return cloud;
}

PointCloud read_pcd(const std::string& path, const InputOptions& options, std::uint64_t* not_finite) {
  return parse_pcd(read_file_bytes(path), path, options, not_finite);
}

}  // namespace vola::io
