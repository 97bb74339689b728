#include "vola/io/las.hpp"

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstring>
#include <limits>
#include <memory>
#include <optional>
#include <sstream>

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include "vola/error.hpp"
#include "vola/stream_builder.hpp"

namespace vola::io {

namespace {

template <class T>
T load(const std::uint8_t* p) {
  T v;
  std::memcpy(&v, p, sizeof(T));
  return v;
}

std::string text(const std::uint8_t* p, std::size_t n) {
  std::string s(reinterpret_cast<const char*>(p), n);
  const auto end = s.find('\0');
  if (end != std::string::npos) s.resize(end);
  while (!s.empty() && s.back() == ' ') s.pop_back();
  return s;
}

// Minimum record length of each point data record format (ASPRS LAS 1.4 R15).
constexpr std::uint16_t kMinRecordLength[11] = {20, 28, 26, 34, 57, 63, 30, 36, 38, 59, 67};
constexpr std::uint32_t kUserDefined = 32767;

// Bytes of one value of a scalar extra-bytes type 1..10.
std::size_t extra_size(std::uint8_t type) {
  static constexpr std::size_t sizes[11] = {0, 1, 1, 2, 2, 4, 4, 8, 8, 4, 8};
  return type <= 10 ? sizes[type] : 0;
}

double extra_value(const std::uint8_t* p, std::uint8_t type) {
  switch (type) {
    case 1: return load<std::uint8_t>(p);
    case 2: return load<std::int8_t>(p);
    case 3: return load<std::uint16_t>(p);
    case 4: return load<std::int16_t>(p);
    case 5: return load<std::uint32_t>(p);
    case 6: return load<std::int32_t>(p);
    case 7: return static_cast<double>(load<std::uint64_t>(p));
    case 8: return static_cast<double>(load<std::int64_t>(p));
    case 9: return load<float>(p);
    case 10: return load<double>(p);
    default: return 0.0;
  }
}

}  // namespace

bool LasHeader::has_rgb() const noexcept {
  return point_format == 2 || point_format == 3 || point_format == 5 || point_format == 7 || point_format == 8 ||
         point_format == 10;
}

bool LasHeader::has_gps_time() const noexcept { return point_format != 0 && point_format != 2; }

void LasChunk::clear() {
  xyz.clear();
  intensity.clear();
  return_number.clear();
  number_of_returns.clear();
  classification.clear();
  user_data.clear();
  point_source_id.clear();
  gps_time.clear();
  red.clear();
  green.clear();
  blue.clear();
  for (auto& e : extra) e.clear();
}

LasReader::LasReader(const std::string& path) : path_(path) {
  const int fd = ::open(path.c_str(), O_RDONLY | O_CLOEXEC);
  if (fd < 0) throw IoError(path + ": cannot open");
  struct stat st {};
  if (::fstat(fd, &st) == 0 && S_ISREG(st.st_mode)) {
    fd_ = std::shared_ptr<const int>(new int(fd), [](const int* f) {
      ::close(*f);
      delete f;
    });
    file_size_ = static_cast<std::uint64_t>(st.st_size);
#ifdef POSIX_FADV_SEQUENTIAL
    ::posix_fadvise(fd, 0, 0, POSIX_FADV_SEQUENTIAL);
#endif
  } else {
    ::close(fd);
    auto file = std::make_unique<std::ifstream>(path, std::ios::binary);
    if (!*file) throw IoError(path + ": cannot open");
    in_ = std::move(file);
  }
  read_header();
}

LasReader::LasReader(std::span<const std::uint8_t> bytes, const std::string& name)
    : path_(name), owned_(bytes.begin(), bytes.end()) {
  bytes_ = owned_;
  file_size_ = bytes_.size();
  read_header();
}

// size bytes at offset (checked by the caller to lie inside the file).
void LasReader::fetch(std::uint64_t offset, std::uint64_t size, std::uint8_t* out) {
  if (fd_) {
    std::uint64_t done = 0;
    while (done < size) {
      const ::ssize_t got = ::pread(*fd_, out + done, static_cast<std::size_t>(size - done),
                                    static_cast<off_t>(offset + done));
      if (got < 0 && errno == EINTR) continue;
      if (got <= 0) throw FormatError(path_, offset + done, "cannot read");
      done += static_cast<std::uint64_t>(got);
    }
    return;
  }
  if (!in_) {
    if (size) std::memcpy(out, bytes_.data() + offset, size);
    return;
  }
  in_->clear();
  in_->seekg(static_cast<std::streamoff>(offset));
  in_->read(reinterpret_cast<char*>(out), static_cast<std::streamsize>(size));
  if (static_cast<std::uint64_t>(in_->gcount()) != size) throw FormatError(path_, offset, "cannot read");
}

void LasReader::read_header() {
  if (in_) {
    in_->seekg(0, std::ios::end);
    file_size_ = static_cast<std::uint64_t>(in_->tellg());
    in_->seekg(0);
  }
  auto fail = [&](std::uint64_t offset, const std::string& cause) -> void { throw FormatError(path_, offset, cause); };
  auto read_at = [&](std::uint64_t offset, std::uint64_t size, const char* what) {
    if (offset > file_size_ || size > file_size_ - offset)
      fail(offset, std::string(what) + " of " + std::to_string(size) + " bytes runs past the end of the " +
                       std::to_string(file_size_) + "-byte file");
    std::vector<std::uint8_t> bytes(size);
    try {
      fetch(offset, size, bytes.data());
    } catch (const FormatError&) {
      fail(offset, std::string("cannot read ") + what);
    }
    return bytes;
  };

  if (file_size_ < 227) fail(file_size_, "a LAS file has at least a 227-byte header; this file has " + std::to_string(file_size_) + " bytes");
  const auto h = read_at(0, std::min<std::uint64_t>(file_size_, 375), "header");
  if (std::memcmp(h.data(), "LASF", 4) != 0) fail(0, "not a LAS file (no LASF signature)");
  LasHeader& hd = header_;
  hd.global_encoding = load<std::uint16_t>(&h[6]);
  hd.version_major = h[24];
  hd.version_minor = h[25];
  if (hd.version_major != 1 || hd.version_minor > 4)
    fail(24, "LAS version " + hd.version() + " is not known (1.0 to 1.4)");
  hd.system_identifier = text(&h[26], 32);
  hd.generating_software = text(&h[58], 32);
  hd.header_size = load<std::uint16_t>(&h[94]);
  hd.offset_to_points = load<std::uint32_t>(&h[96]);
  const std::uint32_t vlr_count = load<std::uint32_t>(&h[100]);
  const std::uint8_t raw_format = h[104];
  hd.record_length = load<std::uint16_t>(&h[105]);
  const std::uint32_t legacy_count = load<std::uint32_t>(&h[107]);
  for (int a = 0; a < 3; ++a) {
    hd.scale[a] = load<double>(&h[131 + 8 * a]);
    hd.offset[a] = load<double>(&h[155 + 8 * a]);
    hd.max[a] = load<double>(&h[179 + 16 * a]);
    hd.min[a] = load<double>(&h[187 + 16 * a]);
  }
  const std::uint16_t min_header = hd.version_minor >= 4 ? 375 : hd.version_minor == 3 ? 235 : 227;
  if (hd.header_size < min_header || hd.header_size > file_size_)
    fail(94, "header size " + std::to_string(hd.header_size) + " does not fit LAS " + hd.version() +
                 " (at least " + std::to_string(min_header) + ") or the file");
  hd.point_count = legacy_count;
  std::uint64_t evlr_start = 0;
  std::uint32_t evlr_count = 0;
  if (hd.version_minor >= 4) {
    evlr_start = load<std::uint64_t>(&h[235]);
    evlr_count = load<std::uint32_t>(&h[243]);
    const std::uint64_t count64 = load<std::uint64_t>(&h[247]);
    if (count64 != 0) hd.point_count = count64;
  }

  // VLRs, then EVLRs.
  std::uint64_t at = hd.header_size;
  bool laszip = false;
  for (std::uint32_t i = 0; i < vlr_count; ++i) {
    const auto v = read_at(at, 54, "VLR header");
    LasVlr vlr;
    vlr.user_id = text(&v[2], 16);
    vlr.record_id = load<std::uint16_t>(&v[18]);
    vlr.description = text(&v[22], 32);
    vlr.offset = at + 54;
    const std::uint16_t length = load<std::uint16_t>(&v[20]);
    vlr.data = read_at(at + 54, length, "VLR data");
    if (vlr.user_id == "laszip encoded") laszip = true;
    hd.vlrs.push_back(std::move(vlr));
    at += 54 + length;
  }
  if (raw_format & 0xC0 || laszip)
    fail(104, "this is a LAZ (compressed LAS) file; no LAZ library is packaged for this system. Decompress it "
              "first (e.g. `laszip -i in.laz -o out.las` or `pdal translate in.laz out.las`) and convert the .las");
  hd.point_format = raw_format;
  if (hd.point_format > 10) fail(104, "point data record format " + std::to_string(hd.point_format) + " is not known (0..10)");
  if (hd.record_length < kMinRecordLength[hd.point_format])
    fail(105, "record length " + std::to_string(hd.record_length) + " is shorter than format " +
                  std::to_string(hd.point_format) + " needs (" + std::to_string(kMinRecordLength[hd.point_format]) + ")");
  if (hd.offset_to_points < at || hd.offset_to_points > file_size_)
    fail(96, "offset to point data " + std::to_string(hd.offset_to_points) + " is before the end of the VLRs (" +
                 std::to_string(at) + ") or past the end of the file");
  for (std::uint32_t i = 0; i < evlr_count; ++i) {
    const auto v = read_at(evlr_start, 60, "EVLR header");
    LasVlr vlr;
    vlr.extended = true;
    vlr.user_id = text(&v[2], 16);
    vlr.record_id = load<std::uint16_t>(&v[18]);
    vlr.description = text(&v[28], 32);
    const std::uint64_t length = load<std::uint64_t>(&v[20]);
    vlr.offset = evlr_start + 60;
    // Waveform data can be huge and is not needed: only keep what describes the points.
    if (vlr.user_id == "LASF_Projection" || vlr.user_id == "LASF_Spec") vlr.data = read_at(evlr_start + 60, length, "EVLR data");
    else if (length > file_size_ - std::min(file_size_, evlr_start + 60)) fail(evlr_start + 20, "EVLR length runs past the end of the file");
    hd.vlrs.push_back(std::move(vlr));
    evlr_start += 60 + length;
  }
  const std::uint64_t point_bytes = file_size_ - hd.offset_to_points;
  if (hd.point_count > point_bytes / hd.record_length)
    fail(hd.offset_to_points, "the header promises " + std::to_string(hd.point_count) + " points of " +
                                  std::to_string(hd.record_length) + " bytes but only " + std::to_string(point_bytes) +
                                  " bytes follow the point data offset (truncated file)");

  // CRS and extra bytes.
  for (const auto& vlr : hd.vlrs) {
    if (vlr.user_id == "LASF_Projection" && vlr.record_id == 34735 && vlr.data.size() >= 8) {
      const std::size_t keys = load<std::uint16_t>(&vlr.data[6]);
      std::optional<std::uint32_t> projected, geographic;
      for (std::size_t k = 0; k < keys && 8 + 8 * k + 8 <= vlr.data.size(); ++k) {
        const std::uint8_t* e = &vlr.data[8 + 8 * k];
        const std::uint16_t id = load<std::uint16_t>(e), location = load<std::uint16_t>(e + 2);
        const std::uint16_t value = load<std::uint16_t>(e + 6);
        if (location != 0) continue;
        if (id == 3072) projected = value;
        if (id == 2048) geographic = value;
      }
      if (projected && *projected != kUserDefined && *projected != 0) hd.epsg = *projected;
      else if (geographic && *geographic != kUserDefined && *geographic != 0) hd.epsg = *geographic;
    } else if (vlr.user_id == "LASF_Projection" && vlr.record_id == 2112) {
      hd.wkt = text(vlr.data.data(), vlr.data.size());
    } else if (vlr.user_id == "LASF_Spec" && vlr.record_id == 4) {
      std::uint32_t offset = kMinRecordLength[hd.point_format];
      for (std::size_t d = 0; d + 192 <= vlr.data.size(); d += 192) {
        const std::uint8_t* e = &vlr.data[d];
        const std::uint8_t type = e[2], options = e[3];
        const std::string name = text(e + 4, 32);
        if (type == 0) {  // undocumented bytes: options holds their count
          offset += options;
          continue;
        }
        // Types 11..30 (LAS 1.4 R13, deprecated since) are arrays of 2 or 3 values of
        // type ((t - 1) % 10) + 1; each element becomes its own field.
        if (type > 30) fail(vlr.offset + d + 2, "extra bytes field '" + name + "' has unknown data type " + std::to_string(type));
        const std::uint8_t base = static_cast<std::uint8_t>((type - 1) % 10 + 1);
        const int count = (type - 1) / 10 + 1;
        for (int k = 0; k < count; ++k) {
          LasExtraField f;
          f.name = count == 1 ? name : name + "_" + std::to_string(k);
          f.data_type = base;
          f.size = static_cast<std::uint32_t>(extra_size(base));
          f.offset = offset;
          if (options & 8) f.scale = load<double>(e + 112 + 8 * k);
          if (options & 16) f.add = load<double>(e + 136 + 8 * k);
          hd.extra_fields.push_back(f);
          offset += f.size;
        }
      }
      if (offset > hd.record_length)
        fail(vlr.offset, "extra bytes fields need " + std::to_string(offset) + " bytes per record, records have " +
                             std::to_string(hd.record_length));
    }
  }
  if (in_) in_->seekg(hd.offset_to_points);
}

std::span<const std::uint8_t> LasReader::read_records(std::size_t max_points) {
  const LasHeader& hd = header_;
  const std::size_t n = static_cast<std::size_t>(std::min<std::uint64_t>(max_points, hd.point_count - next_));
  if (n == 0) return {};
  const std::size_t length = hd.record_length;
  const std::uint64_t at = hd.offset_to_points + next_ * length;
  if (!fd_ && !in_) {  // in memory; the header check guarantees the records lie inside
    next_ += n;
    return bytes_.subspan(static_cast<std::size_t>(at), n * length);
  }
  // resize() only grows the buffer after the first chunk: no zeroing per chunk.
  if (buffer_.size() < n * length) buffer_.resize(n * length);
  if (fd_) {
    try {
      fetch(at, n * length, buffer_.data());
    } catch (const FormatError&) {
      throw FormatError(path_, at, "cannot read the point records (truncated file)");
    }
  } else {
    in_->clear();
    in_->seekg(static_cast<std::streamoff>(at));
    in_->read(reinterpret_cast<char*>(buffer_.data()), static_cast<std::streamsize>(n * length));
    if (static_cast<std::size_t>(in_->gcount()) != n * length)
      throw FormatError(path_, at, "cannot read the point records (truncated file)");
  }
  next_ += n;
  return {buffer_.data(), n * length};
}

std::size_t LasReader::read(LasChunk& chunk, std::size_t max_points, bool xyz_only) {
  chunk.clear();
  const LasHeader& hd = header_;
  chunk.extra.resize(hd.extra_fields.size());
  const std::size_t length = hd.record_length;
  const std::size_t n = static_cast<std::size_t>(std::min<std::uint64_t>(max_points, hd.point_count - next_));
  if (n == 0) return 0;
  // The records come in batches that stay in cache while their fields are spread out.
  const std::size_t batch = std::max<std::size_t>(1, kLasRecordBatchBytes / length);
  if (xyz_only) {
    chunk.xyz.resize(3 * n);
    double* out = chunk.xyz.data();
    for (std::size_t done = 0; done < n;) {
      const std::span<const std::uint8_t> records = read_records(std::min(batch, n - done));
      const std::size_t m = records.size() / length;
      for (std::size_t i = 0; i < m; ++i, out += 3) {
        const std::uint8_t* r = records.data() + i * length;
        for (int a = 0; a < 3; ++a) out[a] = static_cast<double>(load<std::int32_t>(r + 4 * a)) * hd.scale[a] + hd.offset[a];
      }
      done += m;
    }
    return n;
  }
  const bool extended = hd.extended_format();
  const bool rgb = hd.has_rgb(), gps = hd.has_gps_time();
  // Byte offsets of the optional fields inside a record.
  const std::size_t gps_at = extended ? 22 : 20;
  const std::size_t rgb_at = extended ? 30 : (hd.point_format == 2 ? 20 : 28);
  chunk.xyz.resize(3 * n);
  chunk.intensity.resize(n);
  chunk.return_number.resize(n);
  chunk.number_of_returns.resize(n);
  chunk.classification.resize(n);
  chunk.user_data.resize(n);
  chunk.point_source_id.resize(n);
  if (gps) chunk.gps_time.resize(n);
  if (rgb) {
    chunk.red.resize(n);
    chunk.green.resize(n);
    chunk.blue.resize(n);
  }
  for (auto& e : chunk.extra) e.resize(n);
  for (std::size_t done = 0; done < n;) {
    const std::span<const std::uint8_t> records = read_records(std::min(batch, n - done));
    const std::size_t m = records.size() / length;
    for (std::size_t k = 0; k < m; ++k) {
      const std::uint8_t* r = records.data() + k * length;
      const std::size_t i = done + k;
      for (int a = 0; a < 3; ++a)
        chunk.xyz[3 * i + a] = static_cast<double>(load<std::int32_t>(r + 4 * a)) * hd.scale[a] + hd.offset[a];
      chunk.intensity[i] = load<std::uint16_t>(r + 12);
      if (extended) {
        chunk.return_number[i] = r[14] & 15u;
        chunk.number_of_returns[i] = r[14] >> 4;
        chunk.classification[i] = r[16];
        chunk.user_data[i] = r[17];
        chunk.point_source_id[i] = load<std::uint16_t>(r + 20);
      } else {
        chunk.return_number[i] = r[14] & 7u;
        chunk.number_of_returns[i] = (r[14] >> 3) & 7u;
        chunk.classification[i] = r[15] & 31u;  // bits 5-7 are synthetic/key-point/withheld flags
        chunk.user_data[i] = r[17];
        chunk.point_source_id[i] = load<std::uint16_t>(r + 18);
      }
      if (gps) chunk.gps_time[i] = load<double>(r + gps_at);
      if (rgb) {
        chunk.red[i] = load<std::uint16_t>(r + rgb_at);
        chunk.green[i] = load<std::uint16_t>(r + rgb_at + 2);
        chunk.blue[i] = load<std::uint16_t>(r + rgb_at + 4);
      }
      for (std::size_t f = 0; f < hd.extra_fields.size(); ++f) {
        const auto& field = hd.extra_fields[f];
        chunk.extra[f][i] = extra_value(r + field.offset, field.data_type) * field.scale + field.add;
      }
    }
    done += m;
  }
  return n;
}

namespace {

// The reference's las2vola payload: int(255 * clip((v - lo) / (hi - lo), 0, 1)).
std::uint64_t payload_byte(double v, double lo, double hi) {
  const double n = hi > lo ? (v - lo) / (hi - lo) : 0.0;
  if (!(n > 0.0)) return 0;  // also NaN, from a header max z that is not a number
  return static_cast<std::uint64_t>(255.0 * std::min(n, 1.0));
}

}  // namespace

std::vector<AttributeSpec> las_attributes(const LasHeader& hd) {
  std::vector<AttributeSpec> specs;
  if (hd.has_rgb()) {
    specs.push_back({"red", ValueType::u16, Reduction::mean});
    specs.push_back({"green", ValueType::u16, Reduction::mean});
    specs.push_back({"blue", ValueType::u16, Reduction::mean});
  }
  specs.push_back({"intensity", ValueType::u16, Reduction::mean});
  specs.push_back({"classification", ValueType::u8, Reduction::majority});
  specs.push_back({"height", ValueType::f32, Reduction::mean});
  specs.push_back({"number_of_returns", ValueType::u8, Reduction::max});
  for (const auto& f : hd.extra_fields) specs.push_back({f.name, ValueType::f64, Reduction::mean});
  return specs;
}

void las_attribute_values(const LasHeader& hd, const LasChunk& chunk, std::vector<std::vector<double>>& values) {
  const std::size_t n = chunk.size();
  values.resize(las_attributes(hd).size());
  std::size_t c = 0;
  auto column = [&](auto&& value_of) {
    auto& v = values[c++];
    v.resize(n);
    for (std::size_t i = 0; i < n; ++i) v[i] = value_of(i);
  };
  if (hd.has_rgb()) {
    column([&](std::size_t i) { return static_cast<double>(chunk.red[i]); });
    column([&](std::size_t i) { return static_cast<double>(chunk.green[i]); });
    column([&](std::size_t i) { return static_cast<double>(chunk.blue[i]); });
  }
  column([&](std::size_t i) { return static_cast<double>(chunk.intensity[i]); });
  column([&](std::size_t i) { return static_cast<double>(chunk.classification[i]); });
  column([&](std::size_t i) { return chunk.xyz[3 * i + 2]; });
  column([&](std::size_t i) { return static_cast<double>(chunk.number_of_returns[i]); });
  for (const auto& extra : chunk.extra) column([&](std::size_t i) { return extra[i]; });
}

void las_payloads(const LasHeader& hd, const LasChunk& chunk, std::vector<std::uint64_t>& payloads) {
  const std::size_t n = chunk.size();
  payloads.resize(n);
  for (std::size_t i = 0; i < n; ++i) {
    std::uint64_t r = 200, g = 200, b = 200;  // the reference's grey for points without colour
    if (hd.has_rgb() && (chunk.red[i] | chunk.green[i] | chunk.blue[i])) {
      r = chunk.red[i] / 256u;
      g = chunk.green[i] / 256u;
      b = chunk.blue[i] / 256u;
    }
    payloads[i] = r | g << 8 | b << 16 | payload_byte(chunk.xyz[3 * i + 2], 0.0, hd.max[2]) << 24 |
                  payload_byte(chunk.number_of_returns[i], 1.0, 7.0) << 32 |
                  payload_byte(chunk.intensity[i], 0.0, 1000.0) << 40 |
                  payload_byte(chunk.classification[i], 0.0, 31.0) << 48;
  }
}

void LasReader::rewind() {
  next_ = 0;
  if (in_) {
    in_->clear();
    in_->seekg(header_.offset_to_points);
  }
}

PointCloud las_points(LasReader& reader, bool attributes, bool payload,
                      const std::function<void(std::uint64_t, std::uint64_t)>& progress) {
  const LasHeader& hd = reader.header();
  PointCloud cloud;
  const std::uint64_t total = hd.point_count;
  cloud.xyz.reserve(3 * total);
  if (attributes)
    for (const auto& spec : las_attributes(hd)) cloud.attributes.push_back({spec.name, spec.type, spec.reduction, {}});
  LasChunk chunk;
  std::vector<std::vector<double>> values;
  std::vector<std::uint64_t> payloads;
  while (reader.read(chunk, 1 << 20) > 0) {
    cloud.xyz.insert(cloud.xyz.end(), chunk.xyz.begin(), chunk.xyz.end());
    if (attributes) {
      las_attribute_values(hd, chunk, values);
      for (std::size_t a = 0; a < values.size(); ++a)
        cloud.attributes[a].values.insert(cloud.attributes[a].values.end(), values[a].begin(), values[a].end());
    }
    if (payload) {
      las_payloads(hd, chunk, payloads);
      cloud.payload.insert(cloud.payload.end(), payloads.begin(), payloads.end());
    }
    if (progress) progress(reader.points_read(), total);
  }
  return cloud;
}

namespace {

// x y z of each record, appended to xyz.
void decode_xyz(const LasHeader& hd, std::span<const std::uint8_t> records, std::vector<double>& xyz) {
  const std::size_t length = hd.record_length, n = records.size() / length;
  const std::size_t at = xyz.size();
  xyz.resize(at + 3 * n);
  double* out = xyz.data() + at;
  const std::uint8_t* r = records.data();
  for (std::size_t i = 0; i < n; ++i, r += length, out += 3) {
    out[0] = static_cast<double>(load<std::int32_t>(r)) * hd.scale[0] + hd.offset[0];
    out[1] = static_cast<double>(load<std::int32_t>(r + 4)) * hd.scale[1] + hd.offset[1];
    out[2] = static_cast<double>(load<std::int32_t>(r + 8)) * hd.scale[2] + hd.offset[2];
  }
}

// Points in a batch of records that stays in cache (LasReader::read_records).
std::size_t batch_points(const LasHeader& hd) { return std::max<std::size_t>(1, kLasRecordBatchBytes / hd.record_length); }

// The next chunk of up to chunk_points points, decoded into xyz (replaced); the points read.
std::size_t read_xyz(LasReader& reader, std::size_t chunk_points, std::vector<double>& xyz) {
  const LasHeader& hd = reader.header();
  xyz.clear();
  const std::size_t batch = batch_points(hd);
  std::size_t done = 0;
  while (done < chunk_points) {
    const std::span<const std::uint8_t> records = reader.read_records(std::min(batch, chunk_points - done));
    if (records.empty()) break;
    decode_xyz(hd, records, xyz);
    done += records.size() / hd.record_length;
  }
  return done;
}

// The bounds of the decoded coordinates, from the rest of the file. x * scale + offset
// is monotonic in the stored integer x (rounding keeps the order; a negative scale
// reverses it), so the extremes of the integers decode to the extremes of the
// coordinates: no point is decoded. A scale or offset that is not finite could make
// NaN, which the comparisons of the decoded path skip: such files take that path.
Box las_bounds(LasReader& reader, std::size_t chunk_points, std::int32_t stored_lo[3], std::int32_t stored_hi[3],
               const std::function<void(std::uint64_t)>& progress) {
  const LasHeader& hd = reader.header();
  constexpr double inf = std::numeric_limits<double>::infinity();
  Box box{{inf, inf, inf}, {-inf, -inf, -inf}};
  bool finite = true;
  for (int a = 0; a < 3; ++a) finite = finite && std::isfinite(hd.scale[a]) && std::isfinite(hd.offset[a]);
  std::int32_t lo[3], hi[3];
  for (int a = 0; a < 3; ++a) {
    lo[a] = std::numeric_limits<std::int32_t>::max();
    hi[a] = std::numeric_limits<std::int32_t>::min();
  }
  std::vector<double> xyz;
  const std::size_t length = hd.record_length, batch = batch_points(hd);
  std::uint64_t reported = 0;
  while (true) {
    const std::span<const std::uint8_t> records = reader.read_records(batch);
    if (records.empty()) break;
    if (finite) {
      std::int32_t l0 = lo[0], l1 = lo[1], l2 = lo[2], h0 = hi[0], h1 = hi[1], h2 = hi[2];
      for (const std::uint8_t* r = records.data(); r < records.data() + records.size(); r += length) {
        const std::int32_t x = load<std::int32_t>(r), y = load<std::int32_t>(r + 4), z = load<std::int32_t>(r + 8);
        l0 = std::min(l0, x), h0 = std::max(h0, x);
        l1 = std::min(l1, y), h1 = std::max(h1, y);
        l2 = std::min(l2, z), h2 = std::max(h2, z);
      }
      lo[0] = l0, lo[1] = l1, lo[2] = l2, hi[0] = h0, hi[1] = h1, hi[2] = h2;
    } else {
      xyz.clear();
      decode_xyz(hd, records, xyz);
      for (std::size_t i = 0; i < xyz.size(); ++i) {
        box.min[i % 3] = std::min(box.min[i % 3], xyz[i]);
        box.max[i % 3] = std::max(box.max[i % 3], xyz[i]);
      }
    }
    if (reader.points_read() - reported >= chunk_points || reader.points_read() == hd.point_count) {
      reported = reader.points_read();
      progress(reported);
    }
  }
  if (reader.points_read() == 0) return Box{};
  if (finite)
    for (int a = 0; a < 3; ++a) {
      stored_lo[a] = lo[a];
      stored_hi[a] = hi[a];
      const double from_lo = static_cast<double>(lo[a]) * hd.scale[a] + hd.offset[a];
      const double from_hi = static_cast<double>(hi[a]) * hd.scale[a] + hd.offset[a];
      box.min[a] = std::min(from_lo, from_hi);
      box.max[a] = std::max(from_lo, from_hi);
    }
  return box;
}

// The stored integer of one axis -> its voxel's key bits, exactly as decoding the
// coordinate (x * scale + offset, as decode_xyz does) and quantizing it
// (Quantizer::to_voxel) would give, without either per point. Both steps are
// monotonic in the stored integer x (for a positive scale: rounding keeps the order),
// so the cells form runs of consecutive integers: `lower[i]` is the smallest stored
// integer of cell i, found once per cell with the exact decode + to_voxel. Per point,
// one multiply guesses the cell and one or two comparisons correct the guess.
class AxisCells {
 public:
  static constexpr Key kOutside = Key{1} << 63;
  // Cells in [lo, hi], the stored integers of this axis that can occur. False (use the
  // decoded path) when the mapping is not monotonic non-decreasing and finite, or the
  // range spans too many cells for a table.
  bool build(const LasHeader& hd, const Quantizer& quantizer, int axis, std::int64_t lo, std::int64_t hi) {
    const double scale = hd.scale[axis], offset = hd.offset[axis];
    if (!(scale > 0.0) || !std::isfinite(scale) || !std::isfinite(offset)) return false;
    axis_ = axis;
    hd_ = &hd;
    quantizer_ = &quantizer;
    // The other axes at a point known to be inside, so to_voxel speaks of this axis only.
    inside_ = quantizer.center(Voxel{0, 0, 0});
    Voxel v;
    if (!quantizer.to_voxel(inside_, v) || v != Voxel{0, 0, 0}) return false;
    side_ = side_of(quantizer.depth());
    origin_ = quantizer.frame().origin[axis];
    if (!std::isfinite(decode(lo)) || !std::isfinite(decode(hi))) return false;
    const std::int64_t first = cell(lo), last = cell(hi);
    if (first > last || last - first >= kMaxCells) return false;
    const std::size_t cells = static_cast<std::size_t>(last - first + 1);
    lower_.assign(cells + 1, 0);
    key_.assign(cells, 0);
    lower_[0] = std::numeric_limits<std::int64_t>::min();
    lower_[cells] = std::numeric_limits<std::int64_t>::max();
    std::int64_t from = lo, width = 0;
    for (std::size_t i = 1; i < cells; ++i) {
      const std::int64_t at = first_at_least(first + static_cast<std::int64_t>(i), from, hi, from + width);
      if (i >= 2) width = at - from;
      lower_[i] = from = at;
    }
    for (std::size_t i = 0; i < cells; ++i) {
      const std::int64_t c = first + static_cast<std::int64_t>(i);
      key_[i] = c < 0 || c >= side_ ? kOutside : detail::spread(static_cast<std::uint32_t>(c)) << (2 * axis);
    }
    // The guess: cell 1 starts at lower_[1], cells are (lower_[last] - lower_[1]) / (cells - 2) wide.
    base_ = cells >= 2 ? lower_[1] : 0;
    slope_ = cells >= 3 && lower_[cells - 1] > lower_[1]
                 ? static_cast<double>(cells - 2) / static_cast<double>(lower_[cells - 1] - lower_[1])
                 : 0.0;
    last_ = static_cast<std::int64_t>(cells) - 1;
    // Check the guess-and-correct lookup against the exact mapping at every border.
    for (std::size_t i = 1; i < cells; ++i)
      for (const std::int64_t x : {lower_[i] - 1, lower_[i]})
        if (x >= lo && x <= hi && key(static_cast<std::int32_t>(x)) != exact_key(x)) return false;
    return true;
  }

