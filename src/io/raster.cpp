// GeoTIFF rasters of a tree (vola/io/export.hpp): the cells computed here, the file
// written by the gdal plugin (src/io/plugins/raster_gdal.cpp).
#include <algorithm>
#include <cctype>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <limits>
#include <string>
#include <unordered_map>
#include <utility>
#include <vector>

#include "reader_plugin.hpp"
#include "vola/error.hpp"
#include "vola/geo/crs.hpp"
#include "vola/io/export.hpp"
#include "vola/output_file.hpp"

namespace vola::io {

namespace {

constexpr double kGroundClass = 2.0;  // ASPRS ground

// The shortest text that reads back as the same double ("1e-09", not 1.0000000000000001e-09).
std::string number(double value) {
  char text[64];
  const auto end = std::to_chars(text, text + sizeof text, value).ptr;
  return std::string(text, end);
}

}  // namespace

std::optional<RasterProduct> raster_product(std::string_view name) {
  const auto same = [&](std::string_view known) {  // any case: "DSM" as GIS tools write it
    return name.size() == known.size() && std::equal(name.begin(), name.end(), known.begin(), [](char a, char b) {
             return std::tolower(static_cast<unsigned char>(a)) == b;
           });
  };
  for (const RasterProduct product : {RasterProduct::dsm, RasterProduct::dtm, RasterProduct::intensity,
                                      RasterProduct::density, RasterProduct::count})
    if (same(raster_product_name(product))) return product;
  return std::nullopt;
}

Raster make_raster(const Tree& tree, const RasterOptions& options) {
  if (tree.empty()) throw InvalidArgument("the tree has no voxel: there is no raster to write");
  const Frame frame = tree.frame();
  const double voxel = frame.voxel_size;
  const double cell = options.resolution == 0.0 ? voxel : options.resolution;
  if (!(cell > 0.0) || !std::isfinite(cell))
    throw InvalidArgument("raster resolution " + number(cell) + ": give a positive cell size in the file's units");
  if (cell < voxel * (1.0 - 1e-9))
    throw InvalidArgument("raster resolution " + number(cell) + " is finer than the voxels (" + number(voxel) +
                          "): give the voxel size or more");
  // The cell holding voxel column i's centre, origin + (i + 0.5) * voxel, counted in
  // cells: a centre on a border is in the cell above it, as cells are [k R, (k + 1) R)
  // (R = 2.5 voxels puts column 2's centre on the border of cells 0 and 1: cell 1). The
  // quotient of a border rounds to either side when R / voxel is not a binary fraction
  // (7 / 6: 17.5 / 1.1666... = 14.999999999999998), so a quotient within a billionth of
  // a whole number is that number; a centre off a border is at least half a voxel from it.
  const double ratio = cell / voxel;
  auto cell_of = [&](std::uint32_t i) -> std::uint64_t {
    if (ratio == 1.0) return i;
    const double q = (static_cast<double>(i) + 0.5) / ratio;
    const double nearest = std::round(q);
    return static_cast<std::uint64_t>(std::fabs(q - nearest) <= 1e-9 * std::max(1.0, q) ? nearest : std::floor(q));
  };

  std::uint64_t u_min = std::numeric_limits<std::uint64_t>::max(), v_min = u_min, u_max = 0, v_max = 0;
  tree.for_each_voxel([&](const Voxel& voxel_at) {
    const std::uint64_t u = cell_of(voxel_at.x), v = cell_of(voxel_at.y);
    u_min = std::min(u_min, u);
    u_max = std::max(u_max, u);
    v_min = std::min(v_min, v);
    v_max = std::max(v_max, v);
  });
  Raster raster;
  raster.product = options.product;
  raster.width = u_max - u_min + 1;
  raster.height = v_max - v_min + 1;
  if (raster.width * raster.height > kMaxRasterCells)
    throw InvalidArgument("a raster of " + std::to_string(raster.width) + " x " + std::to_string(raster.height) +
                          " cells of " + number(cell) + " is more than " + std::to_string(kMaxRasterCells) +
                          " cells: give a coarser resolution");
  raster.geotransform = {frame.origin[0] + static_cast<double>(u_min) * cell, cell, 0.0,
                         frame.origin[1] + static_cast<double>(v_max + 1) * cell, 0.0, -cell};
  const std::uint64_t width = raster.width;
  auto index = [&](const Voxel& v) { return (v_max - cell_of(v.y)) * width + (cell_of(v.x) - u_min); };

  const std::size_t cells = static_cast<std::size_t>(raster.width * raster.height);
  const auto& attributes = tree.attributes();
  const AttributeColumn* height = attributes.find("height");
  const double z0 = frame.origin[2];
  // The values in the Float32 the GeoTIFF stores (min and max commute with rounding to
  // float), NaN where no voxel is; counts only for the products that need them: 4 or 8
  // bytes a cell, where doubles and counts for every product took 16 (4.15 GB for a
  // raster of 2^28 cells).
  std::vector<float> value(cells, std::numeric_limits<float>::quiet_NaN());
  std::vector<std::uint32_t> count;
  if (options.product != RasterProduct::dsm && options.product != RasterProduct::dtm) count.assign(cells, 0);

  switch (options.product) {
    case RasterProduct::dsm: {
      raster.rule = height ? "max of the height column (mean point z of a voxel) over the cell's voxels"
                           : "top face of the cell's highest voxel (origin z + (k + 1) * voxel size)";
      std::uint64_t rank = 0;
      tree.for_each_voxel([&](const Voxel& v) {
        const auto z = static_cast<float>(height ? height->get(rank) : z0 + (static_cast<double>(v.z) + 1.0) * voxel);
        float& top = value[index(v)];
        if (!(top >= z)) top = z;  // NaN (no value yet) too
        ++rank;
      });
      break;
    }
    case RasterProduct::dtm: {
      const AttributeColumn* classes = attributes.find("classification");
      bool ground = false;
      if (classes)
        for (std::size_t r = 0; r < classes->size() && !ground; ++r) ground = classes->get(r) == kGroundClass;
      raster.rule = std::string(height ? "min of the height column (mean point z of a voxel)"
                                       : "bottom face of the lowest voxel (origin z + k * voxel size)") +
                    (ground ? " over the cell's ground voxels (classification 2)"
                            : classes ? " over the cell's voxels (no voxel has classification 2)"
                                      : " over the cell's voxels (no classification column)");
      std::uint64_t rank = 0;
      tree.for_each_voxel([&](const Voxel& v) {
        if (!ground || classes->get(rank) == kGroundClass) {
          const auto z = static_cast<float>(height ? height->get(rank) : z0 + static_cast<double>(v.z) * voxel);
          float& bottom = value[index(v)];
          if (!(bottom <= z)) bottom = z;
        }
        ++rank;
      });
      break;
    }
    case RasterProduct::intensity: {
      const AttributeColumn* intensity = attributes.find("intensity");
      if (!intensity) throw InvalidArgument("the file has no intensity column: there is no intensity raster to write");
      raster.rule = "mean intensity of the top voxel of each voxel column in the cell";
      // Per voxel column (x | y << 32): the top voxel's z and rank.
      std::unordered_map<std::uint64_t, std::pair<std::uint32_t, std::uint64_t>> tops;
      std::uint64_t rank = 0;
      tree.for_each_voxel([&](const Voxel& v) {
        const std::uint64_t column = std::uint64_t{v.x} | (std::uint64_t{v.y} << 32);
        auto [it, added] = tops.try_emplace(column, v.z, rank);
        if (!added && it->second.first < v.z) it->second = {v.z, rank};
        ++rank;
      });
      for (const auto& [column, top] : tops) {
        const Voxel v{static_cast<std::uint32_t>(column & 0xffffffffu), static_cast<std::uint32_t>(column >> 32), 0};
        const std::uint64_t i = index(v);
        value[i] = (count[i] ? value[i] : 0.0f) + static_cast<float>(intensity->get(top.second));
        ++count[i];
      }
      for (std::size_t i = 0; i < cells; ++i)
        if (count[i]) value[i] /= static_cast<float>(count[i]);
      break;
    }
    case RasterProduct::density:
    case RasterProduct::count: {
      const bool density = options.product == RasterProduct::density;
      raster.rule = density ? "occupied voxels in the cell per square unit (count / " + number(cell * cell) + ")"
                            : "occupied voxels in the cell";
      tree.for_each_voxel([&](const Voxel& v) { ++count[index(v)]; });
      for (std::size_t i = 0; i < cells; ++i)
        if (count[i]) value[i] = static_cast<float>(density ? count[i] / (cell * cell) : count[i]);
      break;
    }
  }

  for (float& v : value) {
    const bool has = !std::isnan(v);
    if (!has) v = kRasterNodata;
    raster.cells_with_data += has;
  }
  raster.values = std::move(value);
  return raster;
}

RasterReport write_geotiff(const Tree& tree, const std::string& path, const RasterOptions& options) {
  const Raster raster = make_raster(tree, options);
  const Georef& georef = tree.georef();
  const std::string wkt = georef.crs_wkt;
  const std::uint32_t epsg = wkt.empty() && georef.epsg != geo::kUnsetEpsg ? georef.epsg : 0;
  const auto entry = reinterpret_cast<plugin::WriteGeotiffEntry>(
      vola::plugin::plugin_symbol("gdal", plugin::kWriteGeotiffSymbol, path + ": writing a GeoTIFF"));
  std::vector<std::uint8_t> bytes;
  PluginFailure failure;
  entry(raster, wkt, epsg, bytes, failure);
  vola::plugin::throw_failure(failure);
  OutputFile out(path);
  out.write(bytes.data(), bytes.size());
  out.commit();

  RasterReport report;
  report.width = raster.width;
  report.height = raster.height;
  report.resolution = raster.geotransform[1];
  report.cells_with_data = raster.cells_with_data;
  report.rule = raster.rule;
  report.has_crs = !wkt.empty() || epsg != 0;
  return report;
}

}  // namespace vola::io
