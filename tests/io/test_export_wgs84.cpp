// Voxel centres to WGS84 longitude/latitude (vola coords --wgs84) through one PROJ
// transformation, and the rule that a file without a CRS has none.
#include <gtest/gtest.h>

#include "export_test_support.hpp"
#include "vola/geo/crs.hpp"

namespace {

TEST(Wgs84, GoldenIrishGridFileLandsInDublin) {
  VOLA_REQUIRE_GOLDEN(golden);
  const vola::Tree tree = vola::read((golden / "crs29902_sparse" / "crs29902_sparse.vol").string());
  const auto crs = vola::geo::crs_definition(tree.georef());
  ASSERT_EQ(crs, "EPSG:29902");  // a reference file: the header code, no WKT
  const vola::geo::ToWgs84 to_wgs84(*crs);
  const vola::Quantizer q = tree.quantizer();
  double lon = 0, lat = 0, n = 0;
  tree.for_each_voxel([&](const vola::Voxel& v) {
    const vola::Point c = q.center(v);
    const vola::Point p = to_wgs84.transform(c);
    EXPECT_EQ(p[2], c[2]);  // z unchanged
    lon += p[0];
    lat += p[1];
    n += 1;
  });
  ASSERT_EQ(n, 192);
  EXPECT_NEAR(lat / n, 53.3457, 0.01);
  EXPECT_NEAR(lon / n, -6.2673, 0.01);
}

TEST(Wgs84, SamePlaceFromWktOrCode) {
  // The same point through the code and through its WKT; and one transformation reused.
  const vola::geo::ToWgs84 by_code("EPSG:32633");
  const vola::geo::ToWgs84 by_wkt(vola::geo::crs_wkt(32633));
  for (double e = 400000; e <= 600000; e += 50000) {
    const vola::Point a = by_code.transform({e, 5500000, 7}), b = by_wkt.transform({e, 5500000, 7});
    EXPECT_NEAR(a[0], b[0], 1e-9);
    EXPECT_NEAR(a[1], b[1], 1e-9);
    EXPECT_GT(a[1], 49.0);  // UTM 33N at northing 5500 km: about 49.6 degrees north
    EXPECT_LT(a[1], 50.0);
  }
  // The central meridian of zone 33 is 15 degrees east.
  EXPECT_NEAR(by_code.transform({500000, 5500000, 0})[0], 15.0, 1e-9);
}

TEST(Wgs84, NoCrsMeansNone) {
  vola::Georef georef;  // the reference's default code, no WKT
  EXPECT_EQ(georef.epsg, vola::geo::kUnsetEpsg);
  EXPECT_EQ(vola::geo::crs_definition(georef), std::nullopt);
  georef.epsg = 26910;
  EXPECT_EQ(vola::geo::crs_definition(georef), "EPSG:26910");
  georef.crs_wkt = vola::geo::crs_wkt(29902);
  EXPECT_EQ(vola::geo::crs_definition(georef), georef.crs_wkt);  // the WKT wins
}

TEST(Wgs84, UnknownCrsAndUnplaceablePointsAreErrors) {
  EXPECT_THROW(vola::geo::ToWgs84("EPSG:999999"), vola::Error);
  const vola::geo::ToWgs84 utm("EPSG:32633");
  EXPECT_THROW(utm.transform({1e30, 1e30, 0}), vola::Error);
}

}  // namespace
