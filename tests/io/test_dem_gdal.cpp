// DEM rasters through GDAL: rasters written here with known cells, and the shared
// GeoTIFFs against their raw cells read the plain way.
#include <cmath>
#include <fstream>
#include <limits>

#include <gdal_priv.h>
#include <ogr_spatialref.h>
#include <gtest/gtest.h>

#include "../mesh/mesh_test_support.hpp"
#include "crafted_tiff.hpp"
#include "memory_cap.hpp"
#include "vola/error.hpp"
#include "vola/io/dem.hpp"
#include "vola/io/input.hpp"

namespace {

namespace fs = std::filesystem;

struct Raster {
  int width, height;
  GDALDataType type;
  std::vector<double> values;  // row by row, north first
  double geotransform[6];
  std::optional<double> nodata;
  double scale = 1.0, offset = 0.0;
  int epsg = 0;  // 0: no CRS
};

void write_geotiff(const fs::path& path, const Raster& r) {
  GDALAllRegister();
  GDALDriver* driver = GetGDALDriverManager()->GetDriverByName("GTiff");
  ASSERT_NE(driver, nullptr);
  GDALDataset* d = driver->Create(path.c_str(), r.width, r.height, 1, r.type, nullptr);
  ASSERT_NE(d, nullptr);
  double gt[6];
  std::copy(r.geotransform, r.geotransform + 6, gt);
  d->SetGeoTransform(gt);
  if (r.epsg) {
    OGRSpatialReference srs;
    srs.importFromEPSG(r.epsg);
    d->SetSpatialRef(&srs);
  }
  GDALRasterBand* band = d->GetRasterBand(1);
  if (r.nodata) band->SetNoDataValue(*r.nodata);
  band->SetScale(r.scale);
  band->SetOffset(r.offset);
  std::vector<double> values = r.values;
  ASSERT_EQ(band->RasterIO(GF_Write, 0, 0, r.width, r.height, values.data(), r.width, r.height, GDT_Float64, 0, 0),
            CE_None);
  GDALClose(d);
}

TEST(DemGdal, CellsCentresHeightsAndCrsOfAWrittenRaster) {
  const double nan = std::numeric_limits<double>::quiet_NaN();
  Raster r{4, 3, GDT_Float32,
           {1, 2, 3, 4,
            5, -9999, 7, 8,
            9, 10, nan, 12},
           {500000, 10, 2, 4000000, 1, -10}, -9999.0, 0.5, 100.0, 32633};
  vola_test::TempDir dir;
  write_geotiff(dir / "dem.tif", r);
  const vola::io::DemRaster dem = vola::io::read_dem((dir / "dem.tif").string());
  EXPECT_EQ(dem.width, 4u);
  EXPECT_EQ(dem.height, 3u);
  EXPECT_EQ(dem.invalid_cells, 2u);
  EXPECT_EQ(dem.epsg, std::optional<std::uint32_t>(32633));
  EXPECT_NE(dem.wkt.find("UTM zone 33N"), std::string::npos) << dem.wkt;
  std::vector<double> expected;
  for (int j = 0; j < 3; ++j)
    for (int i = 0; i < 4; ++i) {
      const double v = r.values[j * 4 + i];
      if (v == -9999 || std::isnan(v)) continue;
      const double px = i + 0.5, py = j + 0.5;
      expected.insert(expected.end(), {500000 + px * 10 + py * 2, 4000000 + px * 1 - py * 10, v * 0.5 + 100});
    }
  EXPECT_EQ(dem.cells.xyz, expected);
  EXPECT_EQ(dem.minimum, 100.5);
}

TEST(DemGdal, InputIsATerrainWithItsBase) {
  Raster r{2, 2, GDT_Int16, {-32768, 20, 30, 40}, {0, 1, 0, 2, 0, -1}, -32768.0, 1.0, 0.0, 0};
  vola_test::TempDir dir;
  write_geotiff(dir / "small.tiff", r);
  const std::string path = (dir / "small.tiff").string();
  vola::io::Input in = vola::io::read_input(path, "auto", {});
  EXPECT_EQ(in.format, "dem");
  EXPECT_TRUE(in.terrain);
  EXPECT_EQ(in.terrain_base, 20.0);
  EXPECT_FALSE(in.terrain_surface_only);
  EXPECT_FALSE(in.epsg.has_value());
  EXPECT_TRUE(in.wkt.empty());
  EXPECT_EQ(in.cloud.xyz, (std::vector<double>{1.5, 1.5, 20, 0.5, 0.5, 30, 1.5, 0.5, 40}));
  vola::io::InputOptions options;
  options.dem_base = -5.0;
  options.dem_surface_only = true;
  in = vola::io::read_input(path, "dem", options);
  EXPECT_EQ(in.terrain_base, -5.0);
  EXPECT_TRUE(in.terrain_surface_only);
}

// A raster wider than one read window (2^20 cells) is read in column windows.
TEST(DemGdal, WideRasterIsReadInWindows) {
  const int width = (1 << 20) + 7;
  Raster r{width, 2, GDT_Int16, std::vector<double>(2 * static_cast<std::size_t>(width)), {0, 1, 0, 2, 0, -1}, -1.0, 1.0,
           0.0, 0};
  for (int i = 0; i < 2 * width; ++i) r.values[static_cast<std::size_t>(i)] = i % 1000 == 0 ? -1.0 : i % 7;
  vola_test::TempDir dir;
  write_geotiff(dir / "wide.tif", r);
  const vola::io::DemRaster dem = vola::io::read_dem((dir / "wide.tif").string());
  std::vector<double> expected;
  for (int j = 0; j < 2; ++j)
    for (int i = 0; i < width; ++i) {
      const double v = r.values[static_cast<std::size_t>(j) * width + i];
      if (v == -1.0) continue;
      expected.insert(expected.end(), {i + 0.5, 2 - (j + 0.5), v});
    }
  EXPECT_EQ(dem.invalid_cells, 2u * width - expected.size() / 3);
  EXPECT_EQ(dem.cells.xyz, expected);
}

// The raw band as int16 without GDAL's mask: what the reader must agree with.
std::uint64_t raw_valid_cells(const fs::path& path, std::int16_t nodata, int& width, int& height) {
  GDALAllRegister();
  GDALDataset* d = static_cast<GDALDataset*>(GDALOpen(path.c_str(), GA_ReadOnly));
  if (!d) return 0;
  width = d->GetRasterXSize();
  height = d->GetRasterYSize();
  std::vector<std::int16_t> cells(static_cast<std::size_t>(width) * height);
  std::uint64_t valid = 0;
  if (d->GetRasterBand(1)->RasterIO(GF_Read, 0, 0, width, height, cells.data(), width, height, GDT_Int16, 0, 0) == CE_None)
    for (std::int16_t c : cells) valid += c != nodata;
  GDALClose(d);
  return valid;
}

TEST(DemGdal, SharedGeoTiffs) {
  VOLA_REQUIRE_DATA(data);
  struct Case {
    const char* file;
    std::uint32_t epsg;
    double first_x, first_y;  // centre of the north-west cell, from EXPECTED.txt's tiepoint and scale
    bool declares_nodata;
  };
  const Case cases[] = {
      {"dem/pdal_gdal_int16_epsg26711.tif", 26711, 440720.0 + 30.0, 3751320.0 - 30.0, false},
      {"dem/pysheds_dem_int16_tiled_epsg4326.tif", 4326, -97.4849999999961 + 0.0008333333333333 / 2,
       32.82166666666536 - 0.0008333333333333 / 2, true},
  };
  for (const Case& c : cases) {
    SCOPED_TRACE(c.file);
    const vola::io::DemRaster dem = vola::io::read_dem((data / c.file).string());
    int width = 0, height = 0;
    const std::uint64_t valid = raw_valid_cells(data / c.file, c.declares_nodata ? -32768 : 0x7fff, width, height);
    EXPECT_EQ(dem.width, static_cast<std::uint64_t>(width));
    EXPECT_EQ(dem.height, static_cast<std::uint64_t>(height));
    EXPECT_EQ(dem.cells.size(), valid);
    EXPECT_EQ(dem.cells.size() + dem.invalid_cells, dem.width * dem.height);
    EXPECT_EQ(dem.epsg, std::optional<std::uint32_t>(c.epsg));
    EXPECT_FALSE(dem.wkt.empty());
    ASSERT_GT(dem.cells.size(), 0u);
    EXPECT_NEAR(dem.cells.xyz[0], c.first_x, 1e-6);
    EXPECT_NEAR(dem.cells.xyz[1], c.first_y, 1e-6);
    EXPECT_EQ(dem.minimum, dem.cells.bounds().min[2]);
  }
}

TEST(DemGdal, FilesGdalCannotReadThrowFormatErrors) {
  vola_test::TempDir dir;
  std::ofstream(dir / "text.tif") << "not a raster at all\n";
  for (const fs::path& p : {dir / "text.tif", dir / "missing.tif"}) {
    const auto error = vola_test::format_error_of([&] { vola::io::read_dem(p.string()); });
    ASSERT_TRUE(error.has_value()) << p;
    EXPECT_EQ(error->file(), p.string());
    EXPECT_FALSE(error->cause().empty());
  }
  // A truncated GeoTIFF: the header survives, the cells do not.
  Raster r{64, 64, GDT_Int16, std::vector<double>(64 * 64, 7.0), {0, 1, 0, 0, 0, -1}, std::nullopt, 1.0, 0.0, 0};
  write_geotiff(dir / "whole.tif", r);
  auto bytes = vola_test::read_bytes(dir / "whole.tif");
  bytes.resize(bytes.size() / 2);
  vola_test::write_bytes(dir / "half.tif", bytes);
  EXPECT_THROW(vola::io::read_dem((dir / "half.tif").string()), vola::FormatError);

  // Placed by ground control points, no geotransform: it was read in pixel units, its CRS
  // (on the points) dropped, without a word.
  {
    GDALDataset* d = GetGDALDriverManager()->GetDriverByName("GTiff")->Create((dir / "gcp.tif").c_str(), 8, 8, 1,
                                                                                GDT_Float32, nullptr);
    ASSERT_NE(d, nullptr);
    OGRSpatialReference srs;
    srs.importFromEPSG(32633);
    GDAL_GCP gcp;
    GDALInitGCPs(1, &gcp);
    gcp.dfGCPPixel = 0, gcp.dfGCPLine = 0, gcp.dfGCPX = 500000, gcp.dfGCPY = 5000000;
    ASSERT_EQ(d->SetGCPs(1, &gcp, &srs), CE_None);
    GDALDeinitGCPs(1, &gcp);
    GDALClose(d);
  }
  const auto gcp = vola_test::format_error_of([&] { vola::io::read_dem((dir / "gcp.tif").string()); });
  ASSERT_TRUE(gcp.has_value());
  EXPECT_NE(gcp->cause().find("ground control points, not a geotransform"), std::string::npos) << gcp->what();

  // An RGB picture (PHOTOMETRIC=RGB: band 1 is red) was read as a relief of its red channel.
  {
    const char* options[] = {"PHOTOMETRIC=RGB", nullptr};
    GDALDataset* d = GetGDALDriverManager()->GetDriverByName("GTiff")->Create((dir / "rgb.tif").c_str(), 4, 4, 3,
                                                                                GDT_Byte, const_cast<char**>(options));
    ASSERT_NE(d, nullptr);
    ASSERT_EQ(d->GetRasterBand(1)->GetColorInterpretation(), GCI_RedBand);
    GDALClose(d);
  }
  const auto rgb = vola_test::format_error_of([&] { vola::io::read_dem((dir / "rgb.tif").string()); });
  ASSERT_TRUE(rgb.has_value());
  EXPECT_NE(rgb->cause().find("Red band of a 3-band colour image"), std::string::npos) << rgb->what();
}

}  // namespace

