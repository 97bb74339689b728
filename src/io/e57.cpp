#include "vola/io/e57.hpp"

#include <algorithm>
#include <bit>
#include <charconv>
#include <cmath>
#include <cstring>
#include <limits>
#include <optional>
#include <span>
#include <unordered_map>
#include <unordered_set>

#include "column_names.hpp"
#include "e57_pages.hpp"
#include "e57_xml.hpp"
#include "point_colours.hpp"
#include "vola/error.hpp"
#include "vola/little_endian.hpp"

namespace vola::io {

namespace {

// Real XML sections are kilobytes (megabytes with many images); a parsed tree takes
// several times its text, so larger ones are refused before they are read.
constexpr std::uint64_t kMaxE57XmlBytes = std::uint64_t{64} << 20;
constexpr std::size_t kMaxE57Fields = 1024;
constexpr std::size_t kCvSectionHeaderBytes = 32;

// One field of a scan's prototype: how its values are stored in its bytestream.
struct E57Field {
  enum class Kind { floating, integer, scaled, text } kind = Kind::floating;
  std::string name;  // as the prototype names it
  int float_bytes = 8;
  std::int64_t minimum = std::numeric_limits<std::int64_t>::min();
  std::int64_t maximum = std::numeric_limits<std::int64_t>::max();
  double scale = 1.0, offset = 0.0;
  int bits = 0;  // per record
};

struct E57ScanData {
  E57Scan info;
  std::vector<E57Field> fields;
  std::uint64_t file_offset = 0;  // physical offset of the binary section
  std::array<std::array<double, 3>, 3> rotation{{{1, 0, 0}, {0, 1, 0}, {0, 0, 1}}};
};

double element_number(const XmlElement& e, const std::string& file, std::uint64_t offset) {
  const std::string& t = e.text;
  const auto first = t.find_first_not_of(" \t\r\n");
  if (first == std::string::npos) return 0.0;  // an empty element is 0 (E57's default)
  const auto last = t.find_last_not_of(" \t\r\n");
  double v = 0;
  const auto [end, error] = std::from_chars(t.data() + first, t.data() + last + 1, v);
  if (error != std::errc{} || end != t.data() + last + 1)
    throw FormatError(file, offset, "element <" + e.name + "> holds '" + t.substr(first, 40) + "', not a number");
  return v;
}

template <class T>
T attribute_value(const XmlElement& e, std::string_view name, T fallback, const std::string& file,
                  std::uint64_t offset) {
  const auto text = e.attribute(name);
  if (!text) return fallback;
  T v{};
  const auto [end, error] = std::from_chars(text->data(), text->data() + text->size(), v);
  if (error != std::errc{} || end != text->data() + text->size())
    throw FormatError(file, offset,
                      "<" + e.name + "> " + std::string(name) + "=\"" + std::string(text->substr(0, 40)) +
                          "\" is not a number of its kind");
  return v;
}

// Bits a value of [minimum, maximum] takes: ceil(log2(maximum - minimum + 1)).
int bits_of_range(std::int64_t minimum, std::int64_t maximum) {
  const std::uint64_t range = static_cast<std::uint64_t>(maximum) - static_cast<std::uint64_t>(minimum);
  return range == 0 ? 0 : 64 - std::countl_zero(range);
}

E57Field prototype_field(const XmlElement& e, const std::string& file, std::uint64_t offset) {
  E57Field f;
  f.name = e.name;
  const std::string type(e.attribute("type").value_or(""));
  if (type == "Float") {
    const std::string precision(e.attribute("precision").value_or("double"));
    if (precision != "single" && precision != "double")
      throw FormatError(file, offset, "field " + f.name + ": precision \"" + precision + "\" (single or double)");
    f.float_bytes = precision == "single" ? 4 : 8;
    f.bits = 8 * f.float_bytes;
  } else if (type == "Integer" || type == "ScaledInteger") {
    f.kind = type == "Integer" ? E57Field::Kind::integer : E57Field::Kind::scaled;
    f.minimum = attribute_value(e, "minimum", f.minimum, file, offset);
    f.maximum = attribute_value(e, "maximum", f.maximum, file, offset);
    if (f.maximum < f.minimum) throw FormatError(file, offset, "field " + f.name + ": maximum below minimum");
    f.bits = bits_of_range(f.minimum, f.maximum);
    if (f.kind == E57Field::Kind::scaled) {
      f.scale = attribute_value(e, "scale", 1.0, file, offset);
      f.offset = attribute_value(e, "offset", 0.0, file, offset);
      if (!std::isfinite(f.scale) || f.scale == 0 || !std::isfinite(f.offset))
        throw FormatError(file, offset, "field " + f.name + ": scale and offset must be finite, scale not 0");
    }
  } else if (type == "String") {
    f.kind = E57Field::Kind::text;  // its bytestream is not read
  } else {
    throw FormatError(file, offset,
                      "field " + f.name + " of type \"" + type +
                          "\" in a point prototype (vola reads Float, Integer, ScaledInteger and String fields)");
  }
  return f;
}

// The rotation matrix of the quaternion w x y z (normalised here).
// Normalises the quaternion w x y z in place and returns its rotation matrix.
std::array<std::array<double, 3>, 3> quaternion_matrix(std::array<double, 4>& q, const std::string& file,
                                                       std::uint64_t offset) {
  const double n = std::sqrt(q[0] * q[0] + q[1] * q[1] + q[2] * q[2] + q[3] * q[3]);
  if (!(n > 0) || !std::isfinite(n)) throw FormatError(file, offset, "a pose's rotation quaternion has no length");
  for (double& c : q) c /= n;
  const double w = q[0], x = q[1], y = q[2], z = q[3];
  return {{{1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y)},
           {2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x)},
           {2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)}}};
}

