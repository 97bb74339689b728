// Footprint layers through OGR: the GeoJSON is RFC 7946 (WGS84 longitude/latitude, the
// corners where PROJ puts them, no crs member), the GeoPackage keeps the layer's own CRS
// (read back with GDAL), both byte-stable, and a layer with no CRS is placed nowhere.
#include <gdal_priv.h>
#include <gtest/gtest.h>
#include <ogr_spatialref.h>
#include <ogrsf_frmts.h>

#include <cmath>
#include <cstdint>
#include <memory>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "../support/test_support.hpp"
#include "vola/geo/crs.hpp"
#include "vola/io/footprints.hpp"

namespace {

using vola::io::FootprintField;
using Type = FootprintField::Type;

// Two 1 km squares in UTM zone 33N (Vienna), one field of every type.
vola::io::FootprintLayer utm_layer(std::string wkt) {
  vola::io::FootprintLayer layer{"tiles", std::move(wkt),
                                 {{"file", Type::text},
                                  {"points", Type::integer},
                                  {"size", Type::real},
                                  {"tile", Type::integer_list},
                                  {"bbox", Type::real_list}},
                                 {}};
  for (int i = 0; i < 2; ++i) {
    const double x = 600000.0 + 1000.0 * i, y = 5340000.0;
    layer.features.push_back({x, y, x + 1000.0, y + 1000.0,
                              {"tile_" + std::to_string(i) + ".vol", std::int64_t{1} << (40 + i), 1000.5,
                               std::vector<std::int64_t>{i, 7, -3}, std::vector<double>{x, y, 0.25, x + 1000, y + 1000, 9}}});
  }
  return layer;
}

nlohmann::json parse(const std::vector<std::uint8_t>& bytes) {
  return nlohmann::json::parse(std::string(bytes.begin(), bytes.end()));
}

struct DatasetCloser {
  void operator()(GDALDataset* d) const { GDALClose(d); }
};

}  // namespace

TEST(Footprints, GeoJsonIsWgs84WithTheCornersWherePROJPutsThem) {
  const auto layer = utm_layer(vola::geo::crs_wkt(32633));
  const auto bytes = vola::io::footprints_geojson(layer, R"({"vola": {"tiles": 2}})");
  EXPECT_EQ(bytes, vola::io::footprints_geojson(layer, R"({"vola": {"tiles": 2}})"));
  const nlohmann::json doc = parse(bytes);
  EXPECT_FALSE(doc.contains("crs"));
  EXPECT_EQ(doc["vola"]["tiles"], 2);
  ASSERT_EQ(doc["features"].size(), 2u);
  const vola::geo::ToWgs84 to_wgs84("EPSG:32633");
  for (std::size_t i = 0; i < 2; ++i) {
    const auto& f = doc["features"][i];
    EXPECT_EQ(f["properties"]["file"], "tile_" + std::to_string(i) + ".vol");
    EXPECT_EQ(f["properties"]["points"].get<std::int64_t>(), std::int64_t{1} << (40 + i));
    EXPECT_EQ(f["properties"]["size"].get<double>(), 1000.5);
    EXPECT_EQ(f["properties"]["tile"], (nlohmann::json{static_cast<int>(i), 7, -3}));
    EXPECT_EQ(f["properties"]["bbox"][2].get<double>(), 0.25);
    const auto& ring = f["geometry"]["coordinates"][0];
    ASSERT_GT(ring.size(), 5u);  // edges densified
    EXPECT_EQ(ring.front(), ring.back());
    const auto& feature = layer.features[i];
    for (const auto& [x, y] : {std::pair{feature.min_x, feature.min_y}, std::pair{feature.max_x, feature.min_y},
                               std::pair{feature.max_x, feature.max_y}, std::pair{feature.min_x, feature.max_y}}) {
      const vola::Point want = to_wgs84.transform({x, y, 0});
      bool found = false;
      for (const auto& p : ring)
        found = found || (std::abs(p[0].get<double>() - want[0]) < 1e-7 && std::abs(p[1].get<double>() - want[1]) < 1e-7);
      EXPECT_TRUE(found) << "corner " << x << " " << y << " -> " << want[0] << " " << want[1];
    }
  }
}

TEST(Footprints, GeoPackageKeepsTheLayersOwnCrs) {
  const auto layer = utm_layer(vola::geo::crs_wkt(32633));
  const auto bytes = vola::io::footprints_geopackage(layer);
  EXPECT_EQ(bytes, vola::io::footprints_geopackage(layer));  // fixed timestamps
  vola_test::TempDir dir;
  vola_test::write_bytes(dir / "tiles.gpkg", bytes);
  GDALAllRegister();
  const std::unique_ptr<GDALDataset, DatasetCloser> dataset(GDALDataset::FromHandle(
      GDALOpenEx((dir / "tiles.gpkg").c_str(), GDAL_OF_VECTOR | GDAL_OF_READONLY, nullptr, nullptr, nullptr)));
  ASSERT_TRUE(dataset);
  OGRLayer* read = dataset->GetLayerByName("tiles");
  ASSERT_NE(read, nullptr);
  EXPECT_EQ(read->GetFeatureCount(), 2);
  OGRSpatialReference utm;
  utm.importFromEPSG(32633);
  ASSERT_NE(read->GetSpatialRef(), nullptr);
  EXPECT_TRUE(read->GetSpatialRef()->IsSame(&utm));
  OGREnvelope extent;
  ASSERT_EQ(read->GetExtent(&extent), OGRERR_NONE);
  EXPECT_EQ(extent.MinX, 600000.0);
  EXPECT_EQ(extent.MaxX, 602000.0);
  EXPECT_EQ(extent.MaxY, 5341000.0);
  std::unique_ptr<OGRFeature> first(read->GetNextFeature());
  ASSERT_TRUE(first);
  EXPECT_EQ(first->GetFieldAsInteger64("points"), std::int64_t{1} << 40);
  EXPECT_STREQ(first->GetFieldAsString("tile"), "[0, 7, -3]");  // lists as JSON text
}

TEST(Footprints, NoCrsIsPlacedNowhere) {
  const auto layer = utm_layer("");
  const nlohmann::json doc = parse(vola::io::footprints_geojson(layer, ""));
  ASSERT_EQ(doc["features"].size(), 2u);
  for (const auto& f : doc["features"]) {
    EXPECT_TRUE(f["geometry"].is_null());
    EXPECT_EQ(f["properties"]["tile"][1], 7);
  }
  vola_test::TempDir dir;
  vola_test::write_bytes(dir / "tiles.gpkg", vola::io::footprints_geopackage(layer));
  GDALAllRegister();
  const std::unique_ptr<GDALDataset, DatasetCloser> dataset(GDALDataset::FromHandle(
      GDALOpenEx((dir / "tiles.gpkg").c_str(), GDAL_OF_VECTOR | GDAL_OF_READONLY, nullptr, nullptr, nullptr)));
  ASSERT_TRUE(dataset);
  const OGRSpatialReference* srs = dataset->GetLayer(0)->GetSpatialRef();
  ASSERT_NE(srs, nullptr);
  EXPECT_TRUE(srs->IsLocal()) << "not GeoPackage's undefined geographic CRS";
}
