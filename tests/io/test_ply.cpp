// PLY reader: the shared files against EXPECTED.txt and against a slow istream-based
// reader written here from the PLY description; hand-made files of each encoding;
// truncated and corrupted input.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstring>

#include <fstream>
#include <map>
#include <sstream>

#include "io_test_data.hpp"
#include "vola/io/input.hpp"
#include "vola/io/ply.hpp"

namespace {

using namespace vola_io_test;

// ---- Slow reference: every value through an istream, one at a time ----
struct SlowPly {
  std::vector<double> xyz;
  std::vector<double> rgb;  // empty without uchar red/green/blue
  std::vector<std::vector<std::int64_t>> faces;
  std::vector<std::string> other_names;     // the vertex's other scalar properties
  std::vector<std::vector<double>> others;  // their values, one vector per name
};

double read_value(std::istream& in, const std::string& type, bool ascii, bool big) {
  if (ascii) {
    double v;
    in >> v;
    if (!in) throw std::runtime_error("slow reader: bad ascii value");
    return type == "float" || type == "float32" ? static_cast<float>(v) : v;
  }
  const std::map<std::string, int> sizes = {{"char", 1},  {"uchar", 1}, {"short", 2}, {"ushort", 2},
                                            {"int", 4},   {"uint", 4},  {"float", 4}, {"double", 8},
                                            {"int8", 1},  {"uint8", 1}, {"int16", 2}, {"uint16", 2},
                                            {"int32", 4}, {"uint32", 4}, {"float32", 4}, {"float64", 8}};
  const int n = sizes.at(type);
  unsigned char raw[8];
  for (int i = 0; i < n; ++i) {
    const int c = in.get();
    if (c == EOF) throw std::runtime_error("slow reader: truncated");
    raw[big ? n - 1 - i : i] = static_cast<unsigned char>(c);
  }
  auto as = [&](auto v) {
    std::memcpy(&v, raw, sizeof v);
    return static_cast<double>(v);
  };
  if (type == "char" || type == "int8") return as(std::int8_t{});
  if (type == "uchar" || type == "uint8") return as(std::uint8_t{});
  if (type == "short" || type == "int16") return as(std::int16_t{});
  if (type == "ushort" || type == "uint16") return as(std::uint16_t{});
  if (type == "int" || type == "int32") return as(std::int32_t{});
  if (type == "uint" || type == "uint32") return as(std::uint32_t{});
  if (type == "float" || type == "float32") return as(float{});
  return as(double{});
}

SlowPly slow_read(const Bytes& bytes) {
  std::istringstream in(std::string(bytes.begin(), bytes.end()));
  struct Prop {
    std::string name, type, count_type;
    bool list = false;
  };
  std::vector<std::pair<std::string, std::size_t>> elements;
  std::vector<std::vector<Prop>> props;
  std::string line, format;
  while (std::getline(in, line)) {
    if (!line.empty() && line.back() == '\r') line.pop_back();
    std::istringstream words(line);
    std::string key;
    words >> key;
    if (key == "format") words >> format;
    if (key == "element") {
      std::string name;
      std::size_t count;
      words >> name >> count;
      elements.push_back({name, count});
      props.emplace_back();
    }
    if (key == "property") {
      Prop p;
      words >> p.type;
      if (p.type == "list") {
        p.list = true;
        words >> p.count_type >> p.type;
      }
      words >> p.name;
      props.back().push_back(p);
    }
    if (key == "end_header") break;
  }
  const bool ascii = format == "ascii", big = format == "binary_big_endian";
  SlowPly out;
  for (std::size_t e = 0; e < elements.size(); ++e) {
    bool has_rgb = false;
    for (const auto& p : props[e]) has_rgb |= p.name == "red" && p.type == "uchar";
    for (std::size_t i = 0; i < elements[e].second; ++i) {
      std::map<std::string, double> scalars;
      for (const auto& p : props[e]) {
        if (!p.list) {
          scalars[p.name] = read_value(in, p.type, ascii, big);
          continue;
        }
        const auto n = static_cast<std::size_t>(read_value(in, p.count_type, ascii, big));
        std::vector<std::int64_t> items;
        for (std::size_t k = 0; k < n; ++k) items.push_back(static_cast<std::int64_t>(read_value(in, p.type, ascii, big)));
        if (elements[e].first == "face" && (p.name == "vertex_indices" || p.name == "vertex_index")) out.faces.push_back(items);
      }
      if (elements[e].first == "vertex") {
        for (const char* a : {"x", "y", "z"}) out.xyz.push_back(scalars.at(a));
        if (has_rgb)
          for (const char* c : {"red", "green", "blue"}) out.rgb.push_back(scalars.at(c));
        // Every other scalar property, once per name, in the header's order.
        std::size_t k = 0;
        for (const auto& p : props[e]) {
          const bool own = p.name == "x" || p.name == "y" || p.name == "z" ||
                           (has_rgb && (p.name == "red" || p.name == "green" || p.name == "blue"));
          if (p.list || own) continue;
          if (std::find(out.other_names.begin(), out.other_names.begin() + static_cast<std::ptrdiff_t>(k), p.name) !=
              out.other_names.begin() + static_cast<std::ptrdiff_t>(k))
            continue;
          if (out.other_names.size() == k) {
            out.other_names.push_back(p.name);
            out.others.emplace_back();
          }
          out.others[k++].push_back(scalars.at(p.name));
        }
      }
    }
  }
  return out;
}

// The reader's output must equal the slow reader's, value for value.
void expect_same_as_slow(const Bytes& bytes, const std::string& label) {
  SCOPED_TRACE(label);
  vola::io::InputOptions options;
  options.payload = true;
  const vola::io::Input in = vola::io::parse_ply(bytes, label, options);
  const SlowPly slow = slow_read(bytes);
  ASSERT_EQ(in.cloud.xyz, slow.xyz);
  // The vertex's other scalar properties follow the colours, in the header's order.
  const std::size_t colours = slow.rgb.empty() ? 0 : 3;
  ASSERT_EQ(in.cloud.attributes.size(), colours + slow.others.size());
  for (std::size_t k = 0; k < slow.others.size(); ++k) {
    EXPECT_EQ(in.cloud.attributes[colours + k].name, slow.other_names[k]);
    EXPECT_EQ(in.cloud.attributes[colours + k].values, slow.others[k]) << slow.other_names[k];
  }
  if (slow.rgb.empty()) {
    EXPECT_TRUE(in.cloud.payload.empty());
  } else {
    ASSERT_EQ(in.cloud.payload.size(), in.cloud.size());
    for (std::size_t i = 0; i < in.cloud.size(); ++i) {
      for (std::size_t c = 0; c < 3; ++c) ASSERT_EQ(in.cloud.attributes[c].values[i], slow.rgb[3 * i + c]) << i;
      const auto word = static_cast<std::uint64_t>(slow.rgb[3 * i]) | static_cast<std::uint64_t>(slow.rgb[3 * i + 1]) << 8 |
                        static_cast<std::uint64_t>(slow.rgb[3 * i + 2]) << 16;
      ASSERT_EQ(in.cloud.payload[i], word) << i;
    }
  }
  std::size_t expected_triangles = 0;
  for (const auto& f : slow.faces) expected_triangles += f.size() >= 3 ? f.size() - 2 : 0;
  ASSERT_EQ(in.triangles.size(), expected_triangles);
  // Each face's n - 2 triangles in turn, cut from its own corners (how they are cut,
  // fan or ears, is polygon_triangles' and tested there).
  std::size_t t = 0;
  for (const auto& f : slow.faces) {
    for (std::size_t k = 1; k + 1 < f.size(); ++k, ++t)
      for (std::size_t c = 0; c < 3; ++c) {
        const bool of_the_face = std::any_of(f.begin(), f.end(), [&](std::int64_t v) {
          for (std::size_t a = 0; a < 3; ++a)
            if (in.triangles[t][c][a] != slow.xyz[3 * static_cast<std::size_t>(v) + a]) return false;
          return true;
        });
        ASSERT_TRUE(of_the_face) << "triangle " << t << " corner " << c;
      }
  }
}

TEST(Ply, SharedFilesMatchExpectedAndTheSlowReader) {
  VOLA_REQUIRE_DATA(data);
  const auto files = files_ending(data / "ply", ".ply");
  ASSERT_FALSE(files.empty());
  for (const auto& path : files) {
    SCOPED_TRACE(path.string());
    const std::string line = expected_line(data, path.filename().string());
    const vola::io::Input in = vola::io::read_input(path.string(), "auto", {});
    EXPECT_EQ(in.format, "ply");
    // EXPECTED.txt: "elements=[('vertex', N, [...]), ('face', F, [...])] bbox=[min]..[max]".
    EXPECT_EQ(in.cloud.size(), expected_integer(line, "('vertex', ").value());
    const auto faces = expected_integer(line, "('face', ");
    // Every face in these files is a triangle, so triangles = faces (0 without faces).
    EXPECT_EQ(in.triangles.size(), faces.value_or(0));
    const auto min = expected_numbers(line, "bbox=").value();
    const auto max = expected_numbers(line, "]..").value();
    const vola::Box box = in.cloud.bounds();
    for (std::size_t a = 0; a < 3; ++a) {
      EXPECT_NEAR(box.min[a], min[a], 5.1e-5) << "axis " << a;  // EXPECTED rounds to 4 decimals
      EXPECT_NEAR(box.max[a], max[a], 5.1e-5) << "axis " << a;
    }
    expect_same_as_slow(vola_test::read_bytes(path), path.filename().string());
  }
}

TEST(Ply, VertexColoursOfTheCycloidBecomeAttributes) {
  VOLA_REQUIRE_DATA(data);
  const auto in = vola::io::read_ply((data / "ply" / "trimesh_cycloidal_binle.ply").string());
  ASSERT_EQ(in.cloud.attributes.size(), 4u);  // red, green, blue, then the alpha property
  EXPECT_EQ(in.cloud.attributes[3].name, "alpha");
  EXPECT_EQ(in.cloud.attributes[3].type, vola::ValueType::u8);
  EXPECT_EQ(in.cloud.attributes[0].name, "red");
  EXPECT_EQ(in.cloud.attributes[0].type, vola::ValueType::u16);
  EXPECT_EQ(in.cloud.attributes[0].reduction, vola::Reduction::mean);
  EXPECT_EQ(in.cloud.attributes[2].values.size(), in.cloud.size());
}

TEST(Ply, HandMadeFilesOfEveryEncodingAndCountType) {
  const PlySample sample = ply_sample();
  for (const std::string encoding : {"ascii", "binary_little_endian", "binary_big_endian"})
    for (const bool int_counts : {false, true}) {
      SCOPED_TRACE(encoding + (int_counts ? " int counts" : " uchar counts"));
      const Bytes bytes = ply_bytes(sample, encoding, int_counts);
      vola::io::InputOptions options;
      options.payload = true;
      const vola::io::Input in = vola::io::parse_ply(bytes, "sample.ply", options);
      ASSERT_EQ(in.cloud.size(), sample.xyz.size());
      for (std::size_t i = 0; i < sample.xyz.size(); ++i) {
        for (std::size_t a = 0; a < 3; ++a) EXPECT_EQ(in.cloud.xyz[3 * i + a], static_cast<double>(sample.xyz[i][a]));
        for (std::size_t c = 0; c < 3; ++c) EXPECT_EQ(in.cloud.attributes[c].values[i], sample.rgb[i][c]);
        EXPECT_EQ(in.cloud.payload[i], sample.rgb[i][0] | sample.rgb[i][1] << 8 | sample.rgb[i][2] << 16);
      }
      ASSERT_EQ(in.triangles.size(), fan_triangles(sample.faces).size());  // the two-corner face makes none
      expect_same_as_slow(bytes, "sample");                                // each face's triangles from its own corners
    }
}

TEST(Ply, OptionsLeaveOutAttributesAndPayload) {
  const Bytes bytes = ply_bytes(ply_sample(), "binary_little_endian", false);
  vola::io::InputOptions options;
  options.attributes = false;
  const auto in = vola::io::parse_ply(bytes, "sample.ply", options);
  EXPECT_TRUE(in.cloud.attributes.empty());
  EXPECT_TRUE(in.cloud.payload.empty());
  EXPECT_EQ(in.cloud.size(), 5u);
}

TEST(Ply, SixteenBitColoursGiveTheHighByteAsPayload) {
  Bytes b;
  put_text(b, "ply\r\nformat binary_big_endian 1.0\r\nelement vertex 2\r\nproperty double x\r\nproperty double y\r\n"
              "property double z\r\nproperty ushort red\r\nproperty ushort green\r\nproperty ushort blue\r\nend_header\r\n");
  for (int i = 0; i < 2; ++i) {
    for (int a = 0; a < 3; ++a) put<double>(b, i * 10.0 + a, true);
    for (std::uint16_t c : {std::uint16_t(65535), std::uint16_t(256), std::uint16_t(255 + i)}) put<std::uint16_t>(b, c, true);
  }
  vola::io::InputOptions options;
  options.payload = true;
  const auto in = vola::io::parse_ply(b, "u16.ply", options);
  ASSERT_EQ(in.cloud.size(), 2u);
  EXPECT_EQ(in.cloud.xyz[5], 12.0);
  EXPECT_EQ(in.cloud.attributes[0].values[0], 65535.0);
  EXPECT_EQ(in.cloud.attributes[2].values[1], 256.0);
  EXPECT_EQ(in.cloud.payload[0], 0xFFu | 1u << 8 | 0u << 16);
  EXPECT_EQ(in.cloud.payload[1], 0xFFu | 1u << 8 | 1u << 16);
}

TEST(Ply, FloatColoursAreUnitOrByteRangedByTheirValues) {
  // Float channels are 0..1 by convention, but many tools write 0..255: taken as 0..1,
  // every such colour came out white (255 255 255).
  const auto read = [](const std::string& values) {
    const std::string text =
        "ply\nformat ascii 1.0\nelement vertex 2\nproperty float x\nproperty float y\n"
        "property float z\nproperty float red\nproperty float green\nproperty float blue\n"
        "end_header\n" +
        values;
    vola::io::InputOptions options;
    options.payload = true;
    return vola::io::parse_ply(Bytes(text.begin(), text.end()), "float.ply", options);
  };
  const auto bytes = read("0 0 0 128 64 32\n1 1 1 200 100 0.5\n");
  EXPECT_EQ(bytes.cloud.attributes[0].values, (std::vector<double>{128, 200}));
  EXPECT_EQ(bytes.cloud.attributes[1].values, (std::vector<double>{64, 100}));
  EXPECT_EQ(bytes.cloud.attributes[2].values,
            (std::vector<double>{32, 1}));  // 0.5 of 0..255 rounds to 1 (half away from zero)
  EXPECT_EQ(bytes.cloud.payload,
            (std::vector<std::uint64_t>{128u | 64u << 8 | 32u << 16, 200u | 100u << 8 | 1u << 16}));
  const auto unit = read("0 0 0 1 0.5 0\n1 1 1 0.2 0 1\n");
  EXPECT_EQ(unit.cloud.attributes[0].values, (std::vector<double>{255, 51}));
  EXPECT_EQ(unit.cloud.attributes[1].values, (std::vector<double>{128, 0}));
  EXPECT_EQ(unit.cloud.payload, (std::vector<std::uint64_t>{255u | 128u << 8, 51u | 255u << 16}));
}

TEST(Ply, FacesBeforeVerticesAndPointsWithoutFaces) {
  const std::string text =
      "ply\nformat ascii 1.0\nelement face 1\nproperty list uint uint vertex_index\nelement vertex 4\n"
      "property double z\nproperty double y\nproperty double x\nend_header\n4 0 1 2 3\n0 0 0\n0 1 0\n1 1 0\n1 0 0\n";
  const auto in = vola::io::parse_ply(Bytes(text.begin(), text.end()), "faces_first.ply");
  ASSERT_EQ(in.cloud.size(), 4u);
  EXPECT_EQ(in.cloud.xyz[3 * 2], 0.0);      // x of vertex 2 is the third column
  EXPECT_EQ(in.cloud.xyz[3 * 2 + 2], 1.0);  // z of vertex 2 is the first
  ASSERT_EQ(in.triangles.size(), 2u);
  EXPECT_EQ(in.triangles[1][2], (vola::Point{0, 0, 1}));
  const std::string points = "ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\nproperty float y\n"
                             "property float z\nend_header\n1 2 3\n";
  const auto p = vola::io::parse_ply(Bytes(points.begin(), points.end()), "points.ply");
  EXPECT_FALSE(p.is_mesh());
  EXPECT_EQ(p.cloud.xyz, (std::vector<double>{1, 2, 3}));
}

// Triangle strips (the "tristrips" element of tinyply's test models): each index
// after the first two makes a triangle, -1 restarts, repeated corners make none.
TEST(Ply, TriangleStripsBecomeTriangles) {
  const std::string text =
      "ply\nformat ascii 1.0\nelement vertex 5\nproperty float x\nproperty float y\nproperty float z\n"
      "element tristrips 1\nproperty list int int vertex_indices\nend_header\n"
      "0 0 0\n1 0 0\n0 1 0\n1 1 0\n2 2 0\n"
      "9 0 1 2 3 -1 2 3 3 4\n";
  const auto in = vola::io::parse_ply(Bytes(text.begin(), text.end()), "strip.ply");
  ASSERT_EQ(in.cloud.size(), 5u);
  // 0 1 2, then 2 1 3 (the second turned to face as the first); after the restart 2 3 3
  // and 3 3 4 repeat a corner.
  ASSERT_EQ(in.triangles.size(), 2u);
  EXPECT_EQ(in.triangles[0], (vola::io::Triangle{vola::Point{0, 0, 0}, vola::Point{1, 0, 0}, vola::Point{0, 1, 0}}));
  EXPECT_EQ(in.triangles[1], (vola::io::Triangle{vola::Point{0, 1, 0}, vola::Point{1, 0, 0}, vola::Point{1, 1, 0}}));
  std::string bad = text;
  bad.replace(bad.rfind("4\n"), 2, "5\n");
  const auto error = vola_test::format_error_of([&] { vola::io::parse_ply(Bytes(bad.begin(), bad.end()), "bad.ply"); });
  ASSERT_TRUE(error);
  EXPECT_NE(error->cause().find("strip index 5"), std::string::npos) << error->cause();
}

TEST(Ply, EveryTruncationOfABinaryFileIsAFormatError) {
  for (const std::string encoding : {"binary_little_endian", "binary_big_endian"}) {
    const Bytes full = ply_bytes(ply_sample(), encoding, true);
    for (std::size_t n = 0; n < full.size(); ++n) {
      const Bytes cut(full.begin(), full.begin() + static_cast<std::ptrdiff_t>(n));
      const auto error = vola_test::format_error_of([&] { vola::io::parse_ply(cut, "cut.ply"); });
      ASSERT_TRUE(error.has_value()) << encoding << " cut at " << n;
      EXPECT_EQ(error->file(), "cut.ply");
    }
  }
}

TEST(Ply, TruncatedAsciiIsAFormatErrorWithTheLine) {
  const Bytes full = ply_bytes(ply_sample(), "ascii", false);
  // Cut inside the last line but one: the last face is missing.
  const std::string text(full.begin(), full.end());
  const std::size_t last_line = text.rfind('\n', text.size() - 2);
  for (std::size_t n = 0; n < last_line; ++n) {
    const Bytes cut(full.begin(), full.begin() + static_cast<std::ptrdiff_t>(n));
    ASSERT_TRUE(vola_test::format_error_of([&] { vola::io::parse_ply(cut, "cut.ply"); })) << "cut at " << n;
  }
  const Bytes cut(full.begin(), full.begin() + static_cast<std::ptrdiff_t>(last_line));
  const auto error = vola_test::format_error_of([&] { vola::io::parse_ply(cut, "cut.ply"); });
  ASSERT_TRUE(error);
  EXPECT_NE(error->cause().find("truncated"), std::string::npos) << error->what();
}

std::optional<vola::FormatError> error_of_text(const std::string& text) {
  return vola_test::format_error_of([&] { vola::io::parse_ply(Bytes(text.begin(), text.end()), "bad.ply"); });
}

TEST(Ply, CorruptedInputIsAFormatErrorNamingTheProblem) {
  const std::string head = "ply\nformat ascii 1.0\nelement vertex 2\nproperty float x\nproperty float y\nproperty float z\n";
  const std::string faces = "element face 1\nproperty list uchar int vertex_indices\nend_header\n0 0 0\n1 1 1\n";
  struct Case {
    std::string text, cause;
  } cases[] = {
      {"plx\n", "not a PLY file"},
      {"ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\n", "without end_header"},
      {"ply\nformat ebcdic 1.0\nend_header\n", "unknown encoding"},
      {"ply\nformat ascii 2.0\nend_header\n", "version"},
      {"ply\nproperty float x\nformat ascii 1.0\nend_header\n", "before any element"},
      {"ply\nformat ascii 1.0\nelement vertex -1\nend_header\n", "element count"},
      {"ply\nformat ascii 1.0\nelement vertex 1\nproperty quad x\nend_header\n", "unknown property type"},
      {"ply\nformat ascii 1.0\nelement vertex 1\nproperty list float int x\nend_header\n", "integer type"},
      {"ply\nformat ascii 1.0\nbogus line\nend_header\n", "unknown header keyword"},
      {"ply\nformat ascii 1.0\nelement face 0\nend_header\n", "no vertex element"},
      {"ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\nproperty float y\nend_header\n1 2\n", "no scalar property z"},
      {head + faces + "3 0 1 2\n", "refers to vertex 2"},
      {head + faces + "3 0 1 -1\n", "vertex index"},
      {head + faces + "3 0 1 0.5\n", "vertex index"},
      {head + faces + "-3 0 1 0\n", "list length"},
      {head + faces.substr(0, faces.find("0 0 0")) + "0 zero 0\n", "'zero' is not a number"},
      {"ply\nformat binary_little_endian 1.0\nelement vertex 1000000\nproperty double x\nproperty double y\n"
       "property double z\nend_header\n",
       "truncated"},
      // One element a line: a whole element more on a line, and a line short of values
      // (its element would take the next line's first value and shift the rest).
      {head + faces.substr(0, faces.find("0 0 0")) + "0 0 0 1 1 1\n3 0 1 1\n", "several elements on one line"},
      {head + faces.substr(0, faces.find("0 0 0")) + "0 0\n0 1 1 1\n3 0 1 1\n", "fewer values than the header"},
      // More elements than the header declares were left unread.
      {head + faces + "3 0 1 1\n2 2 2\n", "values after the last element"},
      {"ply\nformat binary_little_endian 1.0\nelement vertex 0\nproperty float x\nproperty float y\n"
       "property float z\nend_header\n0123456789ab",
       "12 bytes after the last element"},
  };
  for (const auto& c : cases) {
    const auto error = error_of_text(c.text);
    ASSERT_TRUE(error) << c.text;
    EXPECT_NE(error->cause().find(c.cause), std::string::npos) << error->what() << "\nexpected: " << c.cause;
    EXPECT_TRUE(error->offset().has_value()) << error->what();
  }
  // A binary list whose count claims 4 billion indices, and an ascii error's line.
  Bytes b;
  put_text(b, "ply\nformat binary_little_endian 1.0\nelement vertex 1\nproperty float x\nproperty float y\nproperty float z\n"
              "element face 1\nproperty list uint int vertex_indices\nend_header\n");
  for (int i = 0; i < 3; ++i) put<float>(b, 0.0f);
  put<std::uint32_t>(b, 0xFFFFFFFFu);
  const auto huge = vola_test::format_error_of([&] { vola::io::parse_ply(b, "huge.ply"); });
  ASSERT_TRUE(huge);
  EXPECT_NE(huge->cause().find("runs past the end"), std::string::npos) << huge->what();
  const auto line = error_of_text(head + faces + "3 0 1 5\n");
  ASSERT_TRUE(line);
  EXPECT_NE(line->cause().find("line 12"), std::string::npos) << line->what();
}

// One element a line: values after an element's properties on its line are skipped, not
// taken for the next element's ("x y z 99" under three properties shifted every later
// coordinate), as MeshLab writes faces with an undeclared list after their colour.
TEST(Ply, ValuesAfterAnElementsPropertiesOnItsLineAreSkipped) {
  const std::string text =
      "ply\nformat ascii 1.0\ncomment VCGLIB generated\nelement vertex 3\nproperty float x\nproperty float y\n"
      "property float z\nelement face 1\nproperty list uchar int vertex_indices\nproperty uchar red\nend_header\n"
      "0 0 0 99\n1 2 3\v\f\n4 5 6 \n3 0 1 2 9 6 1 1 1 1 1 1\n";  // vertical tab and form feed are spaces too
  const auto in = vola::io::parse_ply(Bytes(text.begin(), text.end()), "vcg.ply");
  ASSERT_EQ(in.triangles.size(), 1u);
  const std::array<double, 9> want = {0, 0, 0, 1, 2, 3, 4, 5, 6};
  for (int v = 0; v < 3; ++v)
    for (int k = 0; k < 3; ++k) EXPECT_EQ(in.triangles[0][v][k], want[3 * v + k]) << v << " " << k;
}

// pyntcloud's write_ply (with allow_bool) stores numpy bools as "property bool", one byte
// each; the bytes here are what it writes for two points with an is_green flag.
TEST(Ply, PyntcloudsOneByteBoolsAreRead) {
  std::string text =
      "ply\nformat binary_little_endian 1.0\nelement vertex 2\nproperty float x\nproperty float y\n"
      "property float z\nproperty bool is_green\nend_header\n";
  Bytes bytes(text.begin(), text.end());
  const auto put_point = [&](float x, float y, float z, std::uint8_t flag) {
    for (float v : {x, y, z}) {
      std::uint8_t raw[4];
      std::memcpy(raw, &v, 4);
      bytes.insert(bytes.end(), raw, raw + 4);
    }
    bytes.push_back(flag);
  };
  put_point(0.5f, 0.0f, 0.5f, 1);
  put_point(0.0f, 0.5f, 0.5f, 0);
  const auto in = vola::io::parse_ply(bytes, "diamond_with_bool.ply");
  ASSERT_EQ(in.cloud.size(), 2u);
  EXPECT_EQ(in.cloud.xyz[3], 0.0);
  EXPECT_EQ(in.cloud.xyz[4], 0.5);
  ASSERT_EQ(in.cloud.attributes.size(), 1u);
  EXPECT_EQ(in.cloud.attributes[0].name, "is_green");
  EXPECT_EQ(in.cloud.attributes[0].values, (std::vector<double>{1.0, 0.0}));
}

TEST(Ply, ElementsWithoutPropertiesTakeNoTimeWhateverTheirCount) {
  const std::string text = "ply\nformat ascii 1.0\nelement nothing 18446744073709551615\nelement vertex 1\n"
                           "property float x\nproperty float y\nproperty float z\nend_header\n1 2 3\n";
  const auto in = vola::io::parse_ply(Bytes(text.begin(), text.end()), "empty_elements.ply");
  EXPECT_EQ(in.cloud.size(), 1u);
}

}  // namespace