struct E57Parsed {
  E57Header header;
  std::string library;
  std::string crs;  // coordinateMetadata: the standard leaves its form open (WKT, EPSG:code)
  std::vector<E57ScanData> scans;
  std::uint64_t images = 0;
};

E57Parsed parse_e57(E57Pages& pages) {
  const std::string& file = pages.path();
  const E57Header& h = pages.header();
  const std::uint64_t at = h.xml_physical_offset;
  if (h.xml_logical_length > kMaxE57XmlBytes)
    throw FormatError(file, 32,
                      std::to_string(h.xml_logical_length) + " bytes of XML, more than the " +
                          std::to_string(kMaxE57XmlBytes >> 20) + " MiB an E57 file's XML may take here");
  const std::vector<std::uint8_t> xml =
      pages.read(pages.logical_of(at, "the XML section"), static_cast<std::size_t>(h.xml_logical_length));
  const XmlElement root =
      parse_e57_xml(std::string_view(reinterpret_cast<const char*>(xml.data()), xml.size()), file, at);
  if (root.name != "e57Root") throw FormatError(file, at, "the XML's root is <" + root.name + ">, not <e57Root>");
  E57Parsed p;
  p.header = h;
  if (const XmlElement* lib = root.child("e57LibraryVersion")) p.library = lib->text;
  if (const XmlElement* crs = root.child("coordinateMetadata")) {
    const auto first = crs->text.find_first_not_of(" \t\r\n");
    if (first != std::string::npos) p.crs = crs->text.substr(first, crs->text.find_last_not_of(" \t\r\n") + 1 - first);
  }
  if (const XmlElement* images = root.child("images2D")) p.images = images->children.size();
  const XmlElement* data3d = root.child("data3D");
  if (!data3d) return p;  // a file of images only
  for (const XmlElement& node : data3d->children) {
    E57ScanData s;
    if (const XmlElement* name = node.child("name")) s.info.name = name->text;
    const XmlElement* points = node.child("points");
    if (!points || points->attribute("type").value_or("") != "CompressedVector")
      throw FormatError(file, at, "scan '" + s.info.name + "' has no <points> CompressedVector");
    s.file_offset = attribute_value<std::uint64_t>(*points, "fileOffset", 0, file, at);
    s.info.records = attribute_value<std::uint64_t>(*points, "recordCount", 0, file, at);
    const XmlElement* prototype = points->child("prototype");
    if (!prototype) throw FormatError(file, at, "scan '" + s.info.name + "' has no point prototype");
    if (prototype->children.size() > kMaxE57Fields)
      throw FormatError(file, at, "scan '" + s.info.name + "': more than " + std::to_string(kMaxE57Fields) + " fields");
    for (const XmlElement& f : prototype->children) {
      s.fields.push_back(prototype_field(f, file, at));
      s.info.fields.push_back(f.name);
    }
    if (const XmlElement* codecs = points->child("codecs"); codecs && !codecs->children.empty())
      throw FormatError(file, at,
                        "scan '" + s.info.name + "' names codecs; vola reads the default bit-pack codec only");
    if (const XmlElement* pose = node.child("pose")) {
      if (const XmlElement* r = pose->child("rotation")) {
        // ASTM E2807 requires all four (and all three of a translation): a missing w taken
        // from the identity made another rotation without a word.
        const char* names[] = {"w", "x", "y", "z"};
        for (std::size_t i = 0; i < 4; ++i) {
          const XmlElement* c = r->child(names[i]);
          if (!c)
            throw FormatError(file, at,
                              "scan '" + s.info.name + "': its pose's rotation has no " + names[i] +
                                  " (a quaternion needs w, x, y and z)");
          s.info.rotation[i] = element_number(*c, file, at);
        }
        s.rotation = quaternion_matrix(s.info.rotation, file, at);
      }
      if (const XmlElement* t = pose->child("translation")) {
        const char* names[] = {"x", "y", "z"};
        for (std::size_t i = 0; i < 3; ++i) {
          const XmlElement* c = t->child(names[i]);
          if (!c) throw FormatError(file, at, "scan '" + s.info.name + "': its pose's translation has no " + names[i]);
          s.info.translation[i] = element_number(*c, file, at);
        }
      }
      s.info.has_pose =
          s.info.rotation != std::array<double, 4>{1, 0, 0, 0} || s.info.translation != std::array<double, 3>{0, 0, 0};
    }
    p.scans.push_back(std::move(s));
  }
  return p;
}

