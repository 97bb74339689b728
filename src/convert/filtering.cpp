#include "filtering.hpp"

#include <algorithm>
#include <set>

#include "georeference.hpp"

#include "vola/error.hpp"
#include "vola/filters/dimensions.hpp"
#include "vola/filters/stages.hpp"
#include "vola/io/column_reduction.hpp"
#include "vola/io/translate.hpp"

namespace vola::convert_detail {

namespace {

// LAS record fields vola convert does not keep per voxel (io::las_attributes).
bool dropped_las_field(const std::string& name) {
  static const char* const kDropped[] = {"return_number", "user_data", "point_source_id", "gps_time", "scan_angle_rank",
                                         "classification_flags", "scan_direction_flag", "edge_of_flight_line",
                                         "scanner_channel", "nir", "wave_packet_index", "wave_offset",
                                         "wave_packet_size", "wave_return_point", "wave_dx", "wave_dy", "wave_dz"};
  return std::any_of(std::begin(kDropped), std::end(kDropped), [&](const char* dropped) { return name == dropped; });
}

// The table of every LAS field (Reduction::last) as the columns io::las_attributes
// lists, in its order and with its types and reductions, then the filters' own columns.
// `extra_bytes`: the names of the file's extra-bytes columns, kept whatever their name (a
// format 6 file's extra "nir" is no NIR field to drop).
PointCloud las_voxel_columns(PointCloud&& table, const std::set<std::string>& extra_bytes) {
  PointCloud cloud;
  cloud.xyz = std::move(table.xyz);
  std::vector<PointAttribute> columns = std::move(table.attributes);
  const auto take = [&](const std::string& name, ValueType type, Reduction reduction) {
    const auto it = std::find_if(columns.begin(), columns.end(), [&](const PointAttribute& a) { return a.name == name; });
    if (it == columns.end()) return false;
    cloud.attributes.push_back({name, type, reduction, std::move(it->values)});
    columns.erase(it);
    return true;
  };
  if (std::any_of(columns.begin(), columns.end(), [](const PointAttribute& a) { return a.name == "red"; })) {
    take("red", ValueType::u16, Reduction::mean);
    take("green", ValueType::u16, Reduction::mean);
    take("blue", ValueType::u16, Reduction::mean);
  }
  take("intensity", ValueType::u16, Reduction::mean);
  take("classification", ValueType::u8, Reduction::majority);
  if (!take("height", ValueType::f32, Reduction::mean)) {  // an extra-bytes "height" is the height
    std::vector<double> z(cloud.size());
    for (std::size_t i = 0; i < z.size(); ++i) z[i] = cloud.xyz[3 * i + 2];
    cloud.attributes.push_back({"height", ValueType::f32, Reduction::mean, std::move(z)});
  }
  take("number_of_returns", ValueType::u8, Reduction::max);
  for (auto& column : columns) {
    if (dropped_las_field(column.name) && !extra_bytes.contains(column.name)) continue;
    column.type = ValueType::f64;
    column.reduction = io::default_reduction(column.name);
    cloud.attributes.push_back(std::move(column));
  }
  return cloud;
}

// The CRS the filters measure in: the one `assign_crs` (or `epsg`) gives, else the file's.
// SMRF's metres become the CRS's units; a relabelled file's feet must count as feet.
std::pair<std::optional<std::uint32_t>, std::string> filters_crs(const ConvertOptions& options,
                                                                 const std::optional<std::uint32_t>& epsg,
                                                                 const std::string& wkt) {
  if (const std::string given = given_crs(options); !given.empty()) return {std::nullopt, crs_definition_of(given)};
  return {epsg, wkt};
}

}  // namespace

std::string describe(const filters::StageReport& stage) {
  std::string line = stage.spec + ": " + std::to_string(stage.points_in) + " -> " + std::to_string(stage.points_out) + " points";
  if (stage.spec.rfind("smrf", 0) == 0) line += ", " + std::to_string(stage.ground) + " ground";
  return line;
}

io::Input read_filtered(const std::string& path, const io::InputFormat& format, const ConvertOptions& options,
                        const io::InputOptions& input_options, std::vector<filters::StageReport>& report) {
  const std::vector<filters::Stage> stages = filters::parse_stages(options.filters);
  if (format.name == "text") {
    io::InputOptions whole = input_options;
    whole.stream = false;
    io::Input text = format.read(path, whole);
    const auto [epsg, wkt] = filters_crs(options, text.epsg, text.wkt);
    const filters::FilterResult result = filters::run_stages(stages, text.cloud, epsg, wkt);
    report = result.stages;
    return text;
  }
  const ConvertProgress& progress = input_options.progress;
  io::PointTable table;
  try {
    table = io::read_point_table(path, progress, format.name);
  } catch (const InvalidArgument& e) {
    throw OptionError("filters", std::string("apply to point input only: ") + e.what());
  }
  std::set<std::string> extra_bytes;
  for (std::size_t c = table.record_fields; c < table.cloud.attributes.size(); ++c)
    extra_bytes.insert(table.cloud.attributes[c].name);
  const auto [epsg, wkt] = filters_crs(options, table.epsg, table.wkt);
  const filters::FilterResult result = filters::run_stages(stages, table.cloud, epsg, wkt);
  report = result.stages;
  io::Input input;
  input.format = table.format;
  input.epsg = table.epsg;
  input.wkt = std::move(table.wkt);
  input.cloud = table.format == "las" ? las_voxel_columns(std::move(table.cloud), extra_bytes) : std::move(table.cloud);
  if (!options.attributes) input.cloud.attributes.clear();
  return input;
}

}  // namespace vola::convert_detail
