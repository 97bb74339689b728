// Seeds for fuzz_e57_read: E57 files written here (tests/io/e57_test_file.hpp; no E57 file
// is in the shared data folder): cartesian scans of every field type with bit widths that
// cross bytes and packets, a spherical scan with invalid points and a pose, two scans of
// different fields; and two Leica PTX files (colours, points of no return, two scans).
// Linked into fuzz_e57_read_replay in place of fuzz_seeds.cpp.
#include <cmath>

#include "../io/e57_test_file.hpp"
#include "fuzz_seeds.hpp"

namespace vola_fuzz {
namespace {

using vola_io_test::E57TestField;
using vola_io_test::E57TestScan;

E57TestField field(const std::string& name, const std::string& type, std::int64_t lo, std::int64_t hi,
                   std::vector<double> values) {
  return {name, type, false, lo, hi, type == "ScaledInteger" ? 1e-3 : 1.0, 0.0, std::move(values)};
}

Seed seed(const std::string& name, const std::vector<E57TestScan>& scans) {
  return {name, vola_io_test::e57_test_file(scans)};
}

}  // namespace

std::vector<Seed> synthetic_seeds() {
  std::vector<double> x, y, z, small, colour;
  for (int i = 0; i < 40; ++i) {
    x.push_back(-0.5 + 0.013 * i);
    y.push_back(0.25 * i);
    z.push_back(0.1 * i);
    small.push_back(i % 8);
    colour.push_back((i * 29) % 256);
  }
  E57TestScan typed;
  typed.records_per_packet = 9;
  typed.fields = {field("cartesianX", "ScaledInteger", -500, 500, x),
                  field("cartesianY", "Float", 0, 0, y),
                  field("cartesianZ", "Float", 0, 0, z),
                  field("returnCount", "Integer", 0, 7, small),
                  field("intensity", "Integer", 0, 4095, colour),
                  field("colorRed", "Integer", 0, 255, colour),
                  field("colorGreen", "Integer", 0, 255, small),
                  field("colorBlue", "Integer", 0, 255, colour)};
  typed.fields[2].single = true;
  E57TestScan spherical;
  spherical.name = "spherical";
  spherical.fields = {field("sphericalRange", "Float", 0, 0, {2, 5, 3, 1}),
                      field("sphericalAzimuth", "Float", 0, 0, {0, 1, 1.5, 0}),
                      field("sphericalElevation", "Float", 0, 0, {0, 0.5, 0.4, 0}),
                      field("sphericalInvalidState", "Integer", 0, 2, {0, 2, 0, 1})};
  spherical.pose = std::array<double, 7>{std::sqrt(0.5), 0, 0, std::sqrt(0.5), 10, 20, 30};
  E57TestScan other;
  other.name = "other";
  other.fields = {field("cartesianX", "Float", 0, 0, {3}), field("cartesianY", "Float", 0, 0, {0}),
                  field("cartesianZ", "Float", 0, 0, {0}), field("intensity", "Float", 0, 0, {0.25})};
  const auto text = [](const std::string& name, const std::string& t) {
    return Seed{name, std::vector<std::uint8_t>(t.begin(), t.end())};
  };
  const std::string ptx_header = "2\n2\n0 0 0\n1 0 0\n0 1 0\n0 0 1\n0 1 0 0\n-1 0 0 0\n0 0 1 0\n10 20 30 1\n";
  return {seed("typed.e57", {typed}), seed("spherical_pose.e57", {spherical}), seed("two_scans.e57", {typed, other}),
          text("colour.ptx", ptx_header + "1 0 0 0.5 255 0 0\n0 0 0 0.5 0 0 0\n0 2 0.5 0.25 0 255 0\n0 0 0 0\n"),
          text("two_scans.ptx", ptx_header + "1 2 3 0.5\n0 0 0 0\n4 5 6 0.25\n7 8 9 1\n\n" +
                                    "1\n1\n0 0 0\n1 0 0\n0 1 0\n0 0 1\n1 0 0 0\n0 1 0 0\n0 0 1 0\n0 0 0 1\n3 2 1 0\n")};
}

std::vector<Seed> golden_seeds(const std::filesystem::path&) { return {}; }

}  // namespace vola_fuzz