// One field's bytestream, fed packet by packet and read a batch of records at a time:
// little-endian floats, or integers packed `bits` to a record from the least significant
// bit of each byte, stored less the minimum. A record's bits may start in one packet and
// end in the next.
class FieldStream {
 public:
  explicit FieldStream(const E57Field& field) : f_(field) {}

  void append(std::span<const std::uint8_t> bytes) {
    // Whole bytes read are dropped once they are half the buffer or more: dropping them at
    // every packet moved the whole buffer each time, quadratic when another field's
    // stream runs far ahead (a 30 MB file took minutes).
    const std::size_t consumed = static_cast<std::size_t>(bit_ >> 3);
    if (consumed > 0 && consumed >= bytes_.size() / 2) {
      bytes_.erase(bytes_.begin(), bytes_.begin() + static_cast<std::ptrdiff_t>(consumed));
      bit_ &= 7;
    }
    bytes_.insert(bytes_.end(), bytes.begin(), bytes.end());
  }

  // Records whose bits are all here (a constant field: any number).
  std::uint64_t available() const {
    if (f_.bits == 0) return std::numeric_limits<std::uint64_t>::max();
    return (8 * static_cast<std::uint64_t>(bytes_.size()) - bit_) / static_cast<std::uint64_t>(f_.bits);
  }

  // The next `n` values (n <= available()).
  void take(std::uint64_t n, std::vector<double>& out) {
    out.resize(static_cast<std::size_t>(n));
    const std::uint64_t mask = f_.bits == 64 ? ~std::uint64_t{0} : (std::uint64_t{1} << f_.bits) - 1;
    for (std::size_t i = 0; i < out.size(); ++i) {
      if (f_.kind == E57Field::Kind::floating) {
        const std::uint8_t* at = bytes_.data() + (bit_ >> 3);
        out[i] = f_.float_bytes == 4 ? static_cast<double>(load_le<float>(at)) : load_le<double>(at);
      } else {
        const auto value = static_cast<std::int64_t>(raw(mask) + static_cast<std::uint64_t>(f_.minimum));  // wraps
        out[i] = f_.kind == E57Field::Kind::scaled ? static_cast<double>(value) * f_.scale + f_.offset
                                                   : static_cast<double>(value);
      }
      bit_ += static_cast<std::uint64_t>(f_.bits);
    }
  }

