// E57 files written here from the standard's layout (ASTM E2807), for the reader's tests
// and the fuzz seeds: the 48-byte header, each scan's compressed-vector section (its
// fields bit-packed into one bytestream each, cut into data packets of at most
// `records_per_packet` records), the XML section last, and the logical bytes laid in
// 1024-byte pages that end with the big-endian CRC-32C of their 1020 bytes (computed bit
// by bit here, not with the reader's table).
#pragma once

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <optional>
#include <string>
#include <vector>

namespace vola_io_test {

struct E57TestField {
  std::string name;                       // cartesianX, colorRed, nor:normalX, ...
  std::string type = "Float";             // Float, Integer, ScaledInteger
  bool single = false;                    // Float: precision="single"
  std::int64_t minimum = 0, maximum = 0;  // Integer, ScaledInteger
  double scale = 1.0, offset = 0.0;       // ScaledInteger
  std::vector<double> values;             // one per record (ScaledInteger: the scaled value)
};

struct E57TestScan {
  std::string name = "scan";
  std::vector<E57TestField> fields;
  std::optional<std::array<double, 7>> pose;  // rotation w x y z, translation x y z
  std::string pose_xml;                       // else a <pose> element written as given (a damaged one)
  std::size_t records_per_packet = 1000;
  std::optional<std::uint64_t> stated_records;  // a lying recordCount
};

inline std::uint32_t e57_test_crc32c(const std::uint8_t* data, std::size_t size) {
  std::uint32_t c = 0xFFFFFFFFu;
  for (std::size_t i = 0; i < size; ++i) {
    c ^= data[i];
    for (int k = 0; k < 8; ++k) c = (c >> 1) ^ (0x82F63B78u & (0u - (c & 1u)));
  }
  return ~c;
}

// The raw integer a field stores for `value`: value - minimum (ScaledInteger: the value
// unscaled first).
inline std::uint64_t e57_test_raw(const E57TestField& f, double value) {
  const double integer = f.type == "ScaledInteger" ? std::round((value - f.offset) / f.scale) : value;
  return static_cast<std::uint64_t>(static_cast<std::int64_t>(integer)) - static_cast<std::uint64_t>(f.minimum);
}

inline int e57_test_bits(const E57TestField& f) {
  if (f.type == "Float") return f.single ? 32 : 64;
  const std::uint64_t range = static_cast<std::uint64_t>(f.maximum) - static_cast<std::uint64_t>(f.minimum);
  int bits = 0;
  while (bits < 64 && (range >> bits) != 0) ++bits;
  return bits;
}

// The field's values as its bytestream: floats little-endian, integers packed from the
// least significant bit of each byte.
inline std::vector<std::uint8_t> e57_test_stream(const E57TestField& f) {
  std::vector<std::uint8_t> out;
  if (f.type == "Float") {
    for (double v : f.values) {
      std::uint8_t b[8];
      if (f.single) {
        const float x = static_cast<float>(v);
        std::memcpy(b, &x, 4);
        out.insert(out.end(), b, b + 4);
      } else {
        std::memcpy(b, &v, 8);
        out.insert(out.end(), b, b + 8);
      }
    }
    return out;
  }
  const int bits = e57_test_bits(f);
  out.assign((f.values.size() * static_cast<std::size_t>(bits) + 7) / 8, 0);
  std::size_t bit = 0;
  for (double v : f.values) {
    const std::uint64_t raw = e57_test_raw(f, v);
    for (int k = 0; k < bits; ++k, ++bit)
      if ((raw >> k) & 1) out[bit / 8] |= static_cast<std::uint8_t>(1u << (bit % 8));
  }
  return out;
}

inline std::uint64_t e57_test_physical(std::uint64_t logical) { return logical / 1020 * 1024 + logical % 1020; }

template <class T>
void e57_test_put(std::vector<std::uint8_t>& out, T value) {
  std::uint8_t b[sizeof value];
  std::memcpy(b, &value, sizeof value);
  out.insert(out.end(), b, b + sizeof value);
}

inline std::string e57_test_number(double v) {
  char text[40];
  std::snprintf(text, sizeof text, "%.17g", v);
  return text;
}

// The whole file.
inline std::vector<std::uint8_t> e57_test_file(const std::vector<E57TestScan>& scans,
                                               const std::string& coordinate_metadata = "") {
  std::vector<std::uint8_t> logical(48, 0);  // the header, filled in last
  std::string data3d;
  for (const E57TestScan& s : scans) {
    const std::size_t records = s.fields.empty() ? 0 : s.fields.front().values.size();
    std::vector<std::vector<std::uint8_t>> streams;
    for (const auto& f : s.fields) streams.push_back(e57_test_stream(f));
    const std::uint64_t section = logical.size();
    std::vector<std::uint8_t> body;
    std::size_t packets = records == 0 ? 0 : (records + s.records_per_packet - 1) / s.records_per_packet;
    std::vector<std::size_t> taken(streams.size(), 0);
    for (std::size_t p = 0; p < packets; ++p) {
      const std::size_t last = std::min(records, (p + 1) * s.records_per_packet);
      std::vector<std::uint8_t> packet = {1, 0, 0, 0};
      e57_test_put<std::uint16_t>(packet, static_cast<std::uint16_t>(streams.size()));
      std::vector<std::vector<std::uint8_t>> pieces;
      for (std::size_t i = 0; i < streams.size(); ++i) {
        // Each stream's bytes up to the last record of this packet (the final packet: all).
        const std::size_t bits = static_cast<std::size_t>(e57_test_bits(s.fields[i]));
        const std::size_t upto = p + 1 == packets ? streams[i].size() : last * bits / 8;
        pieces.emplace_back(streams[i].begin() + static_cast<std::ptrdiff_t>(taken[i]),
                            streams[i].begin() + static_cast<std::ptrdiff_t>(upto));
        taken[i] = upto;
        e57_test_put<std::uint16_t>(packet, static_cast<std::uint16_t>(pieces.back().size()));
      }
      for (const auto& piece : pieces) packet.insert(packet.end(), piece.begin(), piece.end());
      while (packet.size() % 4) packet.push_back(0);
      const auto minus1 = static_cast<std::uint16_t>(packet.size() - 1);
      std::memcpy(packet.data() + 2, &minus1, 2);
      body.insert(body.end(), packet.begin(), packet.end());
    }
    std::vector<std::uint8_t> header = {1, 0, 0, 0, 0, 0, 0, 0};
    e57_test_put<std::uint64_t>(header, 32 + body.size());
    e57_test_put<std::uint64_t>(header, e57_test_physical(section + 32));
    e57_test_put<std::uint64_t>(header, 0);
    logical.insert(logical.end(), header.begin(), header.end());
    logical.insert(logical.end(), body.begin(), body.end());
    std::string prototype;
    for (const auto& f : s.fields) {
      prototype += "<" + f.name + " type=\"" + f.type + "\"";
      if (f.type == "Float" && f.single) prototype += " precision=\"single\"";
      if (f.type != "Float")
        prototype += " minimum=\"" + std::to_string(f.minimum) + "\" maximum=\"" + std::to_string(f.maximum) + "\"";
      if (f.type == "ScaledInteger")
        prototype += " scale=\"" + e57_test_number(f.scale) + "\" offset=\"" + e57_test_number(f.offset) + "\"";
      prototype += "/>";
    }
    std::string pose = s.pose_xml;
    if (s.pose) {
      const auto& q = *s.pose;
      pose = "<pose type=\"Structure\"><rotation type=\"Structure\"><w type=\"Float\">" + e57_test_number(q[0]) +
             "</w><x type=\"Float\">" + e57_test_number(q[1]) + "</x><y type=\"Float\">" + e57_test_number(q[2]) +
             "</y><z type=\"Float\">" + e57_test_number(q[3]) +
             "</z></rotation><translation type=\"Structure\"><x type=\"Float\">" + e57_test_number(q[4]) +
             "</x><y type=\"Float\">" + e57_test_number(q[5]) + "</y><z type=\"Float\">" + e57_test_number(q[6]) +
             "</z></translation></pose>";
    }
    data3d += "<vectorChild type=\"Structure\"><name type=\"String\"><![CDATA[" + s.name + "]]></name>" + pose +
              "<points type=\"CompressedVector\" fileOffset=\"" + std::to_string(e57_test_physical(section)) +
              "\" recordCount=\"" + std::to_string(s.stated_records.value_or(records)) +
              "\"><prototype type=\"Structure\">" + prototype +
              "</prototype><codecs type=\"Vector\" allowHeterogeneousChildren=\"1\"></codecs></points></vectorChild>";
  }
  const std::string xml =
      "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n<e57Root type=\"Structure\" "
      "xmlns=\"http://www.astm.org/COMMIT/E57/2010-e57-v1.0\"><formatName type=\"String\"><![CDATA[ASTM E57 3D "
      "Imaging Data File]]></formatName><versionMajor type=\"Integer\">1</versionMajor><coordinateMetadata "
      "type=\"String\"><![CDATA[" +
      coordinate_metadata +
      "]]></coordinateMetadata><e57LibraryVersion "
      "type=\"String\"><![CDATA[vola tests]]></e57LibraryVersion><data3D type=\"Vector\" "
      "allowHeterogeneousChildren=\"1\">" +
      data3d + "</data3D><images2D type=\"Vector\" allowHeterogeneousChildren=\"1\"></images2D></e57Root>\n";
  const std::uint64_t xml_at = logical.size();
  logical.insert(logical.end(), xml.begin(), xml.end());
  while (logical.size() % 1020) logical.push_back(0);
  const std::uint64_t pages = logical.size() / 1020;
  std::vector<std::uint8_t> h;
  for (char c : std::string("ASTM-E57")) h.push_back(static_cast<std::uint8_t>(c));
  e57_test_put<std::uint32_t>(h, 1);
  e57_test_put<std::uint32_t>(h, 0);
  e57_test_put<std::uint64_t>(h, pages * 1024);
  e57_test_put<std::uint64_t>(h, e57_test_physical(xml_at));
  e57_test_put<std::uint64_t>(h, xml.size());
  e57_test_put<std::uint64_t>(h, 1024);
  std::memcpy(logical.data(), h.data(), 48);
  std::vector<std::uint8_t> file;
  for (std::uint64_t p = 0; p < pages; ++p) {
    const std::uint8_t* page = logical.data() + p * 1020;
    file.insert(file.end(), page, page + 1020);
    const std::uint32_t crc = e57_test_crc32c(page, 1020);
    for (int k = 3; k >= 0; --k) file.push_back(static_cast<std::uint8_t>(crc >> (8 * k)));
  }
  return file;
}

}  // namespace vola_io_test