  // The table by value, for a hot loop (locals that no store can alias).
  struct Lookup {
    const std::int64_t* lower;
    const Key* key;
    std::int64_t base, last;
    double slope;
    Key operator()(std::int32_t x) const noexcept {
      std::int64_t i = 1 + static_cast<std::int64_t>(static_cast<double>(x - base) * slope);
      i = std::clamp<std::int64_t>(i, 0, last);
      while (x < lower[i]) --i;
      while (x >= lower[i + 1]) ++i;
      return key[i];
    }
  };
  Lookup lookup() const noexcept { return {lower_.data(), key_.data(), base_, last_, slope_}; }
  Key key(std::int32_t x) const noexcept { return lookup()(x); }

 private:
  static constexpr std::int64_t kMaxCells = std::int64_t{1} << 21;

  double decode(std::int64_t x) const noexcept {
    return static_cast<double>(static_cast<std::int32_t>(x)) * hd_->scale[axis_] + hd_->offset[axis_];
  }
  // The cell of stored integer x: -1 below a grid, side above it.
  std::int64_t cell(std::int64_t x) const noexcept {
    Point p = inside_;
    p[axis_] = decode(x);
    Voxel v;
    if (quantizer_->to_voxel(p, v)) return axis_ == 0 ? v.x : axis_ == 1 ? v.y : v.z;
    return p[axis_] < origin_ ? -1 : static_cast<std::int64_t>(side_);
  }
  Key exact_key(std::int64_t x) const noexcept {
    const std::int64_t c = cell(x);
    return c < 0 || c >= side_ ? kOutside : detail::spread(static_cast<std::uint32_t>(c)) << (2 * axis_);
  }
  // The smallest x in [from, to] whose cell is at least c (cell(to) >= c, cell(from - 1) < c).
  std::int64_t first_at_least(std::int64_t c, std::int64_t from, std::int64_t to, std::int64_t guess) const {
    std::int64_t below = from - 1, above = to;  // cell(below) < c <= cell(above)
    guess = std::clamp(guess, from, to);
    std::int64_t step = 1;
    if (cell(guess) >= c) {
      above = guess;
      while (above - step > below) {
        if (cell(above - step) < c) {
          below = above - step;
          break;
        }
        above -= step;
        step *= 2;
      }
    } else {
      below = guess;
      while (below + step < above) {
        if (cell(below + step) >= c) {
          above = below + step;
          break;
        }
        below += step;
        step *= 2;
      }
    }
    while (above - below > 1) {
      const std::int64_t mid = below + (above - below) / 2;
      (cell(mid) >= c ? above : below) = mid;
    }
    return above;
  }