 private:
  // The record at bit_: up to 64 bits from the (at most 9) bytes holding them.
  std::uint64_t raw(std::uint64_t mask) const {
    if (f_.bits == 0) return 0;
    const std::size_t byte = static_cast<std::size_t>(bit_ >> 3);
    const int shift = static_cast<int>(bit_ & 7);
    std::uint8_t word[16] = {};
    std::memcpy(word, bytes_.data() + byte, std::min<std::size_t>(16, bytes_.size() - byte));
    std::uint64_t v = load_le<std::uint64_t>(word) >> shift;
    if (shift + f_.bits > 64) v |= static_cast<std::uint64_t>(word[8]) << (64 - shift);
    return v & mask;
  }

  const E57Field& f_;
  std::vector<std::uint8_t> bytes_;
  std::uint64_t bit_ = 0;  // the next record's first bit in bytes_
};

// Calls `on_packet(streams, physical)` with each data packet's bytestreams (one per
// prototype field, in order), in file order, until it returns false; index and empty
// packets are passed over. Checks the section header and that the section can hold the
// scan's records (every record's bits, or one record a byte when every field is
// constant), so that no count allocates more than the file justifies.
template <class OnPacket>
void for_each_data_packet(E57Pages& pages, const E57ScanData& s, OnPacket&& on_packet) {
  const std::string& file = pages.path();
  const std::uint64_t start = pages.logical_of(s.file_offset, "a scan's binary section");
  const std::vector<std::uint8_t> h = pages.read(start, kCvSectionHeaderBytes);
  if (h[0] != 1)
    throw FormatError(file, s.file_offset,
                      "scan '" + s.info.name + "': the section here is not a compressed vector (section id " +
                          std::to_string(h[0]) + ")");
  const std::uint64_t length = load_le<std::uint64_t>(h.data() + 8);
  const std::uint64_t data_physical = load_le<std::uint64_t>(h.data() + 16);
  pages.check_range(start, length);
  const std::uint64_t end = start + length;
  std::uint64_t record_bits = 0;
  for (const E57Field& f : s.fields) record_bits += static_cast<std::uint64_t>(f.bits);
  const bool too_many = record_bits == 0 ? s.info.records > length : s.info.records > length * 8 / record_bits;
  if (too_many)
    throw FormatError(file, s.file_offset,
                      "scan '" + s.info.name + "' claims " + std::to_string(s.info.records) +
                          " records; its section of " + std::to_string(length) + " bytes cannot hold them");
  if (s.info.records == 0) return;
  std::uint64_t at = pages.logical_of(data_physical, "a scan's first data packet");
  if (at < start + kCvSectionHeaderBytes || at >= end)
    throw FormatError(file, data_physical,
                      "scan '" + s.info.name + "': its first data packet lies outside its section");
  std::vector<std::uint8_t> packet;
  std::vector<std::span<const std::uint8_t>> streams(s.fields.size());
  while (at < end) {
    const std::uint64_t physical = at / 1020 * 1024 + at % 1020;
    if (end - at < 4) throw FormatError(file, physical, "a packet header runs past its section");
    std::uint8_t head[4];
    pages.read(at, head, 4);
    const std::uint64_t size = std::uint64_t{load_le<std::uint16_t>(head + 2)} + 1;
    if (size > end - at)
      throw FormatError(file, physical, "a packet of " + std::to_string(size) + " bytes runs past its section");
    if (head[0] == 1) {  // data
      packet.resize(static_cast<std::size_t>(size));
      pages.read(at, packet.data(), packet.size());
      if (size < 6) throw FormatError(file, physical, "a data packet too short for its header");
      const std::size_t count = load_le<std::uint16_t>(packet.data() + 4);
      if (count != s.fields.size())
        throw FormatError(file, physical,
                          "a data packet of " + std::to_string(count) + " bytestreams for a prototype of " +
                              std::to_string(s.fields.size()) + " fields");
      std::size_t offset = 6 + 2 * count;
      if (offset > packet.size()) throw FormatError(file, physical, "a data packet's stream lengths run past it");
      for (std::size_t i = 0; i < count; ++i) {
        const std::size_t n = load_le<std::uint16_t>(packet.data() + 6 + 2 * i);
        if (n > packet.size() - offset)
          throw FormatError(file, physical, "bytestream " + std::to_string(i) + " runs past its data packet");
        streams[i] = std::span<const std::uint8_t>(packet.data() + offset, n);
        offset += n;
      }
      if (!on_packet(streams, physical)) return;
    } else if (head[0] != 0 && head[0] != 2) {  // index and empty packets are passed over
      throw FormatError(file, physical, "a packet of unknown type " + std::to_string(head[0]));
    }
    at += size;
  }
}

