// vola translate beyond LAS <-> LAZ: any point file vola reads, as points with named
// columns (a PointCloud), written as PLY or XYZ text, point by point in input order. A
// LAS/LAZ/COPC input gives every field of its records: intensity, return number and
// count, classification, user data, point source id, GPS time, colour, scan angle, the
// flags, scanner channel, NIR, wave packets, extra bytes.
#include <algorithm>
#include <charconv>
#include <cmath>
#include <cstring>

#include "export_columns.hpp"
#include "las_format.hpp"
#include "vola/output_file.hpp"
#include "vola/point_selection.hpp"
#include "vola/error.hpp"
#include "vola/io/export.hpp"
#include "vola/io/input.hpp"
#include "vola/io/las.hpp"
#include "vola/io/file_checks.hpp"
#include "vola/io/translate.hpp"

namespace vola::io {

namespace {

// The record fields that LasChunk leaves out (vola convert keeps none of them per
// voxel), as columns after the colour: their names, types and decoding.
class RecordFieldColumns {
 public:
  explicit RecordFieldColumns(const LasHeader& hd) : hd_(hd) {
    const std::uint8_t f = hd.point_format;
    names_ = {"scan_angle_rank", "classification_flags", "scan_direction_flag", "edge_of_flight_line"};
    types_ = {ValueType::f32, ValueType::u8, ValueType::u8, ValueType::u8};
    if (hd.extended_format()) add("scanner_channel", ValueType::u8);
    if (f == 8 || f == 10) add("nir", ValueType::u16);
    // The wave packet: LAS formats 4, 5, 9 and 10 end with it (before any extra bytes).
    if (f == 4 || f == 5 || f >= 9) {
      wave_at_ = f == 4 ? 28 : f == 5 ? 34 : f == 9 ? 30 : 38;
      add("wave_packet_index", ValueType::u8);
      add("wave_offset", ValueType::u64);
      add("wave_packet_size", ValueType::u32);
      add("wave_return_point", ValueType::f32);
      add("wave_dx", ValueType::f32);
      add("wave_dy", ValueType::f32);
      add("wave_dz", ValueType::f32);
    }
  }
  const std::vector<const char*>& names() const { return names_; }
  const std::vector<ValueType>& types() const { return types_; }

  // Appends one value per record to each of `columns` (in names() order).
  void append(std::span<const std::uint8_t> records, std::span<PointAttribute> columns) const {
    const std::size_t length = hd_.record_length;
    const bool extended = hd_.extended_format();
    for (std::size_t at = 0; at + length <= records.size(); at += length) {
      const std::uint8_t* r = records.data() + at;
      std::size_t c = 0;
      const auto put = [&](double v) { columns[c++].values.push_back(v); };
      if (extended) {
        put(load_le<std::int16_t>(r + 18) * 0.006);  // units of 0.006 degrees
        put(r[15] & 15u);                            // synthetic, key-point, withheld, overlap
        put((r[15] >> 6) & 1u);
        put(r[15] >> 7);
        put((r[15] >> 4) & 3u);
      } else {
        put(static_cast<std::int8_t>(r[16]));  // whole degrees
        put(r[15] >> 5);                       // synthetic, key-point, withheld
        put((r[14] >> 6) & 1u);
        put(r[14] >> 7);
      }
      if (hd_.point_format == 8 || hd_.point_format == 10) put(load_le<std::uint16_t>(r + 36));
      if (wave_at_) {
        const std::uint8_t* w = r + wave_at_;
        put(w[0]);
        put(static_cast<double>(load_le<std::uint64_t>(w + 1)));
        put(load_le<std::uint32_t>(w + 9));
        for (int k = 0; k < 4; ++k) put(load_le<float>(w + 13 + 4 * k));
      }
    }
  }