  int axis_ = 0;
  const LasHeader* hd_ = nullptr;
  const Quantizer* quantizer_ = nullptr;
  Point inside_{};
  std::int64_t side_ = 0;
  double origin_ = 0.0;
  std::vector<std::int64_t> lower_;
  std::vector<Key> key_;
  std::int64_t base_ = 0, last_ = 0;
  double slope_ = 0.0;
};

// The streamed tree with its bbox and EPSG code in the header, and what went into it.
Tree finish_tree(StreamBuilder& builder, const Box& bbox, std::uint32_t epsg, BuildReport* report) {
  Tree tree = builder.finish();
  tree.georef().bbox = bbox;
  tree.georef().epsg = epsg;
  if (report) {
    report->points_in = builder.points_in();
    report->points_outside = builder.points_outside();
    report->voxels = tree.voxel_count();
  }
  return tree;
}

// The next chunk of up to chunk_points records -> voxel keys -> the builder, the
// records read in batches that stay in cache. With kRange, also widens [lo, hi], the
// range of stored integers per axis. Returns the points read (0 at the end).
template <bool kRange>
std::size_t add_chunk(LasReader& reader, StreamBuilder& builder, std::size_t chunk_points, const AxisCells (&cells)[3],
                      std::int32_t lo[3], std::int32_t hi[3]) {
  const LasHeader& hd = reader.header();
  const std::size_t length = hd.record_length;
  const std::size_t n =
      static_cast<std::size_t>(std::min<std::uint64_t>(chunk_points, hd.point_count - reader.points_read()));
  if (n == 0) return 0;
  const std::size_t batch = batch_points(hd);
  const AxisCells::Lookup kx = cells[0].lookup(), ky = cells[1].lookup(), kz = cells[2].lookup();
  Key* out = builder.key_scratch(n).data();
  std::size_t kept = 0, done = 0;
  std::int32_t l0 = lo[0], l1 = lo[1], l2 = lo[2], h0 = hi[0], h1 = hi[1], h2 = hi[2];
  while (done < n) {
    const std::span<const std::uint8_t> records = reader.read_records(std::min(batch, n - done));
    const std::size_t m = records.size() / length;
    if (m == 0) break;
    const std::uint8_t* r = records.data();
    for (std::size_t i = 0; i < m; ++i, r += length) {
      const std::int32_t x = load<std::int32_t>(r), y = load<std::int32_t>(r + 4), z = load<std::int32_t>(r + 8);
      if constexpr (kRange) {
        l0 = std::min(l0, x), h0 = std::max(h0, x);
        l1 = std::min(l1, y), h1 = std::max(h1, y);
        l2 = std::min(l2, z), h2 = std::max(h2, z);
      }
      const Key key = kx(x) | ky(y) | kz(z);
      out[kept] = key;
      kept += (key >> 63) ^ 1;  // AxisCells::kOutside: the point is outside the grid
    }
    done += m;
  }
  if constexpr (kRange) lo[0] = l0, lo[1] = l1, lo[2] = l2, hi[0] = h0, hi[1] = h1, hi[2] = h2;
  builder.add_keys(std::span<Key>(out, kept), done - kept);
  return done;
}

// The box of the decoded coordinates from the range of stored integers (as las_bounds).
Box decoded_box(const LasHeader& hd, const std::int32_t lo[3], const std::int32_t hi[3]) {
  Box box;
  for (int a = 0; a < 3; ++a) {
    const double from_lo = static_cast<double>(lo[a]) * hd.scale[a] + hd.offset[a];
    const double from_hi = static_cast<double>(hi[a]) * hd.scale[a] + hd.offset[a];
    box.min[a] = std::min(from_lo, from_hi);
    box.max[a] = std::max(from_lo, from_hi);
  }
  return box;
}

// Occupancy only, bbox not given: one pass instead of two. The grid is resolved from
// the header's bounds and the points' bounds are taken on the way; when the grid the
// points' bounds resolve to is the same grid (the usual case: a toolkit grid needs the
// same box, a grid-mode one only the same origin, voxel size and depth), the tree is
// what two passes would build. Otherwise nothing is returned and `bounds`, `lo`, `hi`
// hold the points' bounds, so the caller needs only its second pass.
std::optional<Tree> occupancy_in_one_pass(LasReader& reader, const BuildOptions& options, BuildReport* report,
                                          const std::function<void(std::uint64_t, std::uint64_t)>& progress,
                                          std::size_t chunk_points, std::optional<Box>& bounds, std::int32_t lo[3],
                                          std::int32_t hi[3]) {
  const LasHeader& hd = reader.header();
  if (hd.point_count == 0) return std::nullopt;
  const Box header_box{hd.min, hd.max};
  for (int a = 0; a < 3; ++a)
    if (!(std::isfinite(hd.min[a]) && std::isfinite(hd.max[a]) && hd.min[a] <= hd.max[a])) return std::nullopt;
  std::optional<Quantizer> quantizer;
  try {
    quantizer = resolve_quantizer(header_box, options);
  } catch (const Error&) {
    return std::nullopt;  // a header box no grid fits: the two-pass path says what is wrong
  }
  AxisCells cells[3];
  for (int a = 0; a < 3; ++a)
    if (!cells[a].build(hd, *quantizer, a, std::numeric_limits<std::int32_t>::min(),
                        std::numeric_limits<std::int32_t>::max()))
      return std::nullopt;
  StreamBuilder builder(*quantizer, {}, false);
  for (int a = 0; a < 3; ++a) {
    lo[a] = std::numeric_limits<std::int32_t>::max();
    hi[a] = std::numeric_limits<std::int32_t>::min();
  }
  reader.rewind();
  while (add_chunk<true>(reader, builder, chunk_points, cells, lo, hi) > 0) {
    if (progress) progress(reader.points_read(), hd.point_count);
    // A point well outside the header's box: the header is stale, stop guessing at once.
    // (Writers that round the header's bounds differently from the stored integers put
    // points a step or so outside it; the grid usually comes out the same.)
    const Box so_far = decoded_box(hd, lo, hi);
    for (int a = 0; a < 3; ++a) {
      const double slack = 2.0 * hd.scale[a];
      if (so_far.min[a] < header_box.min[a] - slack || so_far.max[a] > header_box.max[a] + slack) return std::nullopt;
    }
  }
  const Box box = decoded_box(hd, lo, hi);
  const Quantizer resolved = resolve_quantizer(box, options);
  const bool same = resolved.depth() == quantizer->depth() &&
                    (options.quantization == Quantization::toolkit ? box == header_box
                                                                   : resolved.frame() == quantizer->frame());
  if (!same) {
    bounds = box;
    return std::nullopt;
  }
  return finish_tree(builder, box, options.epsg, report);
}

}  // namespace

Tree build_las(LasReader& reader, const BuildOptions& requested, bool attributes, bool payload, BuildReport* report,
               const std::function<void(std::uint64_t, std::uint64_t)>& progress, std::size_t chunk_points) {
  BuildOptions options = requested;  // the bbox is filled in from the points when not given
  const LasHeader& hd = reader.header();
  LasChunk chunk;
  const bool occupancy_only = !attributes && !payload;
  // Keys are 8 bytes a point; decoded coordinates (the path without key tables) 24.
  const std::size_t decoded_chunk = chunk_points == 0 ? kLasChunkPoints : chunk_points;
  if (chunk_points == 0) chunk_points = occupancy_only ? kLasKeyChunkPoints : kLasChunkPoints;
  std::int32_t stored_lo[3], stored_hi[3];
  for (int a = 0; a < 3; ++a) {
    stored_lo[a] = std::numeric_limits<std::int32_t>::min();
    stored_hi[a] = std::numeric_limits<std::int32_t>::max();
  }
  if (occupancy_only && !options.bbox) {
    std::optional<Box> bounds;
    std::int32_t lo[3], hi[3];
    if (std::optional<Tree> tree = occupancy_in_one_pass(reader, options, report, progress, chunk_points, bounds, lo, hi))
      return std::move(*tree);
    if (bounds) {  // the pass above took the points' bounds: only the second pass is left
      options.bbox = bounds;
      std::copy(lo, lo + 3, stored_lo);
      std::copy(hi, hi + 3, stored_hi);
    }
  }
  const std::uint64_t passes = options.bbox ? 1 : 2;
  // Pass 1: the points' bounds, as the reference takes them (the header's may be stale).
  if (!options.bbox) {
    reader.rewind();
    options.bbox = las_bounds(reader, chunk_points, stored_lo, stored_hi, [&](std::uint64_t done) {
      if (progress) progress(done, passes * hd.point_count);
    });
  }
  const Quantizer quantizer = resolve_quantizer(*options.bbox, options);
  std::vector<AttributeSpec> specs = attributes ? las_attributes(hd) : std::vector<AttributeSpec>{};
  StreamBuilder builder(quantizer, specs, payload);
  if (!occupancy_only) builder.expect_points(hd.point_count);
  std::vector<std::vector<double>> values;
  std::vector<std::span<const double>> views;
  std::vector<std::uint64_t> payloads;
  std::vector<double> xyz;  // occupancy only: coordinates decoded straight from the records
  // Occupancy only: keys straight from the stored integers (AxisCells), over the range
  // of stored integers the bounds pass saw (or any int32 when the bbox was given).
  AxisCells cells[3];
  bool by_table = occupancy_only && hd.point_count > 0;
  for (int a = 0; a < 3 && by_table; ++a)
    by_table = cells[a].build(hd, quantizer, a, stored_lo[a], stored_hi[a]);
  reader.rewind();
  while (by_table && add_chunk<false>(reader, builder, chunk_points, cells, stored_lo, stored_hi) > 0) {
    if (progress) progress((passes - 1) * hd.point_count + reader.points_read(), passes * hd.point_count);
  }
  while (!by_table) {
    if (occupancy_only) {
      if (read_xyz(reader, decoded_chunk, xyz) == 0) break;
      builder.add(xyz, {}, {});
    } else {
      if (reader.read(chunk, chunk_points) == 0) break;
      if (attributes) las_attribute_values(hd, chunk, values);
      views.assign(values.begin(), values.end());
      if (payload) las_payloads(hd, chunk, payloads);
      builder.add(chunk.xyz, views, payload ? std::span<const std::uint64_t>(payloads) : std::span<const std::uint64_t>{});
    }
    if (progress) progress((passes - 1) * hd.point_count + reader.points_read(), passes * hd.point_count);
  }
  // The chunk buffers (~100 bytes a point with attributes) are not needed by the final
  // merges, which are the peak of the conversion.
  chunk = LasChunk{};
  values = {};
  views = {};
  payloads = {};
  xyz = {};
  return finish_tree(builder, *options.bbox, options.epsg, report);
}

}  // namespace vola::io
