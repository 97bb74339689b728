// LAS points as vola sees them: the attribute columns a LAS file gives (colour,
// intensity, classification, height, returns, extra bytes), the reference's payload word,
// and a whole file as a PointCloud.
#include <algorithm>

#include "las_format.hpp"

#include "vola/io/column_reduction.hpp"
#include "vola/io/las.hpp"

namespace vola::io {

namespace {

// The reference's las2vola payload: int(255 * clip((v - lo) / (hi - lo), 0, 1)).
std::uint64_t payload_byte(double v, double lo, double hi) {
  const double n = hi > lo ? (v - lo) / (hi - lo) : 0.0;
  if (!(n > 0.0)) return 0;  // also NaN, from a header max z that is not a number
  return static_cast<std::uint64_t>(255.0 * std::min(n, 1.0));
}

}  // namespace

std::vector<AttributeSpec> las_attributes(const LasHeader& hd) {
  std::vector<AttributeSpec> specs;
  if (hd.has_rgb()) {
    specs.push_back({"red", ValueType::u16, Reduction::mean});
    specs.push_back({"green", ValueType::u16, Reduction::mean});
    specs.push_back({"blue", ValueType::u16, Reduction::mean});
  }
  specs.push_back({"intensity", ValueType::u16, Reduction::mean});
  specs.push_back({"classification", ValueType::u8, Reduction::majority});
  specs.push_back({"height", ValueType::f32, Reduction::mean});
  specs.push_back({"number_of_returns", ValueType::u8, Reduction::max});
  for (const auto& f : hd.extra_fields)
    if (f.name != "height") specs.push_back({f.name, ValueType::f64, default_reduction(f.name)});
  return specs;
}

namespace {

// An extra-bytes field named "height" (vola's LAS export writes the voxels' mean z there)
// is the height column; without one, height is the point's z.
const std::vector<double>* height_field(const LasHeader& hd, const LasChunk& chunk) {
  for (std::size_t f = 0; f < hd.extra_fields.size(); ++f)
    if (hd.extra_fields[f].name == "height") return &chunk.extra[f];
  return nullptr;
}

// The same field's description, or nullptr.
const LasExtraField* height_extra_field(const LasHeader& hd) {
  for (const auto& f : hd.extra_fields)
    if (f.name == "height") return &f;
  return nullptr;
}

}  // namespace

void las_attribute_values(const LasHeader& hd, const LasChunk& chunk, std::vector<std::vector<double>>& values) {
  const std::size_t n = chunk.size();
  values.resize(las_attributes(hd).size());
  std::size_t c = 0;
  auto column = [&](auto&& value_of) {
    auto& v = values[c++];
    v.resize(n);
    for (std::size_t i = 0; i < n; ++i) v[i] = value_of(i);
  };
  if (hd.has_rgb()) {
    column([&](std::size_t i) { return static_cast<double>(chunk.red[i]); });
    column([&](std::size_t i) { return static_cast<double>(chunk.green[i]); });
    column([&](std::size_t i) { return static_cast<double>(chunk.blue[i]); });
  }
  column([&](std::size_t i) { return static_cast<double>(chunk.intensity[i]); });
  column([&](std::size_t i) { return static_cast<double>(chunk.classification[i]); });
  if (const std::vector<double>* height = height_field(hd, chunk)) column([&](std::size_t i) { return (*height)[i]; });
  else column([&](std::size_t i) { return chunk.xyz[3 * i + 2]; });
  column([&](std::size_t i) { return static_cast<double>(chunk.number_of_returns[i]); });
  for (std::size_t f = 0; f < chunk.extra.size(); ++f)
    if (hd.extra_fields[f].name != "height") column([&](std::size_t i) { return chunk.extra[f][i]; });
}

void las_record_attribute_values(const LasHeader& hd, const std::uint8_t* records,
                                 std::span<const std::uint32_t> index, std::vector<std::vector<double>>& values) {
  // The fields where LasReader::read finds them, decoded the same way.
  const std::size_t n = index.size(), length = hd.record_length;
  const bool extended = hd.extended_format();
  values.resize(las_attributes(hd).size());
  std::size_t c = 0;
  auto column = [&](auto&& value_of) {
    auto& v = values[c++];
    v.resize(n);
    double* out = v.data();
    for (std::size_t j = 0; j < n; ++j) out[j] = value_of(records + std::size_t{index[j]} * length);
  };
  if (hd.has_rgb()) {
    const std::size_t rgb_at = extended ? 30 : (hd.point_format == 2 ? 20 : 28);
    for (std::size_t k = 0; k < 3; ++k)
      column([&](const std::uint8_t* r) { return static_cast<double>(load_le<std::uint16_t>(r + rgb_at + 2 * k)); });
  }
  column([](const std::uint8_t* r) { return static_cast<double>(load_le<std::uint16_t>(r + 12)); });
  if (extended) column([](const std::uint8_t* r) { return static_cast<double>(r[16]); });
  else column([](const std::uint8_t* r) { return static_cast<double>(r[15] & 31u); });
  const LasExtraField* height = height_extra_field(hd);
  if (height) {
    column([&](const std::uint8_t* r) { return las::extra_field_value(r, *height); });
  } else {
    const double scale = hd.scale[2], offset = hd.offset[2];
    column([&](const std::uint8_t* r) { return static_cast<double>(load_le<std::int32_t>(r + 8)) * scale + offset; });
  }
  if (extended) column([](const std::uint8_t* r) { return static_cast<double>(r[14] >> 4); });
  else column([](const std::uint8_t* r) { return static_cast<double>((r[14] >> 3) & 7u); });
  for (const auto& f : hd.extra_fields)
    if (f.name != "height") column([&](const std::uint8_t* r) { return las::extra_field_value(r, f); });
}

bool las_record_fields(const LasHeader& hd, std::vector<RecordField>& fields) {
  using Kind = RecordField::Kind;
  const bool extended = hd.extended_format();
  fields.clear();
  if (hd.has_rgb()) {
    const std::uint32_t rgb_at = extended ? 30 : (hd.point_format == 2 ? 20 : 28);
    for (std::uint32_t k = 0; k < 3; ++k) fields.push_back({.kind = Kind::u16, .offset = rgb_at + 2 * k});
  }
  fields.push_back({.kind = Kind::u16, .offset = 12});
  if (extended) fields.push_back({.kind = Kind::u8, .offset = 16});
  else fields.push_back({.kind = Kind::u8, .offset = 15, .mask = 31});
  constexpr Kind kinds[] = {Kind::u8, Kind::i8, Kind::u16, Kind::i16, Kind::u32,
                            Kind::i32, Kind::u64, Kind::i64, Kind::f32, Kind::f64};
  const auto extra = [&](const LasExtraField& f) {
    if (f.data_type < 1 || f.data_type > 10) return false;
    fields.push_back({.kind = kinds[f.data_type - 1],
                      .offset = f.offset,
                      .scale = f.scale,
                      .add = f.add,
                      .has_no_data = f.no_data.has_value(),
                      .no_data = f.no_data.value_or(0.0)});
    return true;
  };
  const LasExtraField* height = height_extra_field(hd);
  if (height) {
    if (!extra(*height)) return false;
  } else {
    fields.push_back({.kind = Kind::i32, .offset = 8, .scale = hd.scale[2], .add = hd.offset[2]});
  }
  if (extended) fields.push_back({.kind = Kind::u8, .offset = 14, .shift = 4});
  else fields.push_back({.kind = Kind::u8, .offset = 14, .shift = 3, .mask = 7});
  for (const auto& f : hd.extra_fields)
    if (f.name != "height" && !extra(f)) return false;
  return fields.size() == las_attributes(hd).size();
}

void las_payloads(const LasHeader& hd, const LasChunk& chunk, std::vector<std::uint64_t>& payloads) {
  const std::size_t n = chunk.size();
  payloads.resize(n);
  for (std::size_t i = 0; i < n; ++i) {
    std::uint64_t r = 200, g = 200, b = 200;  // the reference's grey for points without colour
    if (hd.has_rgb() && (chunk.red[i] | chunk.green[i] | chunk.blue[i])) {
      r = chunk.red[i] / 256u;
      g = chunk.green[i] / 256u;
      b = chunk.blue[i] / 256u;
    }
    payloads[i] = r | g << 8 | b << 16 | payload_byte(chunk.xyz[3 * i + 2], 0.0, hd.max[2]) << 24 |
                  payload_byte(chunk.number_of_returns[i], 1.0, 7.0) << 32 |
                  payload_byte(chunk.intensity[i], 0.0, 1000.0) << 40 |
                  payload_byte(chunk.classification[i], 0.0, 31.0) << 48;
  }
}


PointCloud las_points(LasReader& reader, bool attributes, bool payload,
                      const std::function<void(std::uint64_t, std::uint64_t)>& progress) {
  const LasHeader& hd = reader.header();
  PointCloud cloud;
  const std::uint64_t total = reader.points_total();
  // An uncompressed file's count was checked against its size; a LAZ chunk table's
  // counts only bound what decoding may find, so its columns grow as points arrive.
  cloud.xyz.reserve(3 * (hd.compressed() ? std::min<std::uint64_t>(total, std::uint64_t{1} << 22) : total));
  if (attributes)
    for (const auto& spec : las_attributes(hd)) cloud.attributes.push_back({spec.name, spec.type, spec.reduction, {}});
  LasChunk chunk;
  std::vector<std::vector<double>> values;
  std::vector<std::uint64_t> payloads;
  while (reader.read(chunk, 1 << 20) > 0) {
    cloud.xyz.insert(cloud.xyz.end(), chunk.xyz.begin(), chunk.xyz.end());
    if (attributes) {
      las_attribute_values(hd, chunk, values);
      for (std::size_t a = 0; a < values.size(); ++a)
        cloud.attributes[a].values.insert(cloud.attributes[a].values.end(), values[a].begin(), values[a].end());
    }
    if (payload) {
      las_payloads(hd, chunk, payloads);
      cloud.payload.insert(cloud.payload.end(), payloads.begin(), payloads.end());
    }
    if (progress) progress(reader.points_read(), total);
  }
  return cloud;
}


}  // namespace vola::io