namespace {

std::string outcome_of_read_dem(const std::string& path) {
  return vola_test::run_with_memory_cap([&] {
    const auto dem = vola::io::read_dem(path);
    return "read " + std::to_string(dem.cells.size()) + " cells";
  });
}

// A VRT saved as .tif pulled another local file's cells into the output; a /vsicurl/
// path made GDAL go to the network; a directory reached GDAL's directory drivers.
TEST(DemGdal, OnlyLocalFilesOfTheDemDriversAreOpened) {
  vola_test::TempDir dir;
  Raster secret{2, 2, GDT_Float32, {11, 22, 33, 44}, {0, 1, 0, 0, 0, -1}, std::nullopt, 1.0, 0.0, 0};
  write_geotiff(dir / "secret.tif", secret);
  std::ofstream(dir / "innocent.tif")
      << "<VRTDataset rasterXSize=\"2\" rasterYSize=\"2\"><VRTRasterBand dataType=\"Float32\" band=\"1\">"
         "<SimpleSource><SourceFilename relativeToVRT=\"0\">"
      << (dir / "secret.tif").string()
      << "</SourceFilename><SourceBand>1</SourceBand></SimpleSource></VRTRasterBand></VRTDataset>\n";
  const auto vrt = vola_test::format_error_of([&] { vola::io::read_dem((dir / "innocent.tif").string()); });
  ASSERT_TRUE(vrt.has_value());
  EXPECT_NE(vrt->cause().find("no DEM driver reads it"), std::string::npos) << vrt->what();
  for (const std::string& path : {std::string("/vsicurl/http://127.0.0.1:9/dem.tif"),
                                  "/vsizip/" + (dir / "x.zip").string() + "/dem.tif", (dir / "").string()}) {
    const auto error = vola_test::format_error_of([&] { vola::io::read_dem(path); });
    ASSERT_TRUE(error.has_value()) << path;
    EXPECT_TRUE(error->cause().find("/vsi") != std::string::npos || error->cause().find("not a regular file") != std::string::npos)
        << error->what();
  }
  EXPECT_EQ(vola::io::read_dem((dir / "secret.tif").string()).cells.size(), 4u);  // the file itself still reads
}

// A few hundred bytes declaring one deflated 2048 x 2048 strip of 256 float samples per
// pixel: GDAL allocates the 4 GiB block on the first read. Refused from the sizes, within 2 GiB.
TEST(DemGdal, BlocksTheFileCannotJustifyAreRefusedBeforeReading) {
  vola_test::TempDir dir;
  const fs::path path = dir / "block.tif";
  vola_test::write_bytes(path, vola_io_test::crafted_tiff({2048, 2048, 256, 32, 2048, 0, 64, 8}));
  ASSERT_LT(fs::file_size(path), 400u);
  const std::string outcome = outcome_of_read_dem(path.string());
  EXPECT_EQ(outcome.rfind("FormatError: " + path.string() + ": a block of 2048 x 2048 cells x 256 samples takes", 0), 0u)
      << outcome;
}

// 16384 x 16384 sparse tiles (no data at all: GDAL reads them as zeros, each a valid
// cell of 24 bytes of points): 6.4 GB of cells from a 33 KB file.
TEST(DemGdal, CellsTheFileCannotJustifyAreRefusedBeforeReading) {
  vola_test::TempDir dir;
  const fs::path path = dir / "sparse.tif";
  vola_test::write_bytes(path, vola_io_test::crafted_tiff({16384, 16384, 1, 32, 1, 256}));
  const std::string outcome = outcome_of_read_dem(path.string());
  EXPECT_EQ(outcome.rfind("FormatError: " + path.string() + ": declares 16384 x 16384 cells", 0), 0u) << outcome;
}

}  // namespace
