// The LAZ encoder: whatever it writes, the decoder must give back byte for byte. Records
// come from every shared LAS file of a supported format, from every shared LAZ file
// (decoded), and from generated point streams that reach the coders' rare paths
// (scanner channel switches, interleaved and jumping GPS times, odd return numbers,
// every kind of wave-packet offset, arbitrary bytes).
#include <gtest/gtest.h>

#include <cstdlib>
#include <cstring>
#include <fstream>
#include <random>

#include "io_test_data.hpp"
#include "laz_test_support.hpp"
#include "vola/error.hpp"
#include "vola/io/las.hpp"

namespace {

namespace fs = vola_io_test::fs;
namespace laz = vola::io::laz;
using vola_laz_test::Bytes;
using vola_laz_test::LasFile;

void expect_round_trip(const laz::LaszipInfo& info, const Bytes& records, std::uint64_t chunk_points) {
  const LasFile made = vola_laz_test::make_laz(info, records, chunk_points);
  Bytes back;
  ASSERT_NO_THROW(back = vola_laz_test::decode_all(made));
  ASSERT_EQ(back.size(), records.size());
  const std::size_t n = info.record_length();
  for (std::size_t i = 0; i < records.size(); i += n)
    ASSERT_EQ(0, std::memcmp(back.data() + i, records.data() + i, n)) << "record " << i / n;
}

// Point streams that look like scans: drifting coordinates, pulses of 1-5 returns, GPS
// times on up to 3 interleaved sequences with regular steps, rare jumps and repeats.
// `noise` in [0, 1] replaces that share of the fields with arbitrary bytes.
Bytes generated_records(std::uint8_t format, std::uint16_t record_length, std::size_t count, std::uint64_t seed,
                        double noise) {
  std::mt19937_64 rng(seed);
  auto chance = [&rng](double p) { return std::uniform_real_distribution<double>(0, 1)(rng) < p; };
  auto any = [&rng]() { return static_cast<std::uint32_t>(rng()); };
  const bool layered = format >= 6;
  Bytes out(count * record_length);
  std::int32_t x = 1000, y = -5000, z = 300;
  double times[3] = {1e5, 2e5 + 0.25, 3.5e8};
  int sequence = 0, r = 1, n = 1, channel = 0;
  std::uint16_t rgb[4] = {100, 200, 300, 400};
  std::uint64_t wave_offset = 60;
  std::uint32_t wave_size = 4968;
  for (std::size_t i = 0; i < count; ++i) {
    std::uint8_t* p = out.data() + i * record_length;
    // Coordinates wrap like the format's 32-bit arithmetic.
    auto step = [](std::int32_t v, std::uint32_t by) { return static_cast<std::int32_t>(static_cast<std::uint32_t>(v) + by); };
    x = step(x, any() % 200 - 100);
    y = step(y, chance(0.05) ? any() : any() % 50 - 25);
    z = step(z, any() % 21 - 10);
    if (++r > n) {
      r = 1;
      n = 1 + static_cast<int>(any() % (layered ? 15 : 5));
      if (chance(0.1)) sequence = static_cast<int>(any() % 3);
      times[sequence] += chance(0.02) ? 1e7 * (any() % 7) : (chance(0.05) ? 0.0 : 1e-5 * (1 + any() % 3));
      if (layered && chance(0.05)) channel = static_cast<int>(any() % 4);
    }
    if (chance(0.02)) r = static_cast<int>(any() % 16);  // writers that number returns oddly
    const std::uint16_t intensity = static_cast<std::uint16_t>(chance(0.3) ? any() : 1000);
    std::memcpy(p, &x, 4), std::memcpy(p + 4, &y, 4), std::memcpy(p + 8, &z, 4), std::memcpy(p + 12, &intensity, 2);
    std::size_t at;
    if (!layered) {
      p[14] = static_cast<std::uint8_t>((r & 7) | ((n & 7) << 3) | (chance(0.1) ? 0x40 : 0) | (chance(0.01) ? 0x80 : 0));
      p[15] = static_cast<std::uint8_t>(chance(0.9) ? 2 : any() % 32);
      p[16] = static_cast<std::uint8_t>(chance(0.8) ? 0 : any());
      p[17] = static_cast<std::uint8_t>(chance(0.95) ? 7 : any());
      const auto source = static_cast<std::uint16_t>(chance(0.01) ? any() : 17);
      std::memcpy(p + 18, &source, 2);
      at = 20;
      if (format != 0 && format != 2) std::memcpy(p + at, &times[sequence], 8), at += 8;
    } else {
      p[14] = static_cast<std::uint8_t>((r & 15) | ((n & 15) << 4));
      p[15] = static_cast<std::uint8_t>((chance(0.05) ? any() % 16 : 0) | (channel << 4) | (chance(0.1) ? 0x40 : 0));
      p[16] = static_cast<std::uint8_t>(chance(0.9) ? 2 : any());
      p[17] = static_cast<std::uint8_t>(chance(0.9) ? 0 : any());
      const auto angle = static_cast<std::int16_t>(chance(0.2) ? any() : -300);
      const auto source = static_cast<std::uint16_t>(chance(0.01) ? any() : 17);
      std::memcpy(p + 18, &angle, 2), std::memcpy(p + 20, &source, 2), std::memcpy(p + 22, &times[sequence], 8);
      at = 30;
    }
    const std::size_t colours =
        format == 2 || format == 3 || format == 5 || format == 7 ? 3 : (format == 8 || format == 10 ? 4 : 0);
    if (colours) {
      if (chance(0.3)) rgb[0] = rgb[1] = rgb[2] = static_cast<std::uint16_t>(any());  // grey
      else if (chance(0.5)) for (auto& c : rgb) c = static_cast<std::uint16_t>(c + any() % 512 - 256);
      std::memcpy(p + at, rgb, 2 * colours);
      at += 2 * colours;
    }
    if (format == 4 || format == 5 || format >= 9) {
      // A wave packet: the offset repeats, follows the last packet, moves by a 32-bit
      // step or jumps beyond 32 bits (the four ways the coder codes it).
      p[at] = static_cast<std::uint8_t>(chance(0.95) ? 1 : any());
      const double kind = std::uniform_real_distribution<double>(0, 1)(rng);
      if (kind < 0.6) wave_offset += wave_size;
      else if (kind < 0.8) wave_offset += static_cast<std::uint64_t>(static_cast<std::int64_t>(static_cast<std::int32_t>(any())));
      else if (kind < 0.9) wave_offset = (std::uint64_t{any()} << 32) | any();
      if (chance(0.05)) wave_size = any() % 10000;
      const float return_point = static_cast<float>(5e5 + any() % 50000), t[3] = {1e-5f, -2.8e-5f, 1.4e-4f};
      std::memcpy(p + at + 1, &wave_offset, 8), std::memcpy(p + at + 9, &wave_size, 4);
      std::memcpy(p + at + 13, &return_point, 4), std::memcpy(p + at + 17, t, 12);
      at += 29;
    }
    for (; at < record_length; ++at) p[at] = static_cast<std::uint8_t>(chance(0.5) ? i : any());
    for (std::size_t b = 0; b < record_length; ++b)
      if (chance(noise)) p[b] = static_cast<std::uint8_t>(any());
  }
  return out;
}

// With VOLA_LAZ_OUT set: `records` as <name>.laz (vola's encoder, 1000-point chunks) and
// <name>.records, for tests/laz/lazperf_roundtrip.mjs.
void write_for_other_decoders(std::uint8_t format, std::uint16_t length, const Bytes& records, const std::string& name) {
  const char* out_dir = std::getenv("VOLA_LAZ_OUT");
  if (!out_dir) return;
  const Bytes las = vola_laz_test::las_file_bytes(format, length, records);
  const Bytes file = vola_laz_test::laz_from_las(vola_laz_test::parse_las_file(las, name), 1000);
  std::ofstream(fs::path(out_dir) / (name + ".laz"), std::ios::binary)
      .write(reinterpret_cast<const char*>(file.data()), static_cast<std::streamsize>(file.size()));
  std::ofstream(fs::path(out_dir) / (name + ".records"), std::ios::binary)
      .write(reinterpret_cast<const char*>(records.data()), static_cast<std::streamsize>(records.size()));
}

TEST(LazEncode, SharedLasFilesRoundTrip) {
  VOLA_REQUIRE_DATA(data);
  auto files = vola_io_test::files_ending(data / "las", ".las");
  ASSERT_FALSE(files.empty());
  int tested = 0;
  for (const fs::path& path : files) {
    SCOPED_TRACE(path.filename().string());
    const LasFile las = vola_laz_test::read_las_file(path);
    const laz::LaszipInfo info = laz::laszip_info_for(las.point_format, las.record_length);
    EXPECT_EQ(info.compressor, las.point_format <= 5 ? 2 : 3);
    const Bytes records = vola_laz_test::las_records(las);
    expect_round_trip(info, records, 50000);
    expect_round_trip(info, records, 333);  // many chunks, the last one short
    ++tested;
  }
  EXPECT_GE(tested, 20);
}

// Whole LAZ files from the shared LAS files. With VOLA_LAZ_OUT set, each is also written
// there as <name>.laz with its records as <name>.records, for another decoder to check
// (tests/laz/lazperf_roundtrip.mjs).
TEST(LazEncode, LasFilesBecomeLazFiles) {
  VOLA_REQUIRE_DATA(data);
  const char* out_dir = std::getenv("VOLA_LAZ_OUT");
  for (const fs::path& path : vola_io_test::files_ending(data / "las", ".las")) {
    const LasFile las = vola_laz_test::read_las_file(path);
    SCOPED_TRACE(path.filename().string());
    const Bytes records = vola_laz_test::las_records(las);
    const std::string stem = path.stem().string();
    for (const std::uint32_t chunk_points : {50000u, 500u}) {
      const Bytes file = vola_laz_test::laz_from_las(las, chunk_points);
      const LasFile laz = vola_laz_test::parse_las_file(file, stem + ".laz");
      EXPECT_EQ(laz.point_format, las.point_format);
      EXPECT_EQ(laz.point_count, las.point_count);
      EXPECT_TRUE(vola_laz_test::decode_all(laz) == records);
      if (out_dir && chunk_points == 500u) {
        std::ofstream(fs::path(out_dir) / (stem + ".laz"), std::ios::binary)
            .write(reinterpret_cast<const char*>(file.data()), static_cast<std::streamsize>(file.size()));
        std::ofstream(fs::path(out_dir) / (stem + ".records"), std::ios::binary)
            .write(reinterpret_cast<const char*>(records.data()), static_cast<std::streamsize>(records.size()));
      }
    }
  }
}

TEST(LazEncode, SharedLazFilesRoundTripWithTheirOwnItems) {
  VOLA_REQUIRE_DATA(data);
  for (const fs::path& path : vola_io_test::files_ending(data / "laz", ".laz")) {
    SCOPED_TRACE(path.filename().string());
    const LasFile file = vola_laz_test::read_las_file(path);
    const laz::LaszipInfo info = laz::parse_laszip_vlr(file.laszip);
    expect_round_trip(info, vola_laz_test::decode_all(file), info.chunk_size == laz::kVariableChunkSize ? 100 : info.chunk_size);
  }
}

TEST(LazEncode, GeneratedStreamsRoundTripInEveryFormat) {
  for (std::uint8_t format = 0; format <= 10; ++format) {
    for (const std::uint16_t extra : {std::uint16_t{0}, std::uint16_t{1}, std::uint16_t{13}}) {
      for (double noise : {0.0, 0.05, 1.0}) {
        SCOPED_TRACE("format " + std::to_string(format) + " extra " + std::to_string(extra) + " noise " +
                     std::to_string(noise));
        static constexpr std::uint16_t kBase[] = {20, 28, 26, 34, 57, 63, 30, 36, 38, 59, 67};
        const auto length = static_cast<std::uint16_t>(kBase[format] + extra);
        const Bytes records = generated_records(format, length, 3000, format * 100u + extra, noise);
        laz::LaszipInfo info = laz::laszip_info_for(format, length);
        expect_round_trip(info, records, 1000);
        const bool wave_packets = format == 4 || format == 5 || format >= 9;  // laz-perf has no coders for them
        if (!wave_packets)
          write_for_other_decoders(format, length, records, "generated_f" + std::to_string(format) + "_e" +
                                                              std::to_string(extra) + "_n" + std::to_string(int(noise * 100)));
        if (format >= 6) {  // version 4 items, and COPC-style variable chunks
          for (auto& item : info.items) item.version = 4;
          expect_round_trip(info, records, 700);
          info.chunk_size = laz::kVariableChunkSize;
          expect_round_trip(info, records, 450);
        }
      }
    }
  }
}

// Version 1 of the point-wise items (what LASzip 1.x wrote): `info` with every item
// but the wave packet (whose only version is 1) in version 1.
laz::LaszipInfo version_one(laz::LaszipInfo info) {
  for (auto& item : info.items) item.version = 1;
  return info;
}

// Version 1 items, alone and one at a time beside version 2 ones, in one unchunked
// stream (as LASzip 1.x wrote them) and in chunks. Each stream must differ from the
// version 2 stream of the same records: a reader that took version 1 for version 2
// would round-trip too.
TEST(LazEncode, VersionOneItemsRoundTrip) {
  for (std::uint8_t format = 0; format <= 5; ++format) {
    for (const std::uint16_t extra : {std::uint16_t{0}, std::uint16_t{3}}) {
      for (double noise : {0.0, 0.05, 1.0}) {
        SCOPED_TRACE("format " + std::to_string(format) + " extra " + std::to_string(extra) + " noise " +
                     std::to_string(noise));
        static constexpr std::uint16_t kBase[] = {20, 28, 26, 34, 57, 63};
        const auto length = static_cast<std::uint16_t>(kBase[format] + extra);
        const Bytes records = generated_records(format, length, 3000, 700u + format * 10u + extra, noise);
        const laz::LaszipInfo v2 = laz::laszip_info_for(format, length);
        laz::LaszipInfo v1 = version_one(v2);
        expect_round_trip(v1, records, 1000);
        EXPECT_NE(vola_laz_test::make_laz(v1, records, 1000).bytes, vola_laz_test::make_laz(v2, records, 1000).bytes);
        v1.compressor = 1;
        expect_round_trip(v1, records, 0);
        for (std::size_t i = 0; i < v2.items.size(); ++i) {
          if (v2.items[i].type == laz::kWavePacket13) continue;
          laz::LaszipInfo mixed = v2;
          mixed.items[i].version = 1;
          SCOPED_TRACE(laz::describe_item(mixed.items[i]));
          expect_round_trip(mixed, records, 1000);
          EXPECT_NE(vola_laz_test::make_laz(mixed, records, 1000).bytes,
                    vola_laz_test::make_laz(v2, records, 1000).bytes);
        }
      }
    }
  }
}

// Whole LASzip 1.x-style files (version 1 items, compressor 1) of every shared LAS
// file of formats 0-5, read through the LAS reader (`translate_las` to LAS), give the
// LAS file's records back.
TEST(LazEncode, VersionOneFilesReadLikeTheirLas) {
  VOLA_REQUIRE_DATA(data);
  vola_test::TempDir tmp;
  int tested = 0;
  for (const fs::path& path : vola_io_test::files_ending(data / "las", ".las")) {
    const LasFile las = vola_laz_test::read_las_file(path);
    if (las.point_format > 5) continue;
    SCOPED_TRACE(path.filename().string());
    laz::LaszipInfo info = version_one(laz::laszip_info_for(las.point_format, las.record_length));
    info.compressor = 1;
    const fs::path laz_path = tmp / (path.stem().string() + ".laz"), back = tmp / (path.stem().string() + ".las");
    Bytes file = vola_laz_test::laz_from_las(las, 0, info);
    // A LAS 1.3+ header's start of waveform data pointed into the LAS file, not this one.
    if (file[25] >= 3) std::memset(file.data() + 227, 0, 8);
    vola_test::write_bytes(laz_path, file);
    ASSERT_NO_THROW(vola::io::translate_las(laz_path.string(), back.string()));
    EXPECT_TRUE(vola_laz_test::las_records(vola_laz_test::read_las_file(back)) == vola_laz_test::las_records(las));
    ++tested;
  }
  EXPECT_GE(tested, 10);
}

// A chunk whose wave packets never change leaves their layer out; its points still
// carry the packet.
TEST(LazEncode, UnchangingWavePacketsRoundTrip) {
  for (const std::uint8_t format : {std::uint8_t{4}, std::uint8_t{9}, std::uint8_t{10}}) {
    SCOPED_TRACE("format " + std::to_string(format));
    const std::uint16_t length = format == 4 ? 57 : (format == 9 ? 59 : 67);
    Bytes records = generated_records(format, length, 2000, 11, 0.0);
    const std::size_t at = length - 29;
    for (std::size_t i = 1; i < 2000; ++i) std::memcpy(records.data() + i * length + at, records.data() + at, 29);
    laz::LaszipInfo info = laz::laszip_info_for(format, length);
    expect_round_trip(info, records, 600);
    if (format >= 9) {
      for (auto& item : info.items) item.version = 4;
      expect_round_trip(info, records, 600);
    }
  }
}

TEST(LazEncode, UnchunkedCompressorOneRoundTrips) {
  const Bytes records = generated_records(3, 34, 2000, 7, 0.01);
  laz::LaszipInfo info = laz::laszip_info_for(3, 34);
  info.compressor = 1;
  expect_round_trip(info, records, 0);
}

TEST(LazEncode, OnePointChunksAndTinyFiles) {
  for (const std::uint8_t format : {std::uint8_t{1}, std::uint8_t{7}}) {
    const std::uint16_t length = format == 1 ? std::uint16_t{28} : std::uint16_t{36};
    const Bytes records = generated_records(format, length, 5, 3, 0.5);
    const laz::LaszipInfo info = laz::laszip_info_for(format, length);
    expect_round_trip(info, records, 1);
    expect_round_trip(info, Bytes(records.begin(), records.begin() + length), 50000);
  }
}

TEST(LazEncode, VlrPayloadRoundTrips) {
  for (std::uint8_t format = 0; format <= 10; ++format) {
    laz::LaszipInfo info = laz::laszip_info_for(format, 70);
    EXPECT_EQ(info.record_length(), 70u);
    EXPECT_EQ(laz::parse_laszip_vlr(laz::laszip_vlr_payload(info)), info);
  }
  EXPECT_THROW(laz::laszip_info_for(11, 70), vola::InvalidArgument);
  EXPECT_THROW(laz::laszip_info_for(4, 56), vola::InvalidArgument);
  EXPECT_THROW(laz::laszip_info_for(3, 30), vola::InvalidArgument);
}

}  // namespace
