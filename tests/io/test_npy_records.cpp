// Structured NumPy arrays (records of named fields, as laspy's points.array and PDAL's
// numpy writer save them) as points: x/y/z in any case, the other numeric fields as
// attribute columns, subarrays one column per element, padding and text skipped, and
// what cannot be read refused with the file and a cause.
#include <gtest/gtest.h>

#include <cstring>

#include "io_test_data.hpp"
#include "vola/error.hpp"
#include "vola/io/input.hpp"
#include "vola/io/npy.hpp"

namespace {

using namespace vola_io_test;

// An NPY 1.0 file: `descr` as numpy writes it (a list of field tuples), `shape`, data.
Bytes record_npy(const std::string& descr, const std::string& shape, const Bytes& data) {
  std::string dict = "{'descr': " + descr + ", 'fortran_order': False, 'shape': " + shape + ", }";
  while ((10 + dict.size() + 1) % 64) dict.push_back(' ');
  dict.push_back('\n');
  Bytes out = {0x93, 'N', 'U', 'M', 'P', 'Y', 1, 0};
  put<std::uint16_t>(out, static_cast<std::uint16_t>(dict.size()));
  put_text(out, dict);
  out.insert(out.end(), data.begin(), data.end());
  return out;
}

const vola::PointAttribute* attribute_named(const vola::PointCloud& cloud, const std::string& name) {
  for (const auto& a : cloud.attributes)
    if (a.name == name) return &a;
  return nullptr;
}

TEST(NpyRecords, FieldsBecomeCoordinatesAndColumns) {
  // X int32, y big-endian double, 3 bytes of padding, Z float32, Intensity uint16, an
  // rgb subarray of 3 uint8, a 4-byte string, Classification uint8: 29 bytes a record.
  const std::string descr =
      "[('X', '<i4'), ('y', '>f8'), ('', '|V3'), ('Z', '<f4'), ('Intensity', '<u2'), ('rgb', '|u1', (3,)), "
      "('name', '|S4'), ('Classification', '|u1')]";
  Bytes data;
  for (int i = 0; i < 2; ++i) {
    put<std::int32_t>(data, -7 + i);
    put<double>(data, 2.5 * i, true);
    data.insert(data.end(), 3, 0xEE);
    put<float>(data, 0.25f + static_cast<float>(i));
    put<std::uint16_t>(data, static_cast<std::uint16_t>(60000 + i));
    for (int c = 0; c < 3; ++c) data.push_back(static_cast<std::uint8_t>(10 * c + i));
    put_text(data, "abcd");
    data.push_back(static_cast<std::uint8_t>(2 + i));
  }
  const vola::io::NpyArray array = vola::io::parse_npy(record_npy(descr, "(2,)", data), "rec.npy");
  EXPECT_EQ(array.item_size, 29);
  const vola::io::Input in = vola::io::npy_input(array, "rec.npy", {});
  ASSERT_EQ(in.cloud.size(), 2u);
  EXPECT_EQ(in.cloud.xyz, (std::vector<double>{-7, 0, 0.25, -6, 2.5, 1.25}));
  ASSERT_EQ(in.cloud.attributes.size(), 5u);  // intensity, rgb_0..2, classification
  const auto* intensity = attribute_named(in.cloud, "intensity");
  ASSERT_TRUE(intensity);
  EXPECT_EQ(intensity->type, vola::ValueType::u16);
  EXPECT_EQ(intensity->values, (std::vector<double>{60000, 60001}));
  const auto* blue = attribute_named(in.cloud, "rgb_2");
  ASSERT_TRUE(blue);
  EXPECT_EQ(blue->values, (std::vector<double>{20, 21}));
  const auto* classes = attribute_named(in.cloud, "classification");
  ASSERT_TRUE(classes);
  EXPECT_EQ(classes->reduction, vola::Reduction::majority);
  EXPECT_EQ(classes->values, (std::vector<double>{2, 3}));
  EXPECT_FALSE(attribute_named(in.cloud, "name"));
}

TEST(NpyRecords, AnyShapeIsPointsOnePerRecord) {
  Bytes data;
  for (int i = 0; i < 6; ++i)
    for (int a = 0; a < 3; ++a) put<float>(data, static_cast<float>(10 * i + a));
  const auto array =
      vola::io::parse_npy(record_npy("[('x', '<f4'), ('y', '<f4'), ('z', '<f4')]", "(2, 3)", data), "r.npy");
  const auto in = vola::io::npy_input(array, "r.npy", {});
  ASSERT_EQ(in.cloud.size(), 6u);
  EXPECT_EQ(in.cloud.xyz[15], 50.0);
  EXPECT_EQ(in.cloud.xyz[17], 52.0);
}

// numpy writes a name holding a quote or a backslash escaped ('it\\'s'), and a field may be
// called 'shape': neither may hide the header's own keys.
TEST(NpyRecords, EscapedNamesAndAFieldCalledShape) {
  Bytes data;
  for (int i = 0; i < 3; ++i)
    for (int a = 0; a < 4; ++a) put<double>(data, 10.0 * i + a);
  const auto array = vola::io::parse_npy(
      record_npy("[('x', '<f8'), ('y', '<f8'), ('z', '<f8'), ('it\\'s \"q\" \\\\ shape', '<f8')]", "(3,)", data),
      "e.npy");
  const auto in = vola::io::npy_input(array, "e.npy", {});
  ASSERT_EQ(in.cloud.size(), 3u);
  ASSERT_EQ(in.cloud.attributes.size(), 1u);
  EXPECT_EQ(in.cloud.attributes[0].name, "it's \"q\" \\ shape");
  EXPECT_EQ(in.cloud.attributes[0].values, (std::vector<double>{3, 13, 23}));
  const auto shaped = vola::io::parse_npy(
      record_npy("[('shape', '<f8'), ('x', '<f8'), ('y', '<f8'), ('z', '<f8')]", "(3,)", data), "s.npy");
  EXPECT_EQ(shaped.shape, (std::vector<std::uint64_t>{3}));
}

TEST(NpyRecords, WhatCannotBeReadIsRefused) {
  struct Case {
    std::string descr, cause;
    std::size_t record;
  } cases[] = {
      {"[('x', '<f8'), ('y', '<f8')]", "needs numeric fields x, y and z", 16},
      {"[('x', '<f8'), ('y', '<f8'), ('z', '<f2')]", "dtype '<f2'", 18},
      {"[('x', '<f8'), ('y', '<f8'), ('z', '<c16')]", "dtype '<c16'", 32},
      {"[('x', '<f8'), ('y', '<f8'), ('p', [('z', '<f8')])]", "itself a structure", 24},
      {"[(('t', 'x'), '<f8'), ('y', '<f8'), ('z', '<f8')]", "title", 24},
      {"[('x', '<f8'), ('y', '<f8'), ('z', '<f8')", "expected", 24},
      {"[]", "no bytes", 0},
  };
  for (const auto& c : cases) {
    const Bytes file = record_npy(c.descr, "(1,)", Bytes(c.record, 0));
    try {
      const auto array = vola::io::parse_npy(file, "bad.npy");
      (void)vola::io::npy_input(array, "bad.npy", {});
      ADD_FAILURE() << c.descr << " was read";
    } catch (const vola::FormatError& e) {
      EXPECT_NE(std::string(e.what()).find(c.cause), std::string::npos) << e.what();
      EXPECT_NE(std::string(e.what()).find("bad.npy"), std::string::npos) << e.what();
    }
  }
  // More records than the data holds.
  EXPECT_THROW(
      vola::io::parse_npy(record_npy("[('x', '<f8'), ('y', '<f8'), ('z', '<f8')]", "(3,)", Bytes(48, 0)), "t.npy"),
      vola::FormatError);
}

}  // namespace
