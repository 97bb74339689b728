// vola_convert / vola_convert_file: the C face of vola::convert (include/vola/convert.hpp).
#include <string>

#include "capi_guard.hpp"
#include "vola/vola.h"
#ifdef VOLA_C_HAS_CONVERT
#include "vola/convert.hpp"
#include "vola/file.hpp"
#endif

namespace {

#ifdef VOLA_C_HAS_CONVERT
vola::ConvertOptions convert_options(const vola_convert_options& c) {
  vola::capi::require(c.payload_columns != nullptr || c.payload_column_count == 0, "payload_columns is NULL");
  vola::capi::require(c.text_attributes != nullptr || c.text_attribute_count == 0, "text_attributes is NULL");
  vola::ConvertOptions o;
  if (c.format) o.format = c.format;
  if (c.quantization == VOLA_QUANTIZE_TOOLKIT) o.quantization = vola::Quantization::toolkit;
  else if (c.quantization == VOLA_QUANTIZE_GRID) o.quantization = vola::Quantization::grid;
  else if (c.quantization != VOLA_QUANTIZE_AUTO) throw vola::OptionError("quantization", "is not a vola_quantization");
  o.depth = c.depth;
  o.voxel_size = c.voxel_size;
  if (c.has_origin) o.origin = vola::Point{c.origin[0], c.origin[1], c.origin[2]};
  if (c.has_bbox) o.bbox = vola::Box{{c.bbox[0], c.bbox[1], c.bbox[2]}, {c.bbox[3], c.bbox[4], c.bbox[5]}};
  o.nbits = c.nbits;
  if (c.epsg) o.epsg = c.epsg;
  // NULL leaves a CRS option unset; "" is a mistake, not a way to say so.
  vola::capi::require(!c.assign_crs || *c.assign_crs, "assign_crs is empty (NULL: none)");
  vola::capi::require(!c.target_crs || *c.target_crs, "target_crs is empty (NULL: none)");
  if (c.assign_crs) o.assign_crs = c.assign_crs;
  if (c.target_crs) o.target_crs = c.target_crs;
  o.allow_geographic = c.allow_geographic != 0;
  vola::capi::require(c.level >= -1, "level must be -1 (every level) or a COPC level >= 0");
  if (c.level >= 0) o.level = c.level;
  if (c.grid) o.grid = c.grid;
  o.attributes = c.attributes != 0;
  // 0 0 0 (the default): by a header's names, else 1 2 3; any other: given, 1 2 3 too.
  if (c.columns[0] != 0 || c.columns[1] != 0 || c.columns[2] != 0)
    o.columns = std::array<int, 3>{c.columns[0], c.columns[1], c.columns[2]};
  o.payload_columns.assign(c.payload_columns, c.payload_columns + c.payload_column_count);
  for (std::size_t i = 0; i < c.text_attribute_count; ++i) {
    vola::capi::require(c.text_attributes[i] != nullptr, "text_attributes holds a NULL");
    o.text_attributes.emplace_back(c.text_attributes[i]);
  }
  vola::capi::require(c.filters != nullptr || c.filter_count == 0, "filters is NULL");
  for (std::size_t i = 0; i < c.filter_count; ++i) {
    vola::capi::require(c.filters[i] != nullptr, "filters holds a NULL");
    o.filters.emplace_back(c.filters[i]);
  }
  o.skip_lines = c.skip_lines;
  o.solid = c.solid != 0;
  if (c.has_dem_base) o.dem_base = c.dem_base;
  o.dem_surface_only = c.dem_surface_only != 0;
  o.map_height = c.map_height;
  vola::capi::require((c.write_flags & ~(VOLA_WRITE_DENSE | VOLA_WRITE_COMPRESS | VOLA_WRITE_COMPRESS_MAX)) == 0,
                      "write_flags: unknown flags");
  o.dense = (c.write_flags & VOLA_WRITE_DENSE) != 0;
  o.compress = (c.write_flags & VOLA_WRITE_COMPRESS) != 0;
  o.compress_max = (c.write_flags & VOLA_WRITE_COMPRESS_MAX) != 0;
  return o;
}

vola::ConvertProgress progress_of(const vola_convert_options& c) {
  if (!c.progress) return {};
  return [callback = c.progress, user = c.progress_user](std::uint64_t done, std::uint64_t total) {
    callback(done, total, user);
  };
}

void fill(vola_convert_report* out, const vola::ConvertReport& report) {
  if (!out) return;
  out->inputs = report.build.points_in;
  out->dropped = report.build.points_outside;
  out->voxels = report.build.voxels;
  out->epsg = report.epsg.value_or(0);
}
#endif

}  // namespace

extern "C" {

void vola_convert_options_init(vola_convert_options* options) {
  if (!options) return;
  *options = vola_convert_options{};
  options->quantization = VOLA_QUANTIZE_AUTO;
  options->attributes = 1;
  options->level = -1;
}

vola_status vola_convert(const char* input, const vola_convert_options* options, vola_tree** out,
                         vola_convert_report* report) {
  return vola::capi::guarded([&] {
    vola::capi::set_last_warnings({});
    vola::capi::require(input != nullptr && options != nullptr && out != nullptr,
                        "vola_convert: input, options and out must not be NULL");
#ifdef VOLA_C_HAS_CONVERT
    vola::ConvertReport r;
    auto* handle = new vola_tree{vola::convert(input, convert_options(*options), progress_of(*options), &r)};
    *out = handle;
    fill(report, r);
    vola::capi::set_last_warnings(r.warnings);
#else
    (void)report;
    throw vola::InvalidArgument("vola_convert: this library was built without readers (VOLA_BUILD_MODULES=OFF)");
#endif
  });
}

vola_status vola_convert_file(const char* input, const char* output, const vola_convert_options* options,
                              vola_convert_report* report) {
  return vola::capi::guarded([&] {
    vola::capi::set_last_warnings({});
    vola::capi::require(input != nullptr && output != nullptr && options != nullptr,
                        "vola_convert_file: input, output and options must not be NULL");
#ifdef VOLA_C_HAS_CONVERT
    vola::ConvertReport r;
    vola::convert_file(input, output, convert_options(*options), progress_of(*options), &r);
    fill(report, r);
    vola::capi::set_last_warnings(r.warnings);
#else
    (void)report;
    throw vola::InvalidArgument("vola_convert_file: this library was built without readers (VOLA_BUILD_MODULES=OFF)");
#endif
  });
}

}  // extern "C"