 private:
  void add(const char* name, ValueType type) {
    names_.push_back(name);
    types_.push_back(type);
  }
  const LasHeader& hd_;
  std::vector<const char*> names_;
  std::vector<ValueType> types_;
  std::size_t wave_at_ = 0;
};

}  // namespace

// The columns of a LAS file's records, in record order (a chunk of them at a time).
PointCloud las_columns(const LasHeader& hd) {
  PointCloud cloud;
  const auto add = [&](const char* name, ValueType type) { cloud.attributes.push_back({name, type, Reduction::last, {}}); };
  add("intensity", ValueType::u16);
  add("return_number", ValueType::u8);
  add("number_of_returns", ValueType::u8);
  add("classification", ValueType::u8);
  add("user_data", ValueType::u8);
  add("point_source_id", ValueType::u16);
  if (hd.has_gps_time()) add("gps_time", ValueType::f64);
  if (hd.has_rgb()) {
    add("red", ValueType::u16);
    add("green", ValueType::u16);
    add("blue", ValueType::u16);
  }
  const RecordFieldColumns fields(hd);
  for (std::size_t k = 0; k < fields.names().size(); ++k) add(fields.names()[k], fields.types()[k]);
  for (const auto& f : hd.extra_fields) cloud.attributes.push_back({f.name, ValueType::f64, Reduction::last, {}});
  return cloud;
}

void for_each_las_chunk(LasReader& reader, const std::function<void(const PointCloud&)>& each,
                        const std::function<void(std::uint64_t, std::uint64_t)>& progress) {
  const LasHeader& hd = reader.header();
  PointCloud cloud = las_columns(hd);
  const RecordFieldColumns fields(hd);
  const std::size_t fields_at = cloud.attributes.size() - fields.names().size() - hd.extra_fields.size();
  LasChunk chunk;
  for (;;) {
    const std::span<const std::uint8_t> records = reader.read_records(std::size_t{1} << 16);
    if (records.empty()) break;
    chunk.clear();
    decode_las_records(hd, records, chunk);
    cloud.xyz.assign(chunk.xyz.begin(), chunk.xyz.end());
    for (auto& a : cloud.attributes) a.values.clear();
    std::size_t c = 0;
    const auto append = [&](const auto& values) {
      auto& column = cloud.attributes[c++].values;
      column.insert(column.end(), values.begin(), values.end());
    };
    append(chunk.intensity);
    append(chunk.return_number);
    append(chunk.number_of_returns);
    append(chunk.classification);
    append(chunk.user_data);
    append(chunk.point_source_id);
    if (hd.has_gps_time()) append(chunk.gps_time);
    if (hd.has_rgb()) {
      append(chunk.red);
      append(chunk.green);
      append(chunk.blue);
    }
    fields.append(records, std::span(cloud.attributes).subspan(fields_at, fields.names().size()));
    c += fields.names().size();
    for (const auto& e : chunk.extra) append(e);
    each(cloud);
    if (progress) progress(reader.points_read(), reader.points_total());
  }
}

namespace {

PointTable las_point_table(const std::string& path, const std::function<void(std::uint64_t, std::uint64_t)>& progress) {
  LasReader reader(path);
  const LasHeader& hd = reader.header();
  PointTable table;
  table.format = "las";
  table.epsg = hd.epsg;
  table.wkt = hd.wkt;
  table.coordinate_digits = hd.coordinate_decimals();  // the file's own precision
  table.cloud = las_columns(hd);
  table.record_fields = table.cloud.attributes.size() - hd.extra_fields.size();
  for_each_las_chunk(
      reader,
      [&](const PointCloud& chunk) {
        table.cloud.xyz.insert(table.cloud.xyz.end(), chunk.xyz.begin(), chunk.xyz.end());
        for (std::size_t c = 0; c < chunk.attributes.size(); ++c) {
          auto& column = table.cloud.attributes[c].values;
          column.insert(column.end(), chunk.attributes[c].values.begin(), chunk.attributes[c].values.end());
        }
      },
      progress);
  return table;
}

std::vector<std::string> column_names(const PointCloud& cloud) {
  std::vector<std::string> names;
  for (const auto& a : cloud.attributes) names.push_back(a.name);
  return token_names(names, {"x", "y", "z"});
}

// One value in the column's PLY type (64-bit integers as double, which PLY has instead).
void append_binary(std::string& out, ValueType type, double v) {
  if (type == ValueType::u64 || type == ValueType::i64) type = ValueType::f64;
  std::byte bytes[8];
  store_value(type, v, bytes);
  out.append(reinterpret_cast<const char*>(bytes), size_of(type));
}

// The PLY type of each column. 16-bit colour columns whose values all fit in 8 bits (as
// in many LAS files, and colours read from text) are uchar, what PLY readers expect of
// colours, as vola export writes them.
std::vector<ValueType> ply_column_types(const PointCloud& cloud) {
  const auto colour = [](const PointAttribute& a) { return a.name == "red" || a.name == "green" || a.name == "blue"; };
  bool wide_colours = false;
  for (const auto& a : cloud.attributes)
    if (colour(a) && a.type == ValueType::u16)
      wide_colours = wide_colours || std::any_of(a.values.begin(), a.values.end(), [](double v) { return v > 255; });
  std::vector<ValueType> types;
  for (const auto& a : cloud.attributes)
    types.push_back(colour(a) && a.type == ValueType::u16 && !wide_colours ? ValueType::u8 : a.type);
  return types;
}

void write_ply_points(const PointCloud& cloud, const std::string& path) {
  const auto names = column_names(cloud);
  const std::vector<ValueType> types = ply_column_types(cloud);
  std::string header = "ply\nformat binary_little_endian 1.0\ncomment written by vola translate\nelement vertex " +
                       std::to_string(cloud.size()) + "\nproperty double x\nproperty double y\nproperty double z\n";
  for (std::size_t c = 0; c < names.size(); ++c)
    header += std::string("property ") + ply_type(types[c]) + " " + names[c] + "\n";
  header += "end_header\n";
  OutputFile out(path);
  out.write(header);
  std::string buffer;
  for (std::size_t i = 0; i < cloud.size(); ++i) {
    buffer.append(reinterpret_cast<const char*>(&cloud.xyz[3 * i]), 3 * sizeof(double));
    for (std::size_t c = 0; c < cloud.attributes.size(); ++c)
      append_binary(buffer, types[c], cloud.attributes[c].values[i]);
    if (buffer.size() >= (std::size_t{1} << 16)) {
      out.write(buffer);
      buffer.clear();
    }
  }
  out.write(buffer);
  out.commit();
}

// `digits` decimals (the file's own precision), or the shortest text that reads back as v
// when there are none or v is too large for fixed notation in 64 characters (a LAS offset
// of 1e62 made one; the shortest text of a double always fits).
void append_fixed(std::string& out, double v, int digits) {
  char s[64];
  if (digits >= 0) {
    const auto r = std::to_chars(s, s + sizeof s, v, std::chars_format::fixed, digits);
    if (r.ec == std::errc()) {
      out.append(s, r.ptr);
      return;
    }
  }
  out.append(s, std::to_chars(s, s + sizeof s, v).ptr);
}

// The LAS flag bits (classification_flags: synthetic, key-point, withheld, overlap) as
// PDAL's dimensions of the same names, one 0/1 column each: CSV is read by PDAL's
// readers.text, and PDAL's LAS writer takes the flags from these (its ClassFlags is
// deprecated and ignored), so a CSV of a LAS file goes back to LAS with them.
constexpr const char* kFlagBitNames[] = {"synthetic", "key_point", "withheld", "overlap"};

// vola's XYZ ("# x y z ..." and spaces) or CSV (PDAL's quoted header and commas).
void write_text_points(const PointCloud& cloud, const std::string& path, int coordinate_digits, bool csv) {
  struct Column {
    const std::vector<double>* values;
    int bit;  // >= 0: that bit of the values, 0 or 1
  };
  std::vector<std::string> names;
  std::vector<Column> columns;
  for (const auto& a : cloud.attributes) {
    if (csv && a.name == "classification_flags") {
      for (int bit = 0; bit < 4; ++bit) {
        names.push_back(kFlagBitNames[bit]);
        columns.push_back({&a.values, bit});
      }
      continue;
    }
    names.push_back(a.name);
    columns.push_back({&a.values, -1});
  }
  std::string line = text_header(token_names(names, {"x", "y", "z"}), csv);
  const char separator = csv ? ',' : ' ';
  OutputFile out(path);
  for (std::size_t i = 0; i < cloud.size(); ++i) {
    for (int a = 0; a < 3; ++a) {
      if (a) line += separator;
      append_fixed(line, cloud.xyz[3 * i + static_cast<std::size_t>(a)], coordinate_digits);
    }
    for (const Column& c : columns) {
      line += separator;
      const double v = (*c.values)[i];
      if (c.bit < 0)
        append_number(line, v);
      else
        line += v >= 0 && v <= 255 && (static_cast<std::uint32_t>(v) >> c.bit) & 1u ? '1' : '0';  // NaN: 0
    }
    line += '\n';
    if (line.size() >= (std::size_t{1} << 16)) {
      out.write(line);
      line.clear();
    }
  }
  out.write(line);
  out.commit();
}

}  // namespace

PointTable read_point_table(const std::string& input, const std::function<void(std::uint64_t, std::uint64_t)>& progress,
                            const std::string& format) {
  refuse_unopenable_input(input);
  if (find_input_format(input, format).name == "las") return las_point_table(input, progress);
  InputOptions options;
  options.attributes = true;
  options.progress = progress;
  Input in = read_input(input, format, options);
  if (in.is_mesh() || in.grid || in.terrain)
    throw InvalidArgument(input + ": point filters and vola translate take point files; this " + in.format +
                          " file holds " +
                          (in.is_mesh() ? "a mesh of " + std::to_string(in.triangles.size()) + (in.triangles.size() == 1 ? " face" : " faces")
                           : in.grid    ? std::string("a voxel grid")
                                        : std::string("an elevation raster")) +
                          ": `vola convert` makes voxels of it");
  PointTable table;
  table.format = in.format;
  table.cloud = std::move(in.cloud);
  table.epsg = in.epsg;
  table.wkt = std::move(in.wkt);
  table.not_finite = in.not_finite;
  return table;
}

namespace {

// LAS stores coordinates as integers: a point with a NaN or infinite coordinate (text
// and PLY files hold them) has no record. Left out, and said.
void drop_points_las_cannot_hold(const std::string& input, PointCloud& cloud, std::vector<std::string>& warnings) {
  std::vector<bool> finite(cloud.size(), true);
  std::uint64_t dropped = 0;
  for (std::size_t i = 0; i < cloud.size(); ++i)
    if (!std::isfinite(cloud.xyz[3 * i]) || !std::isfinite(cloud.xyz[3 * i + 1]) || !std::isfinite(cloud.xyz[3 * i + 2])) {
      finite[i] = false;
      ++dropped;
    }
  if (dropped == 0) return;
  keep_points(cloud, finite);
  warnings.push_back(input + ": " + std::to_string(dropped) +
                     " points with a coordinate that is not finite are left out: LAS has no record for them");
}

}  // namespace

std::vector<std::string> translate_points(const std::string& input, const std::string& output,
                                          const std::function<void(std::uint64_t, std::uint64_t)>& progress,
                                          const PointEdit& edit, const std::string& format) {
  refuse_output_over_input(input, output, "vola translate writes a new point file; give it another name");
  refuse_unopenable_input(input);
  const std::string out_ext = lower_extension(output);
  const bool las_in = find_input_format(input, format).name == "las";
  const bool las_out = out_ext == ".las" || out_ext == ".laz";
  const bool csv = out_ext == ".csv";
  if (!las_out && !csv && out_ext != ".ply" && out_ext != ".xyz" && out_ext != ".txt")
    throw InvalidArgument(output + ": vola translate writes .las, .laz, .ply, .xyz (or .txt) and .csv");
  if (las_out && las_in && !edit) {
    translate_las(input, output, progress);
    return {};
  }
  PointTable table = read_point_table(input, progress, format);
  if (edit) {
    std::vector<std::string> read_columns;
    for (const PointAttribute& a : table.cloud.attributes) read_columns.push_back(a.name);
    const std::vector<std::uint64_t> kept = edit(table);
    if (las_out && las_in) {
      translate_las(input, output, progress, LasRecordEdits{kept, table.cloud});
      // LAS to LAS copies the records, their classification edited: a column the filters
      // added (hag's height_above_ground) has no field there, and was dropped without a word.
      std::string added;
      for (const PointAttribute& a : table.cloud.attributes)
        if (std::find(read_columns.begin(), read_columns.end(), a.name) == read_columns.end())
          added += (added.empty() ? "" : ", ") + a.name;
      if (added.empty()) return {};
      return {output + ": " + added + ", which the filters added, is not written: LAS to LAS keeps the input's " +
              "records and their fields; write .ply, .xyz or .csv to keep it, or use it in the same command (--where)"};
    }
  }
  std::vector<std::string> warnings;
  if (table.not_finite > 0)
    warnings.push_back(input + ": " + std::to_string(table.not_finite) +
                       (table.format == "e57" || table.format == "ptx"
                            ? " points the scanner marked as no return or invalid"
                            : " points with a coordinate that is not finite") +
                       " (an organized cloud's missing points) are not read, so not written");
  if (las_out) drop_points_las_cannot_hold(input, table.cloud, warnings);
  if (!las_out && (table.epsg || !table.wkt.empty()))
    warnings.push_back(output + ": " +
                       (out_ext == ".ply" ? "PLY"
                        : csv             ? "CSV"
                                          : "XYZ") +
                       " has no place for the CRS of " + input + " (" +
                       (table.epsg ? "EPSG:" + std::to_string(*table.epsg) : "a WKT with no EPSG code") +
                       "): it is not kept; a .las or .laz output keeps it");
  if (out_ext == ".ply") write_ply_points(table.cloud, output);
  else if (las_out) {
    const LasReport r = write_las(table.cloud, output, table.epsg, table.wkt);
    for (const std::string& unfit : r.unfit_values) warnings.push_back(output + ": " + unfit);
  } else
    write_text_points(table.cloud, output, table.coordinate_digits, csv);
  return warnings;
}

}  // namespace vola::io
