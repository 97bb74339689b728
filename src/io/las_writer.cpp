// LAS 1.4 (ASPRS R15), point data record formats 6 and 7: voxel centres with their
// attributes, georeferenced by an OGC WKT record.
#include <algorithm>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <ctime>
#include <functional>
#include <limits>

#include "export_columns.hpp"
#include "las_format.hpp"
#include "vola/output_file.hpp"
#include "vola/error.hpp"
#include "vola/geo/crs.hpp"
#include "vola/io/export.hpp"
#include "vola/io/las.hpp"
#include "vola/version.hpp"

namespace vola::io {

namespace {

constexpr std::size_t kHeaderSize = 375;
constexpr std::size_t kVlrHeaderSize = 54;
constexpr std::size_t kExtraBytesDescriptorSize = 192;
constexpr std::uint16_t kWktBit = 1u << 4;

template <class T>
void put(std::vector<std::uint8_t>& bytes, std::size_t offset, T value) {
  std::memcpy(bytes.data() + offset, &value, sizeof(T));
}

void put_text(std::vector<std::uint8_t>& bytes, std::size_t offset, std::size_t size, const std::string& text) {
  std::memcpy(bytes.data() + offset, text.data(), std::min(size, text.size()));
}

// 10^exponent, the double nearest to the decimal (what a reader prints as "0.001").
double power_of_ten(int exponent) {
  const std::string text = "1e" + std::to_string(exponent);
  double value = 0.0;
  std::from_chars(text.data(), text.data() + text.size(), value);
  return value;
}

// A power of ten at most 1/1000 of a voxel, unless `extent` (the grid's side, counted
// from the offset) would then overflow a 32-bit coordinate: coarser by tens until it
// fits. Even at depth 10 that stays below 1/100 of a voxel.
double choose_scale(double voxel_size, double extent) {
  if (!std::isfinite(extent) || !std::isfinite(voxel_size) || !(voxel_size > 0.0))
    throw InvalidArgument("a LAS file needs finite coordinates: the grid spans " + std::to_string(extent) +
                          " at voxels of " + std::to_string(voxel_size));
  int exponent = static_cast<int>(std::floor(std::log10(voxel_size / 1000.0)));
  while (extent / power_of_ten(exponent) > 2.0e9) ++exponent;  // ends: extent < 2e9 x 1e308
  return power_of_ten(exponent);
}

std::uint8_t extra_bytes_type(ValueType type) {
  switch (type) {
    case ValueType::u8: return 1;
    case ValueType::i8: return 2;
    case ValueType::u16: return 3;
    case ValueType::i16: return 4;
    case ValueType::u32: return 5;
    case ValueType::i32: return 6;
    case ValueType::u64: return 7;
    case ValueType::i64: return 8;
    case ValueType::f32: return 9;
    case ValueType::f64: return 10;
  }
  return 10;
}

// A standard field's value: rounded and clamped into [0, max].
std::uint32_t field_value(const AttributeColumn* column, std::size_t rank, double max, std::uint32_t missing) {
  if (!column) return missing;
  const double v = column->get(rank);
  if (std::isnan(v)) return 0;
  return static_cast<std::uint32_t>(std::clamp(std::nearbyint(v), 0.0, max));
}

// LAS colours are 16-bit: 8-bit columns are widened (255 -> 65535).
std::uint16_t colour_value(const AttributeColumn& column, std::size_t rank) {
  const std::uint32_t v = field_value(&column, rank, 65535.0, 0);
  return static_cast<std::uint16_t>(column.type() == ValueType::u8 ? v * 257u : v);
}

struct LasColumns {
  const AttributeColumn* red = nullptr;
  const AttributeColumn* green = nullptr;
  const AttributeColumn* blue = nullptr;
  const AttributeColumn* intensity = nullptr;
  const AttributeColumn* classification = nullptr;
  const AttributeColumn* returns = nullptr;          // number_of_returns
  const AttributeColumn* return_number = nullptr;    // point files; a voxel is return 1
  const AttributeColumn* user_data = nullptr;
  const AttributeColumn* point_source_id = nullptr;
  const AttributeColumn* gps_time = nullptr;
  const AttributeColumn* scan_angle = nullptr;            // degrees
  const AttributeColumn* classification_flags = nullptr;  // 4 bits
  // PDAL's one-bit dimensions of the same flags (synthetic, key_point, withheld, overlap:
  // what a CSV from PDAL holds), OR'ed into them.
  const AttributeColumn* flag_bits[4] = {};
  const AttributeColumn* scanner_channel = nullptr;       // 2 bits
  const AttributeColumn* scan_direction = nullptr;        // 1 bit
  const AttributeColumn* edge = nullptr;                  // 1 bit
  std::vector<const AttributeColumn*> extra;
  std::vector<std::string> extra_names;  // at most 32 bytes, unique
  bool rgb() const noexcept { return red && green && blue; }
};

// The columns that have a LAS field of their own, by name; the others become extra bytes
// ("height" too: a voxel's mean z is not its centre's z, and vola's LAS reader takes an
// extra-bytes "height" back as the height column).
LasColumns sort_columns(const Attributes& a) {
  LasColumns c;
  if (a.find("red") && a.find("green") && a.find("blue")) {
    c.red = a.find("red");
    c.green = a.find("green");
    c.blue = a.find("blue");
  }
  c.intensity = a.find("intensity");
  c.classification = a.find("classification");
  c.returns = a.find("number_of_returns");
  c.return_number = a.find("return_number");
  c.user_data = a.find("user_data");
  c.point_source_id = a.find("point_source_id");
  c.gps_time = a.find("gps_time");
  c.scan_angle = a.find("scan_angle_rank");
  c.classification_flags = a.find("classification_flags");
  // Only columns of 0s and 1s are flags: an "overlap" of 0.3 or 47.5 is some other
  // measurement, kept as extra bytes.
  const auto holds_bits = [](const AttributeColumn& column) {
    for (std::size_t i = 0; i < column.size(); ++i)
      if (const double v = column.get(i); !(v == 0 || v == 1 || std::isnan(v))) return false;
    return true;
  };
  static constexpr const char* kFlagBits[] = {"synthetic", "key_point", "withheld", "overlap"};
  for (int bit = 0; bit < 4; ++bit)
    if (const AttributeColumn* column = a.find(kFlagBits[bit]); column && holds_bits(*column))
      c.flag_bits[bit] = column;
  c.scanner_channel = a.find("scanner_channel");
  c.scan_direction = a.find("scan_direction_flag");
  c.edge = a.find("edge_of_flight_line");
  for (const auto& column : a.columns()) {
    const std::string& name = column.name();
    const bool standard = name == "intensity" || name == "classification" || name == "number_of_returns" ||
                          name == "return_number" || name == "user_data" || name == "point_source_id" ||
                          name == "gps_time" || name == "scan_angle_rank" || name == "classification_flags" ||
                          std::find(std::begin(c.flag_bits), std::end(c.flag_bits), &column) != std::end(c.flag_bits) ||
                          name == "scanner_channel" || name == "scan_direction_flag" || name == "edge_of_flight_line" ||
                          (c.rgb() && (name == "red" || name == "green" || name == "blue"));
    if (standard) continue;
    std::string short_name = name.substr(0, 32);
    for (int n = 2; std::find(c.extra_names.begin(), c.extra_names.end(), short_name) != c.extra_names.end(); ++n) {
      const std::string number = std::to_string(n);
      short_name = name.substr(0, 31 - number.size());
      short_name += '_';
      short_name += number;
    }
    c.extra.push_back(&column);
    c.extra_names.push_back(short_name);
  }
  return c;
}

std::vector<std::uint8_t> vlr(const std::string& user_id, std::uint16_t record_id, const std::string& description,
                              const std::vector<std::uint8_t>& data) {
  if (data.size() > std::numeric_limits<std::uint16_t>::max())
    throw InvalidArgument("LAS record " + user_id + " " + std::to_string(record_id) + " of " +
                          std::to_string(data.size()) + " bytes does not fit a VLR (65535 bytes)");
  std::vector<std::uint8_t> bytes(kVlrHeaderSize + data.size());
  put_text(bytes, 2, 16, user_id);
  put<std::uint16_t>(bytes, 18, record_id);
  put<std::uint16_t>(bytes, 20, static_cast<std::uint16_t>(data.size()));
  put_text(bytes, 22, 32, description);
  std::copy(data.begin(), data.end(), bytes.begin() + kVlrHeaderSize);
  return bytes;
}

std::vector<std::uint8_t> extra_bytes_vlr(const LasColumns& c, bool voxels) {
  std::vector<std::uint8_t> data(c.extra.size() * kExtraBytesDescriptorSize);
  for (std::size_t i = 0; i < c.extra.size(); ++i) {
    const std::size_t at = i * kExtraBytesDescriptorSize;
    data[at + 2] = extra_bytes_type(c.extra[i]->type());
    put_text(data, at + 4, 32, c.extra_names[i]);
    if (voxels) put_text(data, at + 160, 32, "vola " + std::string(name_of(c.extra[i]->reduction())) + " per voxel");
  }
  return vlr("LASF_Spec", 4, "Extra Bytes Record", data);
}

// What the writer writes, whether voxel centres or points: `count` positions in order
// (for_each), their bounds, their columns (one value per position) and their CRS.
struct LasPoints {
  std::uint64_t count = 0;
  std::function<void(const std::function<void(const Point&)>&)> for_each;
  Point min{}, max{};
  const Attributes* attributes = nullptr;
  std::optional<std::string> crs;  // a definition PROJ reads (WKT or "EPSG:<code>")
  std::string crs_wkt;             // the WKT as stored, when PROJ cannot rewrite it
  bool voxels = false;             // voxel centres (columns are reductions per voxel)
};

// The CRS as WKT1 when PROJ can write it, else the WKT as stored; nullopt when there is
// no CRS or only an EPSG code PROJ does not know.
std::optional<std::string> las_wkt(const LasPoints& points) {
  if (!points.crs) return std::nullopt;
  try {
    return geo::crs_wkt1(*points.crs);
  } catch (const Error&) {
    if (!points.crs_wkt.empty()) return points.crs_wkt;
    return std::nullopt;
  }
}

// Positions as LAS stores them: integers of `scale` from `offset`.
struct LasCoordinates {
  double scale = 1.0;
  Point offset{};