std::optional<std::size_t> field_index(const E57ScanData& s, std::string_view name) {
  for (std::size_t i = 0; i < s.fields.size(); ++i)
    if (s.fields[i].name == name) return i;
  return std::nullopt;
}

// Fields that place the point or describe the scan's grid, not the point: never columns.
bool is_e57_geometry(std::string_view name) {
  return name.starts_with("cartesian") || name.starts_with("spherical") || name == "rowIndex" ||
         name == "columnIndex" || (name.starts_with("is") && name.ends_with("Invalid"));
}

bool is_e57_colour(std::string_view name) { return name == "colorRed" || name == "colorGreen" || name == "colorBlue"; }

// The column a field becomes, and its type.
std::string e57_column_name(std::string_view field) {
  if (field == "returnIndex") return "return_index";  // E57 counts from 0, some writers from 1: kept as stored
  if (field == "returnCount") return "number_of_returns";
  const auto colon = field.find(':');
  return point_column_name(colon == std::string_view::npos ? field : field.substr(colon + 1));
}

ValueType e57_column_type(const E57Field& f) {
  if (f.kind == E57Field::Kind::floating) return f.float_bytes == 4 ? ValueType::f32 : ValueType::f64;
  if (f.kind == E57Field::Kind::scaled) return ValueType::f64;
  if (f.minimum >= 0 && f.maximum <= 0xFF) return ValueType::u8;
  if (f.minimum >= 0 && f.maximum <= 0xFFFF) return ValueType::u16;
  if (f.minimum >= std::numeric_limits<std::int32_t>::min() && f.maximum <= std::numeric_limits<std::int32_t>::max())
    return ValueType::i32;
  return ValueType::f64;
}

// How the file's colours are kept: 16-bit when any scan's channels pass 255, floats in
// 0..1 when they are floats, else 8-bit.
ColourScale e57_colour_scale(const std::vector<E57ScanData>& scans) {
  ColourScale scale = ColourScale::bits8;
  for (const E57ScanData& s : scans)
    if (const auto red = field_index(s, "colorRed")) {
      const E57Field& f = s.fields[*red];
      if (f.kind == E57Field::Kind::floating) return ColourScale::unit;
      if (f.maximum > 255) scale = ColourScale::bits16;
    }
  return scale;
}

}  // namespace

E57Summary e57_summary(const std::string& path) {
  E57Pages pages(path);
  const E57Parsed p = parse_e57(pages);
  E57Summary s;
  s.version_major = p.header.major;
  s.version_minor = p.header.minor;
  s.library = p.library;
  s.crs = p.crs;
  s.images = p.images;
  for (const E57ScanData& scan : p.scans) s.scans.push_back(scan.info);
  return s;
}

