// LAS files as real writers make them, beyond the shared ones: built byte by byte here.
// Coordinates print at the decimals of scale and offset; extra-bytes fields named like
// the record's own (or like each other, or not at all) get names of their own, and their
// no_data value reads as NaN; a file with GeoTIFF keys and a WKT record states the one
// global encoding bit 4 names; a laszip VLR left in an uncompressed file does not make
// it LAZ; waveform EVLRs are not read into memory.
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <string>
#include <vector>

#include "vola/error.hpp"
#include "vola/io/las.hpp"

namespace {

using Bytes = std::vector<std::uint8_t>;

template <class T>
void put_at(Bytes& b, std::size_t at, T value) {
  std::memcpy(b.data() + at, &value, sizeof value);
}

void put_text_at(Bytes& b, std::size_t at, const std::string& text) { std::memcpy(b.data() + at, text.data(), text.size()); }

struct Record {
  std::string user;
  std::uint16_t id = 0;
  Bytes data;
  bool extended = false;
};

// A LAS 1.`minor` file of point format 0 plus `extra` bytes a record, its points at
// (i, 2i, 3i) metres (scale 0.01), record bytes 20.. from `extra_of(i)`.
Bytes las_file(int minor, std::uint16_t global_encoding, const std::vector<Record>& records, std::size_t points,
               std::size_t extra, const std::function<Bytes(std::size_t)>& extra_of, std::uint8_t format_byte = 0) {
  const std::size_t header = minor >= 4 ? 375 : 227;
  Bytes b(header, 0);
  put_text_at(b, 0, "LASF");
  put_at<std::uint16_t>(b, 6, global_encoding);
  b[24] = 1;
  b[25] = static_cast<std::uint8_t>(minor);
  put_at<std::uint16_t>(b, 94, static_cast<std::uint16_t>(header));
  std::uint32_t vlr_count = 0;
  for (const Record& r : records) {
    if (r.extended) continue;
    Bytes v(54, 0);
    put_text_at(v, 2, r.user);
    put_at<std::uint16_t>(v, 18, r.id);
    put_at<std::uint16_t>(v, 20, static_cast<std::uint16_t>(r.data.size()));
    b.insert(b.end(), v.begin(), v.end());
    b.insert(b.end(), r.data.begin(), r.data.end());
    ++vlr_count;
  }
  put_at<std::uint32_t>(b, 96, static_cast<std::uint32_t>(b.size()));
  put_at<std::uint32_t>(b, 100, vlr_count);
  b[104] = format_byte;
  put_at<std::uint16_t>(b, 105, static_cast<std::uint16_t>(20 + extra));
  put_at<std::uint32_t>(b, 107, static_cast<std::uint32_t>(points));
  for (int a = 0; a < 3; ++a) {
    put_at<double>(b, 131 + 8 * a, 0.01);
    put_at<double>(b, 179 + 16 * a, static_cast<double>((a + 1) * (points ? points - 1 : 0)));  // max
  }
  for (std::size_t i = 0; i < points; ++i) {
    Bytes r(20 + extra, 0);
    for (int a = 0; a < 3; ++a) put_at<std::int32_t>(r, 4 * static_cast<std::size_t>(a), static_cast<std::int32_t>(100 * (a + 1) * i));
    r[14] = 1 | (1 << 3);  // return 1 of 1
    const Bytes e = extra_of(i);
    std::memcpy(r.data() + 20, e.data(), std::min(e.size(), extra));
    b.insert(b.end(), r.begin(), r.end());
  }
  std::uint32_t evlr_count = 0;
  const std::size_t evlr_start = b.size();
  for (const Record& r : records) {
    if (!r.extended) continue;
    Bytes v(60, 0);
    put_text_at(v, 2, r.user);
    put_at<std::uint16_t>(v, 18, r.id);
    put_at<std::uint64_t>(v, 20, r.data.size());
    b.insert(b.end(), v.begin(), v.end());
    b.insert(b.end(), r.data.begin(), r.data.end());
    ++evlr_count;
  }
  if (minor >= 4) {
    put_at<std::uint64_t>(b, 235, evlr_count ? evlr_start : 0);
    put_at<std::uint32_t>(b, 243, evlr_count);
    put_at<std::uint64_t>(b, 247, points);
  }
  return b;
}

// One extra-bytes descriptor (LAS 1.4 R15, 192 bytes).
Bytes descriptor(std::uint8_t type, const std::string& name, std::optional<std::int64_t> no_data = std::nullopt) {
  Bytes d(192, 0);
  d[2] = type;
  d[3] = no_data ? 1 : 0;
  put_text_at(d, 4, name);
  if (no_data) put_at<std::int64_t>(d, 40, *no_data);
  return d;
}

Bytes geokeys(std::uint16_t projected) {
  Bytes k(8 + 16, 0);
  const std::uint16_t head[4] = {1, 1, 0, 2};
  std::memcpy(k.data(), head, sizeof head);
  const std::uint16_t keys[8] = {1024, 0, 1, 1, 3072, 0, 1, projected};
  std::memcpy(k.data() + 8, keys, sizeof keys);
  return k;
}

Bytes text_bytes(const std::string& s) {
  Bytes b(s.begin(), s.end());
  b.push_back(0);
  return b;
}

const std::string kWkt32633 =
    "PROJCS[\"WGS 84 / UTM zone 33N\",GEOGCS[\"WGS 84\",DATUM[\"WGS_1984\",SPHEROID[\"WGS 84\",6378137,298.257223563]],"
    "PRIMEM[\"Greenwich\",0],UNIT[\"degree\",0.0174532925199433]],PROJECTION[\"Transverse_Mercator\"],"
    "PARAMETER[\"latitude_of_origin\",0],PARAMETER[\"central_meridian\",15],PARAMETER[\"scale_factor\",0.9996],"
    "PARAMETER[\"false_easting\",500000],PARAMETER[\"false_northing\",0],UNIT[\"metre\",1],AUTHORITY[\"EPSG\",\"32633\"]]";

vola::io::LasHeader header_of(const Bytes& file) { return vola::io::LasReader(file, "variant.las").header(); }

TEST(LasVariants, CoordinatesPrintAtTheDecimalsOfScaleAndOffset) {
  vola::io::LasHeader h;
  h.scale = {0.00025, -0.01, 0.01};
  h.offset = {515396, 0, 7350.194653};
  h.max = {515400, 96, 7400};
  EXPECT_EQ(h.coordinate_decimals(0), 5);  // RiSCAN's quarter millimetres
  EXPECT_EQ(h.coordinate_decimals(1), 2);  // a negative scale as its magnitude
  EXPECT_EQ(h.coordinate_decimals(2), 6);  // the offset's decimals
  EXPECT_EQ(h.coordinate_decimals(), 6);
  h.scale = {1.16451354e-06, 1, 1};  // 14 decimals, but a double holds 15 digits: 8 at 1.69e6
  h.offset = {1692500.352, 0, 0};
  h.max = {1694539.68, 0, 0};
  EXPECT_EQ(h.coordinate_decimals(0), 8);
}

TEST(LasVariants, ExtraBytesNamedLikeOtherFieldsGetNamesOfTheirOwn) {
  Bytes eb;
  for (const auto& name : {"classification", "a", "a", "", "Intensity", "height", "height", "echo width"}) {
    const Bytes d = descriptor(1, name);
    eb.insert(eb.end(), d.begin(), d.end());
  }
  const auto h = header_of(las_file(4, 0, {{"LASF_Spec", 4, eb}}, 3, 8, [](std::size_t) { return Bytes(8, 7); }));
  std::vector<std::string> names;
  for (const auto& f : h.extra_fields) names.push_back(f.name);
  EXPECT_EQ(names, (std::vector<std::string>{"classification_2", "a", "a_2", "attribute", "Intensity_2", "height",
                                             "height_2", "echo width"}));
  // PDAL's names of the flag bits are taken too: an extra "Withheld" hid the flag from
  // --where while the CSV named it Withheld_2.
  Bytes pdal_names;
  for (const auto& name : {"Withheld", "Synthetic", "KeyPoint", "Overlap", "ClassFlags"}) {
    const Bytes d = descriptor(1, name);
    pdal_names.insert(pdal_names.end(), d.begin(), d.end());
  }
  const auto p =
      header_of(las_file(4, 0, {{"LASF_Spec", 4, pdal_names}}, 3, 5, [](std::size_t) { return Bytes(5, 1); }));
  names.clear();
  for (const auto& f : p.extra_fields) names.push_back(f.name);
  EXPECT_EQ(names, (std::vector<std::string>{"Withheld_2", "Synthetic_2", "KeyPoint_2", "Overlap_2", "ClassFlags_2"}));
}

TEST(LasVariants, ExtraBytesNoDataReadsAsNaN) {
  Bytes eb = descriptor(6, "d", -9999);  // int32 with no_data -9999
  const Bytes file = las_file(4, 0, {{"LASF_Spec", 4, eb}}, 10, 4, [](std::size_t i) {
    Bytes v(4);
    const std::int32_t value = i % 5 == 0 ? -9999 : static_cast<std::int32_t>(i);
    std::memcpy(v.data(), &value, 4);
    return v;
  });
  vola::io::LasReader reader(file, "no_data.las");
  ASSERT_EQ(reader.header().extra_fields.size(), 1u);
  vola::io::LasChunk chunk;
  ASSERT_EQ(reader.read(chunk, 100), 10u);
  for (std::size_t i = 0; i < 10; ++i) {
    if (i % 5 == 0) EXPECT_TRUE(std::isnan(chunk.extra[0][i])) << i;
    else EXPECT_EQ(chunk.extra[0][i], static_cast<double>(i));
  }
  // The record-field path (the attribute columns' second pass) says the same.
  std::vector<vola::RecordField> fields;
  ASSERT_TRUE(vola::io::las_record_fields(reader.header(), fields));
  reader.rewind();
  const auto records = reader.read_records(100);
  std::vector<std::uint32_t> index(10);
  for (std::uint32_t i = 0; i < 10; ++i) index[i] = i;
  std::vector<std::vector<double>> values;
  vola::io::las_record_attribute_values(reader.header(), records.data(), index, values);
  EXPECT_TRUE(std::isnan(values.back()[0]) && std::isnan(values.back()[5]));
  EXPECT_EQ(values.back()[3], 3.0);
  EXPECT_TRUE(fields.back().has_no_data);
  EXPECT_EQ(fields.back().no_data, -9999.0);

  // A voxel's mean is over its points with data: all ten points in one voxel, points 0
  // and 5 without data, so (1 + 2 + 3 + 4 + 6 + 7 + 8 + 9) / 8. With payloads too (the
  // StreamBuilder path).
  for (const bool payload : {false, true}) {
    reader.rewind();
    vola::BuildOptions options;
    options.quantization = vola::Quantization::grid;
    options.voxel_size = 100.0;
    const vola::Tree tree = vola::io::build_las(reader, options, true, payload, nullptr);
    ASSERT_EQ(tree.voxel_count(), 1u);
    const auto* column = tree.attributes().find("d");
    ASSERT_NE(column, nullptr);
    EXPECT_EQ(column->get(0), 5.0) << "payload " << payload;
  }
}

TEST(LasVariants, KeysAndWktTheGlobalEncodingBitChooses) {
  const std::vector<Record> both = {{"LASF_Projection", 34735, geokeys(26915)},
                                    {"LASF_Projection", 2112, text_bytes(kWkt32633)}};
  const auto none = [](std::size_t) { return Bytes{}; };
  const auto wkt_bit = header_of(las_file(4, 16, both, 2, 0, none));
  EXPECT_FALSE(wkt_bit.epsg.has_value());  // the WKT's CRS, and no code from the keys beside it
  EXPECT_NE(wkt_bit.wkt.find("32633"), std::string::npos);
  const auto keys_bit = header_of(las_file(4, 0, both, 2, 0, none));
  EXPECT_EQ(keys_bit.epsg, 26915u);
  EXPECT_EQ(keys_bit.wkt.find("32633"), std::string::npos);
  const auto before_1_4 = header_of(las_file(2, 0, both, 2, 0, none));  // no bit: the WKT record, as before
  EXPECT_FALSE(before_1_4.epsg.has_value());
  EXPECT_NE(before_1_4.wkt.find("32633"), std::string::npos);
  const auto keys_alone = header_of(las_file(4, 16, {both[0]}, 2, 0, none));
  EXPECT_EQ(keys_alone.epsg, 26915u);
}

TEST(LasVariants, ALaszipRecordLeftInAnUncompressedFileIsIgnored) {
  Bytes laszip(34, 0);  // a laszip VLR's fixed part; its chunk table would be nonsense here
  put_at<std::uint16_t>(laszip, 0, 2);
  const Bytes file = las_file(2, 0, {{"laszip encoded", 22204, laszip}}, 4, 0, [](std::size_t) { return Bytes{}; });
  vola::io::LasReader reader(file, "left_over.las");
  EXPECT_FALSE(reader.header().compressed());
  vola::io::LasChunk chunk;
  ASSERT_EQ(reader.read(chunk, 10), 4u);
  EXPECT_DOUBLE_EQ(chunk.xyz[3 * 3 + 2], 9.0);
}

TEST(LasVariants, AVlrCountPastThePointsNamesBothFields) {
  Bytes file = las_file(2, 0, {}, 4, 0, [](std::size_t) { return Bytes{}; });
  put_at<std::uint32_t>(file, 100, 3);  // three VLRs that are not there
  try {
    vola::io::LasReader reader(file, "count.las");
    ADD_FAILURE() << "a VLR count past the points was accepted";
  } catch (const vola::FormatError& e) {
    const std::string message = e.what();
    EXPECT_NE(message.find("the 3 VLRs the header counts (byte 100) do not fit"), std::string::npos) << message;
    EXPECT_NE(message.find("0 of them end before it"), std::string::npos) << message;
  }
}

TEST(LasVariants, WaveformRecordsAreNotReadIntoMemory) {
  const std::vector<Record> records = {{"LASF_Spec", 65535, Bytes(1 << 20, 1), true},
                                       {"LASF_Projection", 2112, text_bytes(kWkt32633), true}};
  const auto h = header_of(las_file(4, 16, records, 2, 0, [](std::size_t) { return Bytes{}; }));
  ASSERT_EQ(h.vlrs.size(), 2u);
  EXPECT_TRUE(h.vlrs[0].data.empty());
  EXPECT_EQ(h.vlrs[0].length, 1u << 20);
  EXPECT_NE(h.wkt.find("32633"), std::string::npos);  // an EVLR the header is read from still is
}

}  // namespace