  std::int32_t integer(const Point& p, int axis) const {
    const double v = std::nearbyint((p[axis] - offset[axis]) / scale);
    if (!(std::abs(v) <= 2147483647.0))
      throw InvalidArgument("coordinate " + std::to_string(p[axis]) + " does not fit a 32-bit LAS coordinate");
    return static_cast<std::int32_t>(v);
  }
};

struct RecordLayout {
  std::size_t base_length = 30;  // format 6; 36 for format 7 (RGB)
  std::size_t length = 30;       // with the extra bytes
};

RecordLayout record_layout(const LasColumns& columns) {
  RecordLayout layout;
  layout.base_length = columns.rgb() ? 36 : 30;
  layout.length = layout.base_length;
  for (const auto* c : columns.extra) layout.length += size_of(c->type());
  if (layout.length > std::numeric_limits<std::uint16_t>::max())
    throw InvalidArgument("the attribute columns make LAS records of " + std::to_string(layout.length) +
                          " bytes, more than 65535");
  return layout;
}

// The VLRs: the CRS as WKT (when known) and the extra-bytes descriptors.
std::vector<std::vector<std::uint8_t>> header_vlrs(const LasPoints& points, const LasColumns& columns,
                                                   LasReport& report) {
  std::vector<std::vector<std::uint8_t>> vlrs;
  if (const auto wkt = las_wkt(points)) {
    std::vector<std::uint8_t> data(wkt->begin(), wkt->end());
    data.push_back(0);
    vlrs.push_back(vlr("LASF_Projection", 2112, "OGC WKT coordinate system", data));
    report.has_crs = true;
  }
  if (!columns.extra.empty()) vlrs.push_back(extra_bytes_vlr(columns, points.voxels));
  return vlrs;
}

// Return number and number of returns of record `rank`: a voxel (no return_number
// column) is return 1 of its number_of_returns (1 without that column; 0 of 0 for 0).
std::pair<std::uint32_t, std::uint32_t> returns_of(const LasColumns& columns, std::size_t rank) {
  const std::uint32_t count = field_value(columns.returns, rank, 15.0, 1);
  const std::uint32_t number = columns.return_number ? field_value(columns.return_number, rank, 15.0, 0) : count ? 1 : 0;
  return {number, count};
}

// The LAS 1.4 public header block.
std::vector<std::uint8_t> public_header(const LasPoints& points, const LasColumns& columns, const RecordLayout& layout,
                                        const LasCoordinates& coords, const std::vector<std::vector<std::uint8_t>>& vlrs,
                                        const LasReport& report) {
  std::size_t offset_to_points = kHeaderSize;
  for (const auto& v : vlrs) offset_to_points += v.size();
  std::vector<std::uint8_t> h(kHeaderSize);
  std::memcpy(h.data(), "LASF", 4);
  // Set with or without a CRS: point formats 6-10 take theirs as WKT only (LAS 1.4 R15),
  // and PDAL complains of a format-6 file without the bit.
  put<std::uint16_t>(h, 6, kWktBit);
  h[24] = 1;
  h[25] = 4;
  put_text(h, 26, 32, "vola");
  put_text(h, 58, 32, "vola " VOLA_VERSION_STRING " export");
  const std::time_t now = std::time(nullptr);
  std::tm utc{};
  gmtime_r(&now, &utc);
  put<std::uint16_t>(h, 90, static_cast<std::uint16_t>(utc.tm_yday + 1));
  put<std::uint16_t>(h, 92, static_cast<std::uint16_t>(utc.tm_year + 1900));
  put<std::uint16_t>(h, 94, kHeaderSize);
  put<std::uint32_t>(h, 96, static_cast<std::uint32_t>(offset_to_points));
  put<std::uint32_t>(h, 100, static_cast<std::uint32_t>(vlrs.size()));
  h[104] = report.point_format;
  put<std::uint16_t>(h, 105, static_cast<std::uint16_t>(layout.length));
  // Legacy 32-bit counts stay 0: formats 6-10 use the 64-bit ones.
  for (int a = 0; a < 3; ++a) {
    put<double>(h, 131 + 8 * a, coords.scale);
    put<double>(h, 155 + 8 * a, coords.offset[a]);
    if (points.count == 0) continue;  // bounds as stored: the extreme positions, rounded to the scale
    put<double>(h, 179 + 16 * a, coords.integer(points.max, a) * coords.scale + coords.offset[a]);
    put<double>(h, 187 + 16 * a, coords.integer(points.min, a) * coords.scale + coords.offset[a]);
  }
  put<std::uint64_t>(h, 247, points.count);
  std::uint64_t by_return[15] = {};  // points by return number 1..15
  for (std::size_t r = 0; r < points.count; ++r)
    if (const std::uint32_t number = returns_of(columns, r).first; number >= 1 && number <= 15) ++by_return[number - 1];
  for (int k = 0; k < 15; ++k) put<std::uint64_t>(h, 255 + 8 * static_cast<std::size_t>(k), by_return[k]);
  return h;
}

// A standard field fed from a column whose type can hold values the field cannot (a
// classification of i32, an intensity of f32): the values written otherwise, counted.
struct UnfitValues {
  const char* field;
  const AttributeColumn* column;
  double max;
  std::uint64_t outside = 0, not_numbers = 0;
};

bool column_fits(ValueType type, double max) {
  return (type == ValueType::u8 && max >= 255.0) || (type == ValueType::u16 && max >= 65535.0);
}

std::vector<UnfitValues> watched_fields(const LasColumns& c) {
  const std::vector<UnfitValues> all = {{"intensity", c.intensity, 65535.0},
                                        {"classification", c.classification, 255.0},
                                        {"user_data", c.user_data, 255.0},
                                        {"point_source_id", c.point_source_id, 65535.0},
                                        {"number_of_returns", c.returns, 15.0},
                                        {"return_number", c.return_number, 15.0},
                                        {"scanner_channel", c.scanner_channel, 3.0},
                                        {"classification_flags", c.classification_flags, 15.0},
                                        {"red", c.red, 65535.0},
                                        {"green", c.green, 65535.0},
                                        {"blue", c.blue, 65535.0}};
  std::vector<UnfitValues> watched;
  for (const UnfitValues& f : all)
    if (f.column && !column_fits(f.column->type(), f.max)) watched.push_back(f);
  return watched;
}

void count_unfit(std::vector<UnfitValues>& watched, std::size_t rank) {
  for (UnfitValues& f : watched) {
    const double v = f.column->get(rank);
    if (std::isnan(v))
      ++f.not_numbers;
    else if (std::nearbyint(v) < 0.0 || std::nearbyint(v) > f.max)
      ++f.outside;
  }
}

// One sentence per field whose values were changed to fit it.
std::vector<std::string> describe_unfit(const std::vector<UnfitValues>& watched) {
  std::vector<std::string> out;
  for (const UnfitValues& f : watched) {
    if (f.outside == 0 && f.not_numbers == 0) continue;
    char limit[32];
    std::snprintf(limit, sizeof limit, "0..%.0f", f.max);
    std::string s = std::string(f.field) + ": ";
    if (f.outside) s += std::to_string(f.outside) + " values outside LAS's " + limit + " were clamped to it";
    if (f.outside && f.not_numbers) s += ", ";
    if (f.not_numbers) s += std::to_string(f.not_numbers) + " values that are not numbers were written as 0";
    out.push_back(std::move(s));
  }
  return out;
}

// One point record per position, in order, written in 64 KiB batches. Counts in
// `report` the values the standard fields could not hold.
void write_records(OutputFile& out, const LasPoints& points, const LasColumns& columns, const RecordLayout& layout,
                   const LasCoordinates& coords, LasReport& report) {
  std::uint64_t clamped_intensities = 0;
  std::vector<UnfitValues> watched = watched_fields(columns);
  std::vector<std::uint8_t> record(layout.length);
  std::string buffer;
  std::size_t rank = 0;
  points.for_each([&](const Point& p) {
    std::fill(record.begin(), record.end(), 0);
    for (int a = 0; a < 3; ++a) put<std::int32_t>(record, 4 * static_cast<std::size_t>(a), coords.integer(p, a));
    put<std::uint16_t>(record, 12, static_cast<std::uint16_t>(field_value(columns.intensity, rank, 65535.0, 0)));
    if (columns.intensity) {
      const double v = columns.intensity->get(rank);
      if (v > 65535.0 || v < 0.0) ++clamped_intensities;  // a PTS file's go down to -2048
    }
    count_unfit(watched, rank);
    const auto [number, count] = returns_of(columns, rank);
    record[14] = static_cast<std::uint8_t>(number | count << 4);
    std::uint32_t flags = field_value(columns.classification_flags, rank, 15.0, 0);
    for (int bit = 0; bit < 4; ++bit)
      if (columns.flag_bits[bit] && field_value(columns.flag_bits[bit], rank, 1.0, 0) != 0) flags |= 1u << bit;
    record[15] = static_cast<std::uint8_t>(flags | field_value(columns.scanner_channel, rank, 3.0, 0) << 4 |
                                           field_value(columns.scan_direction, rank, 1.0, 0) << 6 |
                                           field_value(columns.edge, rank, 1.0, 0) << 7);
    record[16] = static_cast<std::uint8_t>(field_value(columns.classification, rank, 255.0, 0));
    record[17] = static_cast<std::uint8_t>(field_value(columns.user_data, rank, 255.0, 0));
    if (columns.scan_angle) {  // units of 0.006 degrees, within the field's +-180 degrees
      const double angle = columns.scan_angle->get(rank);
      const double units = std::isnan(angle) ? 0.0 : std::clamp(std::nearbyint(angle / 0.006), -30000.0, 30000.0);
      put<std::int16_t>(record, 18, static_cast<std::int16_t>(units));
    }
    put<std::uint16_t>(record, 20, static_cast<std::uint16_t>(field_value(columns.point_source_id, rank, 65535.0, 0)));
    if (columns.gps_time) put<double>(record, 22, columns.gps_time->get(rank));
    if (columns.rgb()) {
      put<std::uint16_t>(record, 30, colour_value(*columns.red, rank));
      put<std::uint16_t>(record, 32, colour_value(*columns.green, rank));
      put<std::uint16_t>(record, 34, colour_value(*columns.blue, rank));
    }
    std::size_t at = layout.base_length;
    for (const auto* c : columns.extra) {
      const std::size_t size = size_of(c->type());
      std::memcpy(record.data() + at, c->bytes().data() + rank * size, size);
      at += size;
    }
    buffer.append(reinterpret_cast<const char*>(record.data()), record.size());
    if (buffer.size() >= (std::size_t{1} << 16)) {
      out.write(buffer);
      buffer.clear();
    }
    ++rank;
  });
  out.write(buffer);
  report.clamped_intensities = clamped_intensities;
  report.unfit_values = describe_unfit(watched);
}

// The points as LAS (or, for a .laz path, LAS records then compressed by translate_las).
LasReport write_points(const LasPoints& points, const LasCoordinates& coords, const std::string& path) {
  const LasColumns columns = sort_columns(*points.attributes);
  LasReport report;
  report.point_format = columns.rgb() ? 7 : 6;
  report.extra_bytes = columns.extra_names;
  report.scale = coords.scale;
  const RecordLayout layout = record_layout(columns);
  const auto vlrs = header_vlrs(points, columns, report);
  const std::vector<std::uint8_t> header = public_header(points, columns, layout, coords, vlrs, report);
  // LAZ: the LAS records first (beside the output, removed whatever happens), then
  // compressed record for record by translate_las.
  const bool laz = las::laz_path(path);
  const std::string las_path = laz ? path + ".records.las" : path;
  struct RemovedFile {
    std::string path;
    ~RemovedFile() {
      if (!path.empty()) std::remove(path.c_str());
    }
  } scratch{laz ? las_path : std::string()};
  OutputFile out(las_path);
  out.write(header.data(), header.size());
  for (const auto& v : vlrs) out.write(v.data(), v.size());
  write_records(out, points, columns, layout, coords, report);
  out.commit();
  if (laz) translate_las(las_path, path);
  return report;
}

}  // namespace

LasReport write_las(const Tree& tree, const std::string& path) {
  require_complete_columns(tree);
  const Quantizer quantizer = tree.quantizer();
  LasPoints points;
  points.count = tree.voxel_count();
  points.voxels = true;
  points.for_each = [&](const std::function<void(const Point&)>& f) {
    tree.for_each_voxel([&](const Voxel& v) { f(quantizer.center(v)); });
  };
  if (!tree.empty()) {  // centres are monotonic in the voxel index: the extreme voxels bound them
    Voxel low{tree.side(), tree.side(), tree.side()}, high{0, 0, 0};
    tree.for_each_voxel([&](const Voxel& v) {
      low = {std::min(low.x, v.x), std::min(low.y, v.y), std::min(low.z, v.z)};
      high = {std::max(high.x, v.x), std::max(high.y, v.y), std::max(high.z, v.z)};
    });
    points.min = quantizer.center(low);
    points.max = quantizer.center(high);
  }
  points.attributes = &tree.attributes();
  points.crs = geo::crs_definition(tree.georef());
  points.crs_wkt = tree.georef().crs_wkt;
  const Frame frame = tree.frame();
  const double extent = frame.voxel_size * static_cast<double>(tree.side());
  return write_points(points, LasCoordinates{choose_scale(frame.voxel_size, extent), frame.origin}, path);
}

LasReport write_las(const PointCloud& cloud, const std::string& path, const std::optional<std::uint32_t>& epsg,
                    const std::string& wkt) {
  Attributes attributes;
  for (const auto& a : cloud.attributes) {
    if (a.values.size() != cloud.size())
      throw InvalidArgument("column " + a.name + " holds " + std::to_string(a.values.size()) + " values for " +
                            std::to_string(cloud.size()) + " points");
    AttributeColumn column(a.name, a.type, a.reduction, cloud.size());
    for (std::size_t i = 0; i < cloud.size(); ++i) column.set(i, a.values[i]);
    attributes.add(std::move(column));
  }
  LasPoints points;
  points.count = cloud.size();
  points.for_each = [&](const std::function<void(const Point&)>& f) {
    for (std::size_t i = 0; i < cloud.size(); ++i) f({cloud.xyz[3 * i], cloud.xyz[3 * i + 1], cloud.xyz[3 * i + 2]});
  };
  const Box box = cloud.bounds();
  points.min = box.min;
  points.max = box.max;
  points.attributes = &attributes;
  if (!wkt.empty()) points.crs = wkt;
  else if (epsg) points.crs = "EPSG:" + std::to_string(*epsg);
  points.crs_wkt = wkt;
  // The finest power of ten that keeps every coordinate, counted from the minimum, in 32 bits.
  double extent = 0.0;
  for (int a = 0; a < 3; ++a) extent = std::max(extent, box.max[a] - box.min[a]);
  const double scale = power_of_ten(static_cast<int>(std::ceil(std::log10(std::max(extent, 1e-9) / 2.0e9))));
  Point offset{};
  for (int a = 0; a < 3; ++a) offset[a] = std::floor(box.min[a] / scale) * scale;
  return write_points(points, LasCoordinates{scale, offset}, path);
}

}  // namespace vola::io
