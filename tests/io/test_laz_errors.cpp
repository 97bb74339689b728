// Malformed LAZ: every defect must surface as vola::FormatError (never a crash, a read
// outside the given bytes, or an allocation sized by an unchecked count). Run this
// executable under -fsanitize=address,undefined or valgrind to check the "never" part.
#include <gtest/gtest.h>

#include <cstring>
#include <random>

#include "io_test_data.hpp"
#include "laz_test_support.hpp"
#include "vola/error.hpp"

namespace {

namespace laz = vola::io::laz;
using vola_laz_test::Bytes;
using vola_laz_test::LasFile;

laz::ReadAt reader(const Bytes& bytes) {
  return [&bytes](std::uint64_t offset, std::uint64_t n, std::uint8_t* out) {
    if (offset > bytes.size() || n > bytes.size() - offset) throw std::runtime_error("read past the end");
    std::memcpy(out, bytes.data() + offset, n);
  };
}

std::vector<laz::ChunkEntry> chunks_of(const LasFile& f) {
  const laz::LaszipInfo info = laz::parse_laszip_vlr(f.laszip);
  return laz::read_chunk_table(info, reader(f.bytes), f.bytes.size(), f.offset_to_points, f.point_count, f.name);
}

std::uint64_t table_at(const LasFile& f) {
  std::uint64_t at;
  std::memcpy(&at, f.bytes.data() + f.offset_to_points, 8);
  return at;
}

// `f` with its chunk table replaced by one listing `chunks`.
LasFile with_table(LasFile f, const std::vector<laz::ChunkEntry>& chunks) {
  const Bytes table = laz::chunk_table_bytes(laz::parse_laszip_vlr(f.laszip), chunks);
  f.bytes.resize(table_at(f));
  f.bytes.insert(f.bytes.end(), table.begin(), table.end());
  return f;
}

LasFile generated(std::uint8_t format, std::uint16_t length, std::size_t count, std::uint64_t chunk_points,
                  bool variable = false) {
  std::mt19937_64 rng(count);
  Bytes records(count * length);
  for (auto& b : records) b = static_cast<std::uint8_t>(rng() % 4);  // small changes: long chunks of data
  laz::LaszipInfo info = laz::laszip_info_for(format, length);
  if (variable) info.chunk_size = laz::kVariableChunkSize;
  return vola_laz_test::make_laz(info, records, chunk_points);
}

#define EXPECT_FORMAT_ERROR(statement) EXPECT_THROW(statement, vola::FormatError)

TEST(LazErrors, TruncatedChunksAreRefused) {
  for (const LasFile& f : {generated(3, 34, 3000, 1000), generated(8, 41, 3000, 1000)}) {
    SCOPED_TRACE(int{f.point_format});
    const laz::LaszipInfo info = laz::parse_laszip_vlr(f.laszip);
    const auto chunks = chunks_of(f);
    ASSERT_EQ(chunks.size(), 3u);
    Bytes records(chunks[0].point_count * f.record_length);
    for (std::uint64_t cut : {std::uint64_t{1}, std::uint64_t{5}, std::uint64_t{100}, chunks[0].byte_size - 10,
                              chunks[0].byte_size}) {
      SCOPED_TRACE(cut);
      const auto shorter = std::span(f.bytes).subspan(chunks[0].byte_offset, chunks[0].byte_size - cut);
      EXPECT_FORMAT_ERROR(laz::decode_chunk(info, shorter, chunks[0].point_count, records.data(), f.record_length, 0,
                                            chunks[0].byte_offset, f.name));
    }
  }
}

TEST(LazErrors, TruncatedFilesAreRefused) {
  LasFile f = generated(1, 28, 3000, 1000);
  f.bytes.resize(f.bytes.size() - 20);  // into the chunk table
  EXPECT_FORMAT_ERROR(vola_laz_test::decode_all(f));
  f.bytes.resize(f.offset_to_points + 1000);  // into the chunks: the table is past the end
  EXPECT_FORMAT_ERROR(vola_laz_test::decode_all(f));
  f.bytes.resize(f.offset_to_points + 3);  // not even the table's offset
  EXPECT_FORMAT_ERROR(vola_laz_test::decode_all(f));
}

TEST(LazErrors, LyingChunkTablesAreRefused) {
  for (const LasFile& f : {generated(0, 20, 3000, 1000), generated(6, 30, 3000, 1000)}) {
    auto chunks = chunks_of(f);
    auto shifted = chunks;
    shifted[0].byte_size -= 30;
    shifted[1].byte_size += 30;
    EXPECT_FORMAT_ERROR(vola_laz_test::decode_all(with_table(f, shifted)));
    auto longer = chunks;
    longer[2].byte_size += 1;  // runs into the table
    EXPECT_FORMAT_ERROR(vola_laz_test::decode_all(with_table(f, longer)));
    auto fewer = chunks;
    fewer.pop_back();  // the chunks hold fewer points than the header
    EXPECT_FORMAT_ERROR(vola_laz_test::decode_all(with_table(f, fewer)));
    auto more = chunks;
    more.push_back(more.back());
    EXPECT_FORMAT_ERROR(vola_laz_test::decode_all(with_table(f, more)));
    // The header claims fewer points than the chunks hold: a layered chunk says how many
    // it holds; a point-wise one does not (decoding fewer of its points is sound).
    LasFile fewer_points = f;
    fewer_points.point_count -= 1;
    if (laz::parse_laszip_vlr(f.laszip).compressor == 3) EXPECT_FORMAT_ERROR(vola_laz_test::decode_all(fewer_points));
    else EXPECT_NO_THROW(vola_laz_test::decode_all(fewer_points));
  }
}

TEST(LazErrors, ChunksClaimingMorePointsThanTheHeaderAreRefused) {
  const LasFile f = generated(7, 36, 2000, 700, true);  // variable-size chunks
  auto chunks = chunks_of(f);
  ASSERT_EQ(chunks.size(), 3u);
  auto more = chunks;
  more[1].point_count += 1;
  EXPECT_FORMAT_ERROR(vola_laz_test::decode_all(with_table(f, more)));
  auto huge = chunks;
  huge[0].point_count = 0xFFFFFFF0u;
  EXPECT_FORMAT_ERROR(vola_laz_test::decode_all(with_table(f, huge)));
  // A layered chunk also states its own count: it must agree with the table.
  auto shifted = chunks;
  shifted[0].point_count -= 1;
  shifted[1].point_count += 1;
  EXPECT_FORMAT_ERROR(vola_laz_test::decode_all(with_table(f, shifted)));
  // The table's chunk count beyond the points.
  LasFile many = f;
  const std::uint32_t lots = 0x7FFFFFFF;
  std::memcpy(many.bytes.data() + table_at(many) + 4, &lots, 4);
  EXPECT_FORMAT_ERROR(vola_laz_test::decode_all(many));
}

TEST(LazErrors, UnsupportedRecordsAreRefused) {
  const Bytes good = laz::laszip_vlr_payload(laz::laszip_info_for(3, 40));
  auto patched = [&good](std::size_t at, std::uint16_t value) {
    Bytes b = good;
    std::memcpy(b.data() + at, &value, 2);
    return b;
  };
  EXPECT_NO_THROW(laz::parse_laszip_vlr(good));
  EXPECT_FORMAT_ERROR(laz::parse_laszip_vlr(patched(0, 7)));        // compressor
  EXPECT_FORMAT_ERROR(laz::parse_laszip_vlr(patched(0, 0)));        // compressor "none"
  EXPECT_FORMAT_ERROR(laz::parse_laszip_vlr(patched(2, 1)));        // coder
  EXPECT_NO_THROW(laz::parse_laszip_vlr(patched(34 + 4, 1)));       // POINT10 version 1 (LASzip 1.x)
  EXPECT_FORMAT_ERROR(laz::parse_laszip_vlr(patched(34 + 4, 0)));   // POINT10 version 0
  EXPECT_FORMAT_ERROR(laz::parse_laszip_vlr(patched(34 + 4, 3)));   // POINT10 version 3
  EXPECT_FORMAT_ERROR(laz::parse_laszip_vlr(patched(34 + 10, 3)));  // GPSTIME11 version 3
  EXPECT_FORMAT_ERROR(laz::parse_laszip_vlr(patched(34 + 8, 9)));   // GPSTIME11 size
  EXPECT_FORMAT_ERROR(laz::parse_laszip_vlr(patched(34 + 6, 9)));   // WAVEPACKET13 (size 8: also wrong)
  EXPECT_FORMAT_ERROR(laz::parse_laszip_vlr(patched(34 + 12, 7)));  // GPSTIME11 twice
  EXPECT_FORMAT_ERROR(laz::parse_laszip_vlr(patched(32, 9)));       // more items than bytes
  EXPECT_FORMAT_ERROR(laz::parse_laszip_vlr(std::span(good).first(20)));
  Bytes wave = laz::laszip_vlr_payload(laz::laszip_info_for(1, 28));
  wave.insert(wave.end(), {9, 0, 29, 0, 2, 0});  // POINT10 GPSTIME11 WAVEPACKET13
  wave[32] = 3;
  try {
    laz::parse_laszip_vlr(wave, "w.laz", 100);
    ADD_FAILURE() << "wave packets accepted";
  } catch (const vola::FormatError& e) {
    EXPECT_NE(std::string(e.what()).find("WAVEPACKET13"), std::string::npos) << e.what();
    EXPECT_EQ(e.offset(), 100u + 34 + 12);
  }
  // Records whose length disagrees with the items.
  const LasFile f = generated(3, 34, 100, 100);
  Bytes records(100 * 40);
  EXPECT_FORMAT_ERROR(laz::decode_chunk(laz::parse_laszip_vlr(f.laszip), f.bytes, 100, records.data(), 40));
}

TEST(LazErrors, ChunkTableOffsets) {
  const LasFile f = generated(2, 26, 2500, 1000);
  const Bytes expected = vola_laz_test::decode_all(f);
  auto with_offset = [&f](std::uint64_t at) {
    LasFile g = f;
    std::memcpy(g.bytes.data() + g.offset_to_points, &at, 8);
    return g;
  };
  EXPECT_FORMAT_ERROR(vola_laz_test::decode_all(with_offset(f.bytes.size() + 10)));  // past the end
  EXPECT_FORMAT_ERROR(vola_laz_test::decode_all(with_offset(f.bytes.size() - 4)));
  EXPECT_FORMAT_ERROR(vola_laz_test::decode_all(with_offset(f.offset_to_points)));  // writer did not finish
  EXPECT_FORMAT_ERROR(vola_laz_test::decode_all(with_offset(3)));                   // before the point data
  // -1: the offset is in the file's last 8 bytes (a writer that could not seek back).
  LasFile tail = with_offset(~std::uint64_t{0});
  const std::uint64_t at = table_at(f);
  tail.bytes.resize(tail.bytes.size() + 8);
  std::memcpy(tail.bytes.data() + tail.bytes.size() - 8, &at, 8);
  EXPECT_EQ(vola_laz_test::decode_all(tail), expected);
  std::memset(tail.bytes.data() + tail.bytes.size() - 8, 0x7F, 8);
  EXPECT_FORMAT_ERROR(vola_laz_test::decode_all(tail));
  LasFile version = f;
  version.bytes[at] = 1;
  EXPECT_FORMAT_ERROR(vola_laz_test::decode_all(version));
}

// Random damage to real files: FormatError or (when the damage decodes) any records,
// but nothing else.
TEST(LazErrors, DamagedFilesFailCleanly) {
  VOLA_REQUIRE_DATA(data);
  std::mt19937_64 rng(2024);
  int refused = 0, decoded = 0;
  for (const char* name : {"laspy_simple.laz", "laspy_extra.laz", "pdal_autzen_clip_native.copc.laz",
                           "laspy_1_4_w_evlr.laz", "pdal_ept_1.2-with-color_0-0-0-0.laz"}) {
    const LasFile original = vola_laz_test::read_las_file(data / "laz" / name);
    for (int trial = 0; trial < 150; ++trial) {
      LasFile f = original;
      const int damage = 1 + static_cast<int>(rng() % 8);
      for (int d = 0; d < damage; ++d) {
        const std::size_t at = f.offset_to_points + rng() % (f.bytes.size() - f.offset_to_points);
        f.bytes[at] = trial % 3 == 0 ? static_cast<std::uint8_t>(rng()) : static_cast<std::uint8_t>(f.bytes[at] ^ (1u << (rng() % 8)));
      }
      if (trial % 5 == 0) f.bytes.resize(f.offset_to_points + rng() % (f.bytes.size() - f.offset_to_points));
      try {
        vola_laz_test::decode_all(f);
        ++decoded;
      } catch (const vola::FormatError&) {
        ++refused;
      }
    }
  }
  EXPECT_GT(refused, 300);
  std::printf("damaged files: %d refused, %d decoded (to whatever the damage says)\n", refused, decoded);
}

// A chunk size of 0 in the laszip record, as lasR's COPC writer leaves it
// (inst/extdata/example.copc.laz): LASzip and laz-perf start a chunk at the first point
// and never another, so a table of one chunk holds every point, and a table of more
// cannot be read that way.
TEST(LazErrors, ChunkSizeZeroIsOneChunkOfEveryPoint) {
  for (const auto& [format, length] : {std::pair<std::uint8_t, std::uint16_t>{3, 34}, {7, 36}}) {
    SCOPED_TRACE(int{format});
    const auto zero_chunk_size = [](LasFile f) {
      std::memset(f.laszip.data() + 12, 0, 4);  // the record's chunk size, in the file and the copy
      std::memset(f.bytes.data() + f.laszip_offset + 12, 0, 4);
      return f;
    };
    const LasFile one = generated(format, length, 3000, 3000);
    const LasFile zero = zero_chunk_size(one);
    ASSERT_EQ(laz::parse_laszip_vlr(zero.laszip).chunk_size, 0u);
    EXPECT_EQ(vola_laz_test::decode_all(zero), vola_laz_test::decode_all(one));
    const LasFile three = zero_chunk_size(generated(format, length, 3000, 1000));
    try {
      chunks_of(three);
      ADD_FAILURE() << "three chunks under a chunk size of 0 were read";
    } catch (const vola::FormatError& e) {
      EXPECT_NE(std::string(e.what()).find("chunk size of 0 puts every point in the first"), std::string::npos)
          << e.what();
    }
  }
}

}  // namespace
