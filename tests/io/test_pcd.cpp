// PCD reader: the shared files against EXPECTED.txt; files of each DATA kind written
// here field by field (binary_compressed with liblzf's lzf_compress); truncated and
// corrupted input.
#include <gtest/gtest.h>
#include <lzf.h>

#include <bit>
#include <cctype>
#include <cmath>
#include <limits>
#include <optional>
#include <sstream>
#include <string>
#include <vector>

#include "io_test_data.hpp"
#include "vola/io/input.hpp"
#include "vola/io/pcd.hpp"

namespace {

using namespace vola_io_test;

// EXPECTED.txt's "fields=['x', 'y', ...]" of a PCD line.
std::optional<std::vector<std::string>> expected_fields(const std::string& line) {
  const auto start = line.find("fields=[");
  if (start == std::string::npos) return std::nullopt;
  const auto end = line.find(']', start);
  if (end == std::string::npos) return std::nullopt;
  std::vector<std::string> fields;
  for (std::size_t at = line.find('\'', start); at < end; at = line.find('\'', at + 1)) {
    const auto close = line.find('\'', at + 1);
    fields.push_back(line.substr(at + 1, close - at - 1));
    at = close;
  }
  return fields;
}

std::string lower(std::string s) {
  for (char& c : s) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return s;
}

TEST(Pcd, SharedFilesMatchExpected) {
  VOLA_REQUIRE_DATA(data);
  const auto files = files_ending(data / "pcd", ".pcd");
  ASSERT_FALSE(files.empty());
  for (const auto& path : files) {
    SCOPED_TRACE(path.string());
    const std::string line = expected_line(data, path.filename().string());
    const vola::io::Input in = vola::io::read_input(path.string(), "auto", {});
    EXPECT_EQ(in.format, "pcd");
    // EXPECTED.txt: "points=N decoded=N finite=F min=[...] max=[...]"; non-finite points are dropped.
    ASSERT_TRUE(expected_integer(line, "finite="));
    EXPECT_EQ(in.cloud.size(), *expected_integer(line, "finite="));
    const auto min = expected_numbers(line, "min=");
    const auto max = expected_numbers(line, "max=");
    if (min && max) {  // one line is cut short in EXPECTED.txt
      const vola::Box box = in.cloud.bounds();
      for (std::size_t a = 0; a < 3; ++a) {
        EXPECT_NEAR(box.min[a], (*min)[a], 5.1e-4) << "axis " << a;  // EXPECTED rounds to 3 decimals
        EXPECT_NEAR(box.max[a], (*max)[a], 5.1e-4) << "axis " << a;
      }
    }
    // Colours make three columns (red, green, blue) of one or three fields; every other
    // field but x, y, z is a column of its own.
    const auto fields = expected_fields(line);
    ASSERT_TRUE(fields) << line;
    std::size_t columns = 0;
    for (const std::string& f : *fields) {
      const std::string key = lower(f);
      if (key == "x" || key == "y" || key == "z" || key == "green" || key == "blue") continue;
      columns += key == "rgb" || key == "rgba" || key == "red" ? 3 : 1;
    }
    EXPECT_EQ(in.cloud.attributes.size(), columns);
    for (const auto& a : in.cloud.attributes) EXPECT_EQ(a.values.size(), in.cloud.size()) << a.name;
  }
}

// PDAL's PCD writer spells LAS fields its way: they come out under the LAS reader's
// column names, with its reductions, and equal to the LAS file's values.
TEST(Pcd, PdalsLasFieldsComeOutAsTheLasReadersColumns) {
  VOLA_REQUIRE_DATA(data);
  const auto pcd = vola::io::read_input((data / "pcd" / "pdal_autzen-utm.pcd").string(), "auto", {});
  const auto find = [&](const std::string& name) -> const vola::PointAttribute* {
    for (const auto& a : pcd.cloud.attributes)
      if (a.name == name) return &a;
    return nullptr;
  };
  for (const char* name : {"intensity", "return_number", "number_of_returns", "scan_direction_flag",
                           "edge_of_flight_line", "classification", "scan_angle_rank", "user_data", "point_source_id",
                           "gps_time", "red", "green", "blue"})
    EXPECT_TRUE(find(name)) << name;
  ASSERT_TRUE(find("classification") && find("number_of_returns") && find("point_source_id"));
  EXPECT_EQ(find("classification")->reduction, vola::Reduction::majority);
  // PointSourceId is an identifier by its spelling (the lower-cased pointsourceid is not):
  // a voxel takes its points' most common one, as from LAS, PLY and NPY, not their mean.
  EXPECT_EQ(find("point_source_id")->reduction, vola::Reduction::majority);
  EXPECT_EQ(find("number_of_returns")->reduction, vola::Reduction::max);
  // The same survey as LAS (EXPECTED.txt: both 1065 points): classes point for point.
  const auto las = vola::io::read_input((data / "las" / "pdal_autzen-utm.las").string(), "auto", {});
  ASSERT_EQ(las.cloud.size(), pcd.cloud.size());
  const vola::PointAttribute* las_class = nullptr;
  for (const auto& a : las.cloud.attributes)
    if (a.name == "classification") las_class = &a;
  ASSERT_TRUE(las_class);
  EXPECT_EQ(find("classification")->values, las_class->values);
}

TEST(Pcd, OrganizedCloudDropsItsNaNPoints) {
  VOLA_REQUIRE_DATA(data);
  const auto path = data / "pcd" / "pcl_table_scene_mug_stereo_textured.pcd";
  vola::io::InputOptions options;
  options.payload = true;
  std::uint64_t not_finite = 0;
  const auto cloud = vola::io::read_pcd(path.string(), options, &not_finite);
  // EXPECTED.txt: W=640 H=480 points=307200 finite=209280.
  EXPECT_EQ(cloud.size(), 209280u);
  EXPECT_EQ(not_finite, 307200u - 209280u);  // counted, so that vola map and convert can say so
  EXPECT_EQ(vola::io::read_input(path.string(), "auto", options).not_finite, not_finite);
  EXPECT_EQ(cloud.payload.size(), cloud.size());
  for (double v : cloud.xyz) ASSERT_TRUE(std::isfinite(v));
}

// ---- Hand-made files ----

struct Sample {
  std::vector<std::array<double, 3>> xyz;  // some not finite
  std::vector<std::uint32_t> rgb;          // 0x00RRGGBB
  std::vector<std::uint16_t> intensity;
};

Sample sample() {
  const double nan = std::numeric_limits<double>::quiet_NaN();
  Sample s;
  s.xyz = {{1.5, -2.25, 3.0}, {nan, nan, nan}, {-0.125, 1e-3, 250.0}, {4.0, nan, 1.0}, {0.0, 0.0, 0.0}, {7.0, 8.0, -9.5}};
  s.rgb = {0xFF0010u, 0u, 0x010203u, 0x808080u, 0u, 0xC8C9CAu};
  s.intensity = {0, 1, 65535, 3, 400, 12};
  return s;
}

// Fields: x y z (F4, or F8 upper case), rgb (F4 packed), a normal of COUNT 3 (F4),
// intensity (U2), label (I8). Width 3, height 2 (organized).
Bytes pcd_bytes(const Sample& s, const std::string& data_kind, bool doubles, bool rgb_as_integer_text = true,
                const std::string& version = "0.7") {
  const std::size_t n = s.xyz.size();
  std::ostringstream h;
  h << "# .PCD v" << version << " - made by the vola tests\nVERSION " << version << "\n";
  h << (doubles ? "FIELDS X Y Z rgb normal intensity label\nSIZE 8 8 8 4 4 2 8\nTYPE F F F F F U I\n"
                : "FIELDS x y z rgb normal intensity label\nSIZE 4 4 4 4 4 2 8\nTYPE F F F F F U I\n");
  h << "COUNT 1 1 1 1 3 1 1\nWIDTH 3\nHEIGHT 2\n";
  if (version != ".5") h << "VIEWPOINT 0 0 0 1 0 0 0\n";
  h << "POINTS " << n << "\nDATA " << data_kind << "\n";
  Bytes out;
  put_text(out, h.str());
  const int coordinate_size = doubles ? 8 : 4;
  auto coordinate = [&](Bytes& b, double v) {
    if (doubles) put<double>(b, v);
    else put<float>(b, static_cast<float>(v));
  };
  auto normal = [](std::size_t i, int k) { return static_cast<float>(i) + 0.5f * static_cast<float>(k); };
  auto label = [](std::size_t i) { return -static_cast<std::int64_t>(i) * 1000000007; };
  if (data_kind == "ascii") {
    std::ostringstream body;
    body.precision(17);
    for (std::size_t i = 0; i < n; ++i) {
      for (double v : s.xyz[i]) {
        if (std::isnan(v)) body << "nan ";
        else body << v << ' ';
      }
      if (rgb_as_integer_text) body << s.rgb[i];
      else body << std::bit_cast<float>(s.rgb[i]);
      for (int k = 0; k < 3; ++k) body << ' ' << normal(i, k);
      body << ' ' << s.intensity[i] << ' ' << label(i) << "\n";
    }
    put_text(out, body.str());
    return out;
  }
  Bytes records;
  if (data_kind == "binary") {
    for (std::size_t i = 0; i < n; ++i) {
      for (double v : s.xyz[i]) coordinate(records, v);
      put<std::uint32_t>(records, s.rgb[i]);
      for (int k = 0; k < 3; ++k) put<float>(records, normal(i, k));
      put<std::uint16_t>(records, s.intensity[i]);
      put<std::int64_t>(records, label(i));
    }
    out.insert(out.end(), records.begin(), records.end());
    return out;
  }
  // binary_compressed: each field's values for all points, one field after another.
  for (int a = 0; a < 3; ++a)
    for (std::size_t i = 0; i < n; ++i) coordinate(records, s.xyz[i][static_cast<std::size_t>(a)]);
  for (std::size_t i = 0; i < n; ++i) put<std::uint32_t>(records, s.rgb[i]);
  for (std::size_t i = 0; i < n; ++i)
    for (int k = 0; k < 3; ++k) put<float>(records, normal(i, k));
  for (std::size_t i = 0; i < n; ++i) put<std::uint16_t>(records, s.intensity[i]);
  for (std::size_t i = 0; i < n; ++i) put<std::int64_t>(records, label(i));
  EXPECT_EQ(records.size(), n * (3 * static_cast<std::size_t>(coordinate_size) + 4 + 12 + 2 + 8));
  Bytes packed(records.size() * 2 + 64);
  const unsigned compressed = lzf_compress(records.data(), static_cast<unsigned>(records.size()), packed.data(),
                                           static_cast<unsigned>(packed.size()));
  EXPECT_GT(compressed, 0u);
  put<std::uint32_t>(out, compressed);
  put<std::uint32_t>(out, static_cast<std::uint32_t>(records.size()));
  out.insert(out.end(), packed.begin(), packed.begin() + compressed);
  return out;
}

void expect_sample(const vola::PointCloud& cloud, const Sample& s, bool doubles) {
  std::size_t k = 0;
  // red, green, blue, intensity, then normal (COUNT 3: normal_0, _1, _2) and label (I8, a
  // class: majority).
  ASSERT_EQ(cloud.attributes.size(), 8u);
  EXPECT_EQ(cloud.attributes[3].name, "intensity");
  for (std::size_t c = 0; c < 3; ++c) EXPECT_EQ(cloud.attributes[4 + c].name, "normal_" + std::to_string(c));
  EXPECT_EQ(cloud.attributes[7].name, "label");
  EXPECT_EQ(cloud.attributes[7].type, vola::ValueType::i64);
  EXPECT_EQ(cloud.attributes[7].reduction, vola::Reduction::majority);
  for (std::size_t i = 0; i < s.xyz.size(); ++i) {
    if (!std::isfinite(s.xyz[i][0]) || !std::isfinite(s.xyz[i][1]) || !std::isfinite(s.xyz[i][2])) continue;
    ASSERT_LT(k, cloud.size());
    for (std::size_t a = 0; a < 3; ++a)
      EXPECT_EQ(cloud.xyz[3 * k + a], doubles ? s.xyz[i][a] : static_cast<double>(static_cast<float>(s.xyz[i][a])));
    const double rgb[3] = {static_cast<double>(s.rgb[i] >> 16), static_cast<double>((s.rgb[i] >> 8) & 255),
                           static_cast<double>(s.rgb[i] & 255)};
    for (std::size_t c = 0; c < 3; ++c) EXPECT_EQ(cloud.attributes[c].values[k], rgb[c]) << "point " << i;
    EXPECT_EQ(cloud.attributes[3].values[k], s.intensity[i]);
    for (std::size_t c = 0; c < 3; ++c)
      EXPECT_EQ(cloud.attributes[4 + c].values[k], static_cast<double>(i) + 0.5 * static_cast<double>(c))
          << "point " << i;
    EXPECT_EQ(cloud.attributes[7].values[k], static_cast<double>(-static_cast<std::int64_t>(i) * 1000000007));
    EXPECT_EQ(cloud.payload[k], std::uint64_t{s.rgb[i] >> 16} | std::uint64_t{(s.rgb[i] >> 8) & 255} << 8 |
                                    std::uint64_t{s.rgb[i] & 255} << 16);
    ++k;
  }
  EXPECT_EQ(cloud.size(), k);
  EXPECT_EQ(k, 4u);  // two of the six points have a NaN coordinate
}

TEST(Pcd, HandMadeFilesOfEveryDataKind) {
  const Sample s = sample();
  vola::io::InputOptions options;
  options.payload = true;
  for (const std::string kind : {"ascii", "binary", "binary_compressed"})
    for (const bool doubles : {false, true})
      for (const std::string version : {".5", "0.7"}) {
        SCOPED_TRACE(kind + (doubles ? " F8 upper case" : " F4") + " v" + version);
        expect_sample(vola::io::parse_pcd(pcd_bytes(s, kind, doubles, true, version), "sample.pcd", options), s, doubles);
      }
  // A float rgb written as the float itself rather than its bit pattern.
  expect_sample(vola::io::parse_pcd(pcd_bytes(s, "ascii", false, false), "float_rgb.pcd", options), s, false);
}

TEST(Pcd, SeparateColourFieldsAndNoColours) {
  const std::string text =
      "VERSION 0.7\nFIELDS x y z Red Green Blue\nSIZE 4 4 4 2 2 2\nTYPE F F F U U U\nCOUNT 1 1 1 1 1 1\n"
      "WIDTH 2\nHEIGHT 1\nPOINTS 2\nDATA ascii\n1 2 3 65535 256 255\n\n4 5 6 0 512 1024\n";
  vola::io::InputOptions options;
  options.payload = true;
  const auto cloud = vola::io::parse_pcd(Bytes(text.begin(), text.end()), "channels.pcd", options);
  ASSERT_EQ(cloud.size(), 2u);
  ASSERT_EQ(cloud.attributes.size(), 3u);
  EXPECT_EQ(cloud.attributes[0].values, (std::vector<double>{65535, 0}));
  EXPECT_EQ(cloud.payload[0], 0xFFu | 1u << 8 | 0u << 16);
  EXPECT_EQ(cloud.payload[1], 0u | 2u << 8 | 4u << 16);
  const std::string plain = "FIELDS x y z\nSIZE 4 4 4\nTYPE F F F\nWIDTH 1\nPOINTS 1\nDATA ascii\n1 2 3";
  const auto p = vola::io::parse_pcd(Bytes(plain.begin(), plain.end()), "plain.pcd", options);
  EXPECT_EQ(p.xyz, (std::vector<double>{1, 2, 3}));
  EXPECT_TRUE(p.attributes.empty());
  EXPECT_TRUE(p.payload.empty());  // the builder's default payload, as for any colourless input
}

// A field of a few values (COUNT <= 16) is a column per value; a descriptor (FPFH's 33)
// is not read, and the values after it still land in their own columns.
TEST(Pcd, FieldsOfSeveralValuesBecomeAColumnEachUpToSixteen) {
  std::string text =
      "FIELDS x y z fpfh uv\nSIZE 4 4 4 4 4\nTYPE F F F F F\nCOUNT 1 1 1 33 2\nWIDTH 1\nPOINTS 1\nDATA ascii\n1 2 3";
  for (int k = 0; k < 33; ++k) text += " " + std::to_string(100 + k);
  text += " 0.25 0.75\n";
  const auto cloud = vola::io::parse_pcd(Bytes(text.begin(), text.end()), "uv.pcd", {});
  ASSERT_EQ(cloud.attributes.size(), 2u);
  EXPECT_EQ(cloud.attributes[0].name, "uv_0");
  EXPECT_EQ(cloud.attributes[1].name, "uv_1");
  EXPECT_EQ(cloud.attributes[0].values, (std::vector<double>{0.25}));
  EXPECT_EQ(cloud.attributes[1].values, (std::vector<double>{0.75}));
}

TEST(Pcd, EveryTruncationOfBinaryDataIsAFormatError) {
  for (const std::string kind : {"binary", "binary_compressed"}) {
    const Bytes full = pcd_bytes(sample(), kind, false);
    for (std::size_t n = 0; n < full.size(); ++n) {
      const Bytes cut(full.begin(), full.begin() + static_cast<std::ptrdiff_t>(n));
      const auto error = vola_test::format_error_of([&] { vola::io::parse_pcd(cut, "cut.pcd"); });
      ASSERT_TRUE(error.has_value()) << kind << " cut at " << n;
      EXPECT_EQ(error->file(), "cut.pcd");
    }
  }
  const Bytes ascii = pcd_bytes(sample(), "ascii", false);
  const std::string text(ascii.begin(), ascii.end());
  const std::size_t last_line = text.rfind('\n', text.size() - 2);
  for (std::size_t n = 0; n < last_line; ++n) {
    const Bytes cut(ascii.begin(), ascii.begin() + static_cast<std::ptrdiff_t>(n));
    ASSERT_TRUE(vola_test::format_error_of([&] { vola::io::parse_pcd(cut, "cut.pcd"); })) << "ascii cut at " << n;
  }
}

std::optional<vola::FormatError> error_of(const Bytes& bytes) {
  return vola_test::format_error_of([&] { vola::io::parse_pcd(bytes, "bad.pcd"); });
}

Bytes with_text(const std::string& text) { return Bytes(text.begin(), text.end()); }

TEST(Pcd, CorruptedInputIsAFormatErrorNamingTheProblem) {
  const std::string fields = "FIELDS x y z\nSIZE 4 4 4\nTYPE F F F\n";
  struct Case {
    std::string text, cause;
  } cases[] = {
      {"VERSION 0.7\n" + fields, "without a DATA line"},
      {"VERSION 0.7\nBANANA 3\nDATA ascii\n", "unknown header line"},
      {"FIELDS x y z\nSIZE 4 4\nTYPE F F F\nPOINTS 0\nDATA ascii\n", "same number of fields"},
      {"FIELDS x y z\nSIZE 4 4 3\nTYPE F F F\nPOINTS 0\nDATA ascii\n", "TYPE F of SIZE 3"},
      {"FIELDS x y z\nSIZE 4 4 4\nTYPE F F Q\nPOINTS 0\nDATA ascii\n", "TYPE Q"},
      {fields + "COUNT 1 1 0\nPOINTS 0\nDATA ascii\n", "COUNT 0"},
      {fields + "COUNT 1 1 3\nPOINTS 0\nDATA ascii\n", "COUNT 3, expected 1"},
      {"FIELDS x y w\nSIZE 4 4 4\nTYPE F F F\nPOINTS 0\nDATA ascii\n", "no field z"},
      {fields + "WIDTH 2\nHEIGHT 2\nPOINTS 3\nDATA ascii\n", "not WIDTH x HEIGHT"},
      {fields + "DATA ascii\n", "how many points"},
      {fields + "POINTS 1\nDATA zipped\n", "not ascii, binary"},
      {fields + "POINTS 2\nDATA ascii\n1 2 3\n", "truncated"},
      {fields + "POINTS 1\nDATA ascii\n1 2\n", "2 values"},
      {fields + "POINTS 1\nDATA ascii\n1 two 3\n", "'two' is not a number"},
      {fields + "POINTS 1000000\nDATA binary\n", "truncated"},
      {fields + "POINTS 1\nDATA binary_compressed\n\x0c", "truncated"},
  };
  for (const auto& c : cases) {
    const auto error = error_of(with_text(c.text));
    ASSERT_TRUE(error) << c.text;
    EXPECT_NE(error->cause().find(c.cause), std::string::npos) << error->what() << "\nexpected: " << c.cause;
    EXPECT_TRUE(error->offset().has_value()) << error->what();
  }
  auto compressed = [&](std::uint32_t packed_size, std::uint32_t raw_size, const Bytes& lzf) {
    Bytes b = with_text(fields + "POINTS 1\nDATA binary_compressed\n");
    put<std::uint32_t>(b, packed_size);
    put<std::uint32_t>(b, raw_size);
    b.insert(b.end(), lzf.begin(), lzf.end());
    return error_of(b);
  };
  const auto wrong_size = compressed(3, 13, {0, 1, 2});
  ASSERT_TRUE(wrong_size);
  EXPECT_NE(wrong_size->cause().find("need 12"), std::string::npos) << wrong_size->what();
  const auto too_long = compressed(300, 12, {0, 1, 2});
  ASSERT_TRUE(too_long);
  EXPECT_NE(too_long->cause().find("runs past the end"), std::string::npos) << too_long->what();
  // LZF cannot inflate 2 bytes to 12 000 bytes; refused before allocating.
  Bytes big = with_text(fields + "POINTS 1000\nDATA binary_compressed\n");
  put<std::uint32_t>(big, 2);
  put<std::uint32_t>(big, 12000);
  put<std::uint16_t>(big, 0xE0E0);
  const auto inflated = error_of(big);
  ASSERT_TRUE(inflated);
  EXPECT_NE(inflated->cause().find("cannot hold"), std::string::npos) << inflated->what();
  // A back reference to before the start of the output, and a literal run that is too short.
  const auto backwards = compressed(2, 12, {0x20, 0x05});
  ASSERT_TRUE(backwards);
  EXPECT_NE(backwards->cause().find("corrupt"), std::string::npos) << backwards->what();
  const auto short_literal = compressed(3, 12, {11, 1, 2});
  ASSERT_TRUE(short_literal);
  EXPECT_NE(short_literal->cause().find("corrupt"), std::string::npos) << short_literal->what();
  // One-byte fields at LZF's best ratio: 40 M points of 3 values (8-byte doubles each, 960
  // MB) from 1.4 MB. Refused before inflating, by 2^25 + 8 values per compressed byte.
  const std::uint32_t points = 40'000'000, raw = 3 * points, packed = raw / 88 + 1;
  Bytes bomb = with_text("FIELDS x y z\nSIZE 1 1 1\nTYPE U U U\nPOINTS 40000000\nDATA binary_compressed\n");
  put<std::uint32_t>(bomb, packed);
  put<std::uint32_t>(bomb, raw);
  bomb.resize(bomb.size() + packed, 0);
  const auto values = error_of(bomb);
  ASSERT_TRUE(values);
  EXPECT_NE(values->cause().find("40000000 points of 3 values from 1363637 LZF bytes: more than the 44463528 values"),
            std::string::npos)
      << values->what();
}

}  // namespace