Input read_e57(const std::string& path, const InputOptions& options) {
  E57Pages pages(path);
  const E57Parsed p = parse_e57(pages);
  Input in;
  in.format = "e57";
  // "EPSG:32633" gives the code; any other text is taken as a CRS definition (WKT), which
  // vola convert keeps only when PROJ reads it (and says so when it does not).
  std::uint32_t code = 0;
  const std::string_view crs = p.crs;
  if (crs.starts_with("EPSG:") &&
      std::from_chars(crs.data() + 5, crs.data() + crs.size(), code).ptr == crs.data() + crs.size() && code > 0)
    in.epsg = code;
  else
    in.wkt = p.crs;
  // Columns: the numeric fields every scan has (by column name), colours as red/green/blue.
  std::vector<std::string> columns;
  std::vector<ValueType> types;
  std::vector<std::string> spelled;  // the field name as the first scan spells it
  bool colours = !p.scans.empty();
  for (const E57ScanData& s : p.scans)
    for (const char* c : {"colorRed", "colorGreen", "colorBlue"}) colours = colours && field_index(s, c).has_value();
  // Each scan's numeric fields by column name (the first of a name), made once: a search
  // per field and scan took 45 s for 1000 scans of 1000 fields.
  std::vector<std::unordered_map<std::string, const E57Field*>> by_column(p.scans.size());
  for (std::size_t i = 0; i < p.scans.size(); ++i)
    for (const E57Field& g : p.scans[i].fields)
      if (g.kind != E57Field::Kind::text && !is_e57_geometry(g.name))
        by_column[i].try_emplace(e57_column_name(g.name), &g);
  std::unordered_set<std::string> taken;
  if (!p.scans.empty())
    for (const E57Field& f : p.scans.front().fields) {
      if (is_e57_geometry(f.name) || is_e57_colour(f.name) || f.kind == E57Field::Kind::text) continue;
      const std::string column = e57_column_name(f.name);
      if (!taken.insert(column).second) continue;
      bool everywhere = true;
      ValueType type = e57_column_type(f);
      for (const auto& fields : by_column) {
        const auto it = fields.find(column);
        if (it == fields.end()) {
          everywhere = false;
          break;
        }
        if (e57_column_type(*it->second) != type) type = ValueType::f64;
      }
      if (!everywhere) continue;
      columns.push_back(column);
      types.push_back(type);
      spelled.push_back(f.name);
    }
  if (!options.attributes) columns.clear(), types.clear(), spelled.clear();
  const ColourScale scale = e57_colour_scale(p.scans);
  std::uint64_t total = 0, done = 0;
  for (const E57ScanData& s : p.scans) total += s.info.records;
  PointCloud& cloud = in.cloud;
  for (std::size_t c = 0; c < columns.size(); ++c)
    cloud.attributes.push_back({columns[c], types[c], point_column_reduction(columns[c], spelled[c]), {}});
  std::optional<ColourColumns> colour;
  if (colours && (options.attributes || options.payload))
    colour.emplace(cloud, scale, options.attributes, options.payload);

  for (const E57ScanData& s : p.scans) {
    const auto cx = field_index(s, "cartesianX"), cy = field_index(s, "cartesianY"), cz = field_index(s, "cartesianZ");
    const auto range = field_index(s, "sphericalRange"), azimuth = field_index(s, "sphericalAzimuth"),
               elevation = field_index(s, "sphericalElevation");
    const bool cartesian = cx && cy && cz;
    if (!cartesian && !(range && azimuth && elevation))
      throw FormatError(
          path, s.file_offset,
          "scan '" + s.info.name + "' has neither cartesianX/Y/Z nor sphericalRange/Azimuth/Elevation fields");
    const auto invalid = field_index(s, cartesian ? "cartesianInvalidState" : "sphericalInvalidState");
    std::vector<bool> wanted(s.fields.size(), false);
    for (auto i : {cartesian ? cx : range, cartesian ? cy : azimuth, cartesian ? cz : elevation, invalid})
      if (i) wanted[*i] = true;
    std::vector<std::size_t> column_field(columns.size());
    for (std::size_t c = 0; c < columns.size(); ++c)
      for (std::size_t i = 0; i < s.fields.size(); ++i)
        if (s.fields[i].kind != E57Field::Kind::text && !is_e57_geometry(s.fields[i].name) &&
            e57_column_name(s.fields[i].name) == columns[c]) {
          column_field[c] = i;
          wanted[i] = true;
          break;
        }
    std::array<std::optional<std::size_t>, 3> rgb{field_index(s, "colorRed"), field_index(s, "colorGreen"),
                                                  field_index(s, "colorBlue")};
    if (colour)
      for (auto i : rgb) wanted[*i] = true;
    // 8-bit channels in a file whose colours are 16-bit (another scan's) are widened.
    const double widen = colour && scale == ColourScale::bits16 && s.fields[*rgb[0]].maximum <= 255 ? 257.0 : 1.0;
    std::vector<std::optional<FieldStream>> streams(s.fields.size());
    for (std::size_t i = 0; i < s.fields.size(); ++i)
      if (wanted[i]) streams[i].emplace(s.fields[i]);
    std::vector<std::vector<double>> values(s.fields.size());
    std::uint64_t decoded = 0;
    // The points of one batch of records (those whose every wanted field is here).
    const auto emit = [&](std::size_t n) {
      const auto& a = values[*(cartesian ? cx : range)];
      const auto& b = values[*(cartesian ? cy : azimuth)];
      const auto& c = values[*(cartesian ? cz : elevation)];
      const std::vector<double>* state = invalid ? &values[*invalid] : nullptr;
      for (std::size_t k = 0; k < n; ++k) {
        if (state && (*state)[k] != 0) {
          ++in.not_finite;
          continue;
        }
        double local[3] = {a[k], b[k], c[k]};
        if (!cartesian) {
          const double r = a[k], az = b[k], el = c[k];
          local[0] = r * std::cos(el) * std::cos(az);
          local[1] = r * std::cos(el) * std::sin(az);
          local[2] = r * std::sin(el);
        }
        double world[3];
        for (std::size_t r = 0; r < 3; ++r)
          world[r] = s.rotation[r][0] * local[0] + s.rotation[r][1] * local[1] + s.rotation[r][2] * local[2] +
                     s.info.translation[r];
        if (!std::isfinite(world[0]) || !std::isfinite(world[1]) || !std::isfinite(world[2])) {
          ++in.not_finite;
          continue;
        }
        cloud.xyz.insert(cloud.xyz.end(), world, world + 3);
        for (std::size_t col = 0; col < columns.size(); ++col)
          cloud.attributes[col].values.push_back(values[column_field[col]][k]);
        if (colour) colour->add(values[*rgb[0]][k] * widen, values[*rgb[1]][k] * widen, values[*rgb[2]][k] * widen);
      }
    };
    for_each_data_packet(pages, s, [&](const std::vector<std::span<const std::uint8_t>>& packet, std::uint64_t) {
      std::uint64_t n = s.info.records - decoded;
      for (std::size_t i = 0; i < streams.size(); ++i)
        if (streams[i]) {
          streams[i]->append(packet[i]);
          n = std::min(n, streams[i]->available());
        }
      for (std::size_t i = 0; i < streams.size(); ++i)
        if (streams[i]) streams[i]->take(n, values[i]);
      emit(static_cast<std::size_t>(n));
      decoded += n;
      if (options.progress) options.progress(done + decoded, total);
      return decoded < s.info.records;
    });
    if (decoded < s.info.records) {
      std::size_t shortest = 0;  // the field that ran out first
      std::uint64_t fewest = std::numeric_limits<std::uint64_t>::max();
      for (std::size_t i = 0; i < streams.size(); ++i)
        if (streams[i] && streams[i]->available() < fewest) fewest = streams[i]->available(), shortest = i;
      throw FormatError(path, s.file_offset,
                        "scan '" + s.info.name + "': field " + s.fields[shortest].name + " ends after " +
                            std::to_string(decoded) + " of its " + std::to_string(s.info.records) +
                            " records (the section ends early)");
    }
    done += s.info.records;
  }
  if (colour) colour->finish();  // float channels: 0..1, or 0..255 when any is above 1
  return in;
}

}  // namespace vola::io
