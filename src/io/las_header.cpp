// LasReader::read_header: the public header block, the VLRs and EVLRs, the CRS (GeoTIFF
// keys or WKT) and the extra-bytes fields, each checked against the file's size before
// anything is allocated for it.
#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstring>
#include <functional>
#include <optional>

#include "column_names.hpp"
#include "content_kind.hpp"
#include "las_format.hpp"
#include "reader_plugin.hpp"
#include "vola/error.hpp"
#include "vola/geo/crs.hpp"
#include "vola/io/las.hpp"

namespace vola::io {

namespace {

using las::text;

// The file's bytes as the header parser reads them: bounds-checked, errors with offsets.
struct HeaderSource {
  const std::string& path;
  std::uint64_t file_size;
  std::function<void(std::uint64_t, std::uint64_t, std::uint8_t*)> fetch;

  [[noreturn]] void fail(std::uint64_t offset, const std::string& cause) const { throw FormatError(path, offset, cause); }

  std::vector<std::uint8_t> read_at(std::uint64_t offset, std::uint64_t size, const char* what) const {
    if (offset > file_size || size > file_size - offset)
      fail(offset, std::string(what) + " of " + std::to_string(size) + " bytes runs past the end of the " +
                       std::to_string(file_size) + "-byte file");
    std::vector<std::uint8_t> bytes(size);
    try {
      fetch(offset, size, bytes.data());
    } catch (const FormatError&) {
      fail(offset, std::string("cannot read ") + what);
    }
    return bytes;
  }
};

// What the public header block says about the records that follow it.
struct HeaderCounts {
  std::uint32_t vlr_count = 0;
  std::uint8_t raw_format = 0;  // with the LAZ bits
  std::uint64_t evlr_start = 0;
  std::uint32_t evlr_count = 0;
};

const char* not_a_number(double v) {
  return std::isnan(v) ? "NaN" : std::isinf(v) ? "infinite" : v == 0.0 ? "0" : nullptr;
}

// A coordinate is offset + scale * integer: a NaN, infinite or zero scale (or a NaN or
// infinite offset) makes every point NaN or the same, which the builders then drop or
// pile up silently. Refused here, where the file and the field's offset are known.
void check_scale_and_offset(const HeaderSource& src, const LasHeader& hd, int a) {
  const char axis = static_cast<char>('x' + a);
  if (const char* what = not_a_number(hd.scale[a]))
    src.fail(131 + 8 * static_cast<std::uint64_t>(a), std::string(1, axis) + " scale is " + what);
  if (const char* what = not_a_number(hd.offset[a]); what && hd.offset[a] != 0.0)
    src.fail(155 + 8 * static_cast<std::uint64_t>(a), std::string(1, axis) + " offset is " + what);
}

HeaderCounts parse_public_block(const HeaderSource& src, LasHeader& hd) {
  if (src.file_size < 227)
    src.fail(src.file_size, "a LAS file has at least a 227-byte header; this file has " + std::to_string(src.file_size) +
                                " bytes");
  const auto h = src.read_at(0, std::min<std::uint64_t>(src.file_size, 375), "header");
  if (std::memcmp(h.data(), "LASF", 4) != 0)
    src.fail(0, "not a LAS file (no LASF signature)" + content_kind_note(std::span<const std::uint8_t>(h).first(16)));
  hd.global_encoding = load_le<std::uint16_t>(&h[6]);
  hd.version_major = h[24];
  hd.version_minor = h[25];
  if (hd.version_major != 1 || hd.version_minor > 4)
    src.fail(24, "LAS version " + hd.version() + " is not known (1.0 to 1.4)");
  hd.system_identifier = text(&h[26], 32);
  hd.generating_software = text(&h[58], 32);
  hd.header_size = load_le<std::uint16_t>(&h[94]);
  hd.offset_to_points = load_le<std::uint32_t>(&h[96]);
  HeaderCounts counts;
  counts.vlr_count = load_le<std::uint32_t>(&h[100]);
  counts.raw_format = h[104];
  hd.record_length = load_le<std::uint16_t>(&h[105]);
  for (int a = 0; a < 3; ++a) {
    hd.scale[a] = load_le<double>(&h[131 + 8 * a]);
    hd.offset[a] = load_le<double>(&h[155 + 8 * a]);
    hd.max[a] = load_le<double>(&h[179 + 16 * a]);
    hd.min[a] = load_le<double>(&h[187 + 16 * a]);
    check_scale_and_offset(src, hd, a);
  }
  const std::uint16_t min_header = hd.version_minor >= 4 ? 375 : hd.version_minor == 3 ? 235 : 227;
  if (hd.header_size < min_header || hd.header_size > src.file_size)
    src.fail(94, "header size " + std::to_string(hd.header_size) + " does not fit LAS " + hd.version() +
                     " (at least " + std::to_string(min_header) + ") or the file");
  hd.point_count = load_le<std::uint32_t>(&h[107]);
  if (hd.version_minor >= 4) {
    counts.evlr_start = load_le<std::uint64_t>(&h[235]);
    counts.evlr_count = load_le<std::uint32_t>(&h[243]);
    const std::uint64_t count64 = load_le<std::uint64_t>(&h[247]);
    if (count64 != 0) hd.point_count = count64;
  }
  return counts;
}

// The VLRs after the header; returns the offset just past them.
std::uint64_t read_vlrs(const HeaderSource& src, LasHeader& hd, std::uint32_t count) {
  std::uint64_t at = hd.header_size;
  for (std::uint32_t i = 0; i < count; ++i) {
    // A count too high would read the points as VLRs: name the two fields that disagree.
    if (at + 54 > hd.offset_to_points)
      src.fail(100, "the " + std::to_string(count) + " VLRs the header counts (byte 100) do not fit before the " +
                        "offset to point data " + std::to_string(hd.offset_to_points) + " (byte 96); " +
                        std::to_string(i) + " of them end before it: the VLR count or the offset is wrong");
    const auto v = src.read_at(at, 54, "VLR header");
    LasVlr vlr;
    vlr.user_id = text(&v[2], 16);
    vlr.record_id = load_le<std::uint16_t>(&v[18]);
    vlr.description = text(&v[22], 32);
    vlr.offset = at + 54;
    const std::uint16_t length = load_le<std::uint16_t>(&v[20]);
    vlr.length = length;
    vlr.data = src.read_at(at + 54, length, "VLR data");
    hd.vlrs.push_back(std::move(vlr));
    at += 54 + length;
  }
  return at;
}

// The point format and record layout, checked against the format and the file.
void check_point_layout(const HeaderSource& src, LasHeader& hd, std::uint8_t raw_format, std::uint64_t vlrs_end) {
  const auto laszip = std::find_if(hd.vlrs.begin(), hd.vlrs.end(),
                                   [](const LasVlr& v) { return v.user_id == "laszip encoded" && v.record_id == 22204; });
  // LAZ: bit 7 (6 in LAZ 1.x) marks compressed records. A laszip VLR left in a file whose
  // bit is clear (a tool decompressed it and kept the VLR) does not make it LAZ when the
  // file holds every record uncompressed, as LASzip and laspy read it.
  const bool left_over_vlr = !(raw_format & 0xC0) && laszip != hd.vlrs.end() && hd.record_length > 0 &&
                             hd.offset_to_points <= src.file_size &&
                             hd.point_count <= (src.file_size - hd.offset_to_points) / hd.record_length;
  if (raw_format & 0xC0 || (laszip != hd.vlrs.end() && !left_over_vlr)) {
    if (laszip == hd.vlrs.end())
      src.fail(104, "the point format says the records are compressed (LAZ) but there is no laszip VLR "
                    "(user \"laszip encoded\", record 22204)");
    hd.laszip = laz::parse_laszip_vlr(laszip->data, src.path, laszip->offset);
    if (hd.laszip->record_length() != hd.record_length)
      src.fail(105, "record length " + std::to_string(hd.record_length) + " differs from the " +
                        std::to_string(hd.laszip->record_length()) + " bytes of the laszip VLR's items");
  }
  hd.point_format = raw_format & 0x3F;
  if (hd.point_format > 10)
    src.fail(104, "point data record format " + std::to_string(hd.point_format) + " is not known (0..10)");
  if (hd.record_length < las::kMinRecordLength[hd.point_format])
    src.fail(105, "record length " + std::to_string(hd.record_length) + " is shorter than format " +
                      std::to_string(hd.point_format) + " needs (" +
                      std::to_string(las::kMinRecordLength[hd.point_format]) + ")");
  if (hd.offset_to_points > src.file_size)
    src.fail(96, "offset to point data " + std::to_string(hd.offset_to_points) + " is past the end of the " +
                     std::to_string(src.file_size) + "-byte file");
  if (hd.offset_to_points < vlrs_end) {
    // Either field may lie: say how many of the counted VLRs end before the points.
    std::size_t fit = 0;
    while (fit < hd.vlrs.size() && hd.vlrs[fit].offset + hd.vlrs[fit].length <= hd.offset_to_points) ++fit;
    src.fail(fit < hd.vlrs.size() ? 100 : 96,
             "the " + std::to_string(hd.vlrs.size()) + " VLRs the header counts (byte 100) end at byte " +
                 std::to_string(vlrs_end) + ", past the offset to point data " + std::to_string(hd.offset_to_points) +
                 " (byte 96); " + std::to_string(fit) + " of them end before it: the VLR count or the offset is wrong");
  }
}

// The EVLRs (LAS 1.4). Waveform data can be huge and is not needed: only the records
// that describe the points are kept.
void read_evlrs(const HeaderSource& src, LasHeader& hd, std::uint64_t at, std::uint32_t count) {
  for (std::uint32_t i = 0; i < count; ++i) {
    const auto v = src.read_at(at, 60, "EVLR header");
    LasVlr vlr;
    vlr.extended = true;
    vlr.user_id = text(&v[2], 16);
    vlr.record_id = load_le<std::uint16_t>(&v[18]);
    vlr.description = text(&v[28], 32);
    const std::uint64_t length = load_le<std::uint64_t>(&v[20]);
    vlr.offset = at + 60;
    vlr.length = length;
    // Only the records the header is read from are loaded: the CRS and the extra-bytes
    // descriptors. Waveform data (LASF_Spec 65535) runs to gigabytes, and the others are
    // copied from the file where they lie.
    const bool described = (vlr.user_id == "LASF_Projection" &&
                            (vlr.record_id == 2112 || (vlr.record_id >= 34735 && vlr.record_id <= 34737))) ||
                           (vlr.user_id == "LASF_Spec" && vlr.record_id == 4);
    if (described)
      vlr.data = src.read_at(at + 60, length, "EVLR data");
    else if (length > src.file_size - std::min(src.file_size, at + 60))
      src.fail(at + 20, "EVLR length runs past the end of the file");
    hd.vlrs.push_back(std::move(vlr));
    at += 60 + length;
  }
}

// The unit keys of a GeoKeyDirectory, which may qualify its projected CRS code.
struct UnitKeys {
  std::uint32_t linear = 0;    // ProjLinearUnitsGeoKey
  std::uint32_t vertical = 0;  // VerticalUnitsGeoKey, when no VerticalCSTypeGeoKey names a vertical CRS
  // The CRS is defined by its parts, not by a code: a user-defined (32767) projected CRS
  // (its geographic code, if any, is only its base), or a model type that says projected
  // or geocentric with no projected code, or a user-defined geographic CRS with no
  // projected one.
  bool user_defined = false;
};

// GeoKeyDirectoryTag: the projected CRS code, else the geographic one (none when
// user-defined), and the unit keys.
void parse_geokeys(const LasVlr& vlr, LasHeader& hd, UnitKeys& units) {
  const std::size_t keys = load_le<std::uint16_t>(&vlr.data[6]);
  std::optional<std::uint32_t> projected, geographic, model;
  bool vertical_crs = false;
  for (std::size_t k = 0; k < keys && 8 + 8 * k + 8 <= vlr.data.size(); ++k) {
    const std::uint8_t* e = &vlr.data[8 + 8 * k];
    const std::uint16_t id = load_le<std::uint16_t>(e), location = load_le<std::uint16_t>(e + 2);
    const std::uint16_t value = load_le<std::uint16_t>(e + 6);
    if (location != 0) continue;
    if (id == 1024) model = value;
    if (id == 3072) projected = value;
    if (id == 2048) geographic = value;
    if (id == 3076) units.linear = value;
    if (id == 4099) units.vertical = value;
    if (id == 4096 && value != 0 && value != las::kUserDefined) vertical_crs = true;
  }
  // A named vertical CRS has a unit of its own; GDAL then reads no vertical part at all
  // by default, and neither does vola (heights in the unit of x and y).
  if (vertical_crs) units.vertical = 0;
  // A code of 0 is no code (GDAL reads it so).
  const auto coded = [](const std::optional<std::uint32_t>& v) { return v && *v != las::kUserDefined && *v != 0; };
  // A geocentric model (3) on a geographic code is that datum's geocentric CRS, not the
  // geographic one: GDAL builds it from the keys (PDAL's lone-star.laz, EPSG:4326 keys on
  // earth-centred coordinates).
  units.user_defined = !coded(projected) && (projected == las::kUserDefined || model == 1u || model == 3u ||
                                             (!coded(geographic) && geographic == las::kUserDefined));
  if (units.user_defined) return;
  if (coded(projected)) hd.epsg = *projected;
  else if (coded(geographic)) hd.epsg = *geographic;
}

// A key directory that defines its CRS by its parts, read as GDAL reads it (the gdal
// plugin, src/io/plugins/geokeys_gdal.cpp). Like a unit-qualified code, it becomes the
// header's WKT (unless a WKT record wins) and the code PROJ identifies it as, or none.
// Without GDAL's reading (GDAL reads no CRS from the keys, or cannot be loaded) the file
// states none: never the base geographic code of projected coordinates.
void apply_user_defined_keys(LasHeader& hd, const UnitKeys& units) {
  if (!units.user_defined || !hd.wkt.empty()) return;
  plugin::GeoKeyRecords records;
  for (const auto& vlr : hd.vlrs) {
    if (vlr.user_id != "LASF_Projection") continue;
    if (vlr.record_id == 34735 && records.directory.empty()) records.directory = vlr.data;
    if (vlr.record_id == 34736 && records.doubles.empty()) records.doubles = vlr.data;
    if (vlr.record_id == 34737 && records.ascii.empty()) records.ascii = vlr.data;
  }
  try {
    const auto entry = reinterpret_cast<plugin::GeokeysWktEntry>(
        vola::plugin::plugin_symbol("gdal", plugin::kGeokeysWktSymbol, "reading the user-defined GeoTIFF keys"));
    std::string wkt;
    PluginFailure failure;
    entry(records, wkt, failure);
    vola::plugin::throw_failure(failure);
    if (wkt.empty()) return;
    hd.epsg = geo::epsg_from_wkt(wkt);
    hd.wkt = std::move(wkt);
  } catch (const Error&) {
    // GDAL or PROJ cannot be loaded: no CRS, as for keys GDAL cannot read.
  }
}

// A projected CRS code whose unit keys say more than the code (geo::keyed_projected_crs:
// pdal_mvk-thin.las is EPSG:26995, a metre CRS, in US survey feet) is the CRS GDAL and
// PDAL read from them. It becomes the header's WKT (unless the file has a WKT record,
// which wins), and the header's code is what PROJ identifies it as, or none.
void apply_unit_keys(LasHeader& hd, const UnitKeys& units) {
  if (!hd.epsg || !hd.wkt.empty() || (units.linear == 0 && units.vertical == 0)) return;
  try {
    std::string wkt = geo::keyed_projected_crs(*hd.epsg, units.linear, units.vertical);
    if (wkt.empty()) return;
    const auto code = geo::epsg_from_wkt(wkt);  // both or neither: never the feet WKT with the metre code
    hd.wkt = std::move(wkt);
    hd.epsg = code;
  } catch (const Error&) {
    // PROJ cannot be loaded: the code alone, as before the unit keys were read.
  }
}

// The extra-bytes VLR: one field per value after the point format's own bytes.
void parse_extra_bytes(const HeaderSource& src, const LasVlr& vlr, LasHeader& hd) {
  std::uint32_t offset = las::kMinRecordLength[hd.point_format];
  for (std::size_t d = 0; d + 192 <= vlr.data.size(); d += 192) {
    const std::uint8_t* e = &vlr.data[d];
    const std::uint8_t type = e[2], options = e[3];
    const std::string name = utf8_name(text(e + 4, 32));
    if (type == 0) {  // undocumented bytes: options holds their count
      offset += options;
      continue;
    }
    // Types 11..30 (LAS 1.4 R13, deprecated since) are arrays of 2 or 3 values of
    // type ((t - 1) % 10) + 1; each element becomes its own field.
    if (type > 30)
      src.fail(vlr.offset + d + 2, "extra bytes field '" + name + "' has unknown data type " + std::to_string(type));
    const auto base = static_cast<std::uint8_t>((type - 1) % 10 + 1);
    const int count = (type - 1) / 10 + 1;
    for (int k = 0; k < count; ++k) {
      LasExtraField f;
      f.name = count == 1 ? name : name + "_" + std::to_string(k);
      f.data_type = base;
      f.size = static_cast<std::uint32_t>(las::extra_size(base));
      f.offset = offset;
      // no_data, min and max are "anytype" unions: 8 bytes of u64, i64 or double by type.
      if (options & 1)
        f.no_data = base >= 9       ? load_le<double>(e + 40 + 8 * k)
                    : base % 2 == 1 ? static_cast<double>(load_le<std::uint64_t>(e + 40 + 8 * k))
                                    : static_cast<double>(load_le<std::int64_t>(e + 40 + 8 * k));
      if (options & 8) f.scale = load_le<double>(e + 112 + 8 * k);
      if (options & 16) f.add = load_le<double>(e + 136 + 8 * k);
      hd.extra_fields.push_back(f);
      offset += f.size;
    }
  }
  if (offset > hd.record_length)
    src.fail(vlr.offset, "extra bytes fields need " + std::to_string(offset) + " bytes per record, records have " +
                             std::to_string(hd.record_length));
}

// A name as the point filters match it: lower case, without '_', spaces and bytes outside
// printable ASCII (which the text and PLY writers turn into '_').
std::string name_key(const std::string& name) {
  std::string key;
  for (const char c : name)
    if (c != '_' && c > ' ' && c <= '~') key += static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return key;
}

// Extra-bytes fields named like a field of the record, like each other or not at all
// (the specification forbids none of these, and writers do all three) get names of their
// own, as the text writers would make them: "classification_2", "a_2", "attribute". So
// every command, filter and report sees one column per field under one name (PDAL's names
// of record fields count too: an extra "Withheld" hid the flag bit from --where). Only the
// fields this point format has are taken: an extra "nir" of a format 6 file (vola's own
// LAS of a cloud with an infrared column) keeps its name. The first "height" stays:
// vola's LAS export writes the voxels' mean z under that name, read back as the height
// column.
void give_extra_fields_unique_names(LasHeader& hd) {
  // clang-format off
  std::vector<std::string> taken = {
      "x", "y", "z", "intensity", "return_number", "number_of_returns", "classification", "user_data",
      "point_source_id", "scan_angle_rank", "scan_angle", "classification_flags", "scan_direction_flag",
      "edge_of_flight_line",
      // PDAL's names of the classification flag bits, which --where takes too.
      "synthetic", "keypoint", "withheld", "overlap", "classflags"};
  // clang-format on
  const int format = hd.point_format;
  if (format != 0 && format != 2) taken.push_back("gps_time");
  if (format == 2 || format == 3 || format == 5 || format == 7 || format == 8 || format == 10)
    taken.insert(taken.end(), {"red", "green", "blue"});
  if (format == 8 || format == 10) taken.insert(taken.end(), {"nir", "infrared"});
  if (format >= 6) taken.insert(taken.end(), {"scanner_channel", "scan_channel"});
  if (format == 4 || format == 5 || format >= 9)
    taken.insert(taken.end(), {"wave_packet_index", "wave_offset", "wave_packet_size", "wave_return_point", "wave_dx",
                               "wave_dy", "wave_dz"});
  for (auto& key : taken) key = name_key(key);
  bool height_kept = false;
  for (LasExtraField& f : hd.extra_fields) {
    if (f.name == "height" && !height_kept) {
      height_kept = true;
      taken.push_back("height");
      continue;
    }
    const std::string base = name_key(f.name).empty() ? "attribute" : f.name;
    std::string unique = base;
    for (int n = 2; std::find(taken.begin(), taken.end(), name_key(unique)) != taken.end(); ++n)
      unique = base + "_" + std::to_string(n);
    taken.push_back(name_key(unique));
    f.name = std::move(unique);
  }
}

// The CRS (GeoKeys, WKT) and the extra-bytes fields, from the (E)VLRs read.
//
// A file holding both GeoTIFF keys and a WKT record states one CRS: in LAS 1.4 the one
// global encoding bit 4 names (set: the WKT, clear: the keys), before 1.4 (no such bit)
// the WKT record, as before. The other is not read, so the header's code and WKT never
// come from two different CRSs (a WKT record gives no code, as when it is alone).
void parse_crs_and_fields(const HeaderSource& src, LasHeader& hd) {
  const auto is_keys = [](const LasVlr& v) {
    return v.user_id == "LASF_Projection" && v.record_id == 34735 && v.data.size() >= 8;
  };
  const auto is_wkt = [](const LasVlr& v) { return v.user_id == "LASF_Projection" && v.record_id == 2112; };
  const bool has_keys = std::any_of(hd.vlrs.begin(), hd.vlrs.end(), is_keys);
  const bool has_wkt = std::any_of(hd.vlrs.begin(), hd.vlrs.end(), is_wkt);
  const bool wkt_bit_clear = hd.version_major == 1 && hd.version_minor >= 4 && !(hd.global_encoding & 16);
  const bool use_keys = has_keys && !(has_wkt && !wkt_bit_clear);
  UnitKeys units;
  bool keys_read = false;  // the first key directory counts, as for GDAL's reading of it
  for (const auto& vlr : hd.vlrs) {
    if (is_keys(vlr) && use_keys && !keys_read) {
      parse_geokeys(vlr, hd, units);
      keys_read = true;
    } else if (is_wkt(vlr) && !use_keys)
      hd.wkt = text(vlr.data.data(), vlr.data.size());
    else if (vlr.user_id == "LASF_Spec" && vlr.record_id == 4) parse_extra_bytes(src, vlr, hd);
  }
  apply_unit_keys(hd, units);
  apply_user_defined_keys(hd, units);
  give_extra_fields_unique_names(hd);
}

}  // namespace

void LasReader::read_header() {
  const HeaderSource src{path_, file_size_,
                         [this](std::uint64_t offset, std::uint64_t size, std::uint8_t* out) { fetch(offset, size, out); }};
  LasHeader& hd = header_;
  const HeaderCounts counts = parse_public_block(src, hd);
  const std::uint64_t vlrs_end = read_vlrs(src, hd, counts.vlr_count);
  check_point_layout(src, hd, counts.raw_format, vlrs_end);
  read_evlrs(src, hd, counts.evlr_start, counts.evlr_count);
  if (hd.compressed()) {
    hd.laz_chunks = laz::read_chunk_table(
        *hd.laszip, [this](std::uint64_t offset, std::uint64_t size, std::uint8_t* out) { fetch(offset, size, out); },
        file_size_, hd.offset_to_points, hd.point_count, path_);
    hd.copc = read_copc_hierarchy(
        hd, [this](std::uint64_t offset, std::uint64_t size, std::uint8_t* out) { fetch(offset, size, out); },
        file_size_, path_);
    parse_crs_and_fields(src, hd);
    select_copc_nodes(std::nullopt, std::nullopt);
    return;
  }
  const std::uint64_t point_bytes = file_size_ - hd.offset_to_points;
  if (hd.point_count > point_bytes / hd.record_length)
    src.fail(hd.offset_to_points, "the header promises " + std::to_string(hd.point_count) + " points of " +
                                      std::to_string(hd.record_length) + " bytes but only " +
                                      std::to_string(point_bytes) + " bytes follow the point data offset (truncated file)");
  parse_crs_and_fields(src, hd);
  points_total_ = hd.point_count;
}

}  // namespace vola::io
