#include <algorithm>
#include <iterator>
#include <nlohmann/json.hpp>

#include "vola/convert.hpp"
#include "vola/error.hpp"
#include "vola/filters/pipeline.hpp"
#include "vola/io/file_checks.hpp"
#include "vola/io/input.hpp"
#include "vola/io/translate.hpp"
#include "vola/pipeline.hpp"

namespace vola {

namespace {

// A writers.vola stage's options (JSON text by name) as the conversion's options.
ConvertOptions convert_options(const filters::PipelineWriter& writer, const std::vector<std::string>& stages) {
  ConvertOptions options;
  options.filters = stages;
  for (const auto& [key, text] : writer.options) {
    const auto value = nlohmann::json::parse(text);
    const auto wrong = [&](const char* kind) {
      return InvalidArgument("pipeline writer " + writer.filename + ": \"" + key + "\" must be " + kind + ", not " + text);
    };
    if (key == "voxel_size") {
      if (!value.is_number()) throw wrong("a number");
      options.voxel_size = value.get<double>();
    } else if (key == "depth") {
      if (!value.is_number_integer()) throw wrong("an integer");
      options.depth = value.get<int>();
    } else {
      if (!value.is_boolean()) throw wrong("true or false");
      (key == "compress"       ? options.compress
       : key == "compress_max" ? options.compress_max
       : key == "dense"        ? options.dense
                               : options.attributes) = value.get<bool>();
    }
  }
  return options;
}

// Whether the input is a point format (a voxel grid or map needs no voxel size).
bool reads_points(const std::string& input) {
  static const char* const kPointFormats[] = {"las", "text", "ply", "pcd", "kitti", "ept", "ptx", "e57"};
  try {
    const std::string format = io::find_input_format(input).name;
    return std::find(std::begin(kPointFormats), std::end(kPointFormats), format) != std::end(kPointFormats);
  } catch (const Error&) {
    return false;  // said when the input is read
  }
}

// A .vol writer's options, checked before any writer runs: a mistake in the last writer
// left the earlier ones' files behind, and was said in the CLI's flags.
void check_voxel_writer(const std::string& input, const filters::PipelineWriter& writer,
                        const std::vector<std::string>& stages) {
  const ConvertOptions options = convert_options(writer, stages);
  // Points need a voxel size (a map or grid input maps cell for cell without one).
  if (options.voxel_size <= 0.0 && options.depth <= 0 && reads_points(input))
    throw InvalidArgument("pipeline writer " + writer.filename +
                          ": how fine should the voxels be? Give \"voxel_size\" (the voxel edge in the input's units, "
                          "e.g. the point spacing) or \"depth\" (4^depth voxels along the longest side, 1..10)");
  try {
    options.check();
  } catch (const OptionError& e) {
    std::string cause = e.cause();
    for (char& c : cause)
      if (c == '`') c = '"';
    throw InvalidArgument("pipeline writer " + writer.filename + ": " +
                          (e.option().empty() || e.option() == "filters" ? "" : "\"" + e.option() + "\" ") + cause);
  }
}

}  // namespace

std::vector<PipelineOutputReport> run_pipeline(const std::string& json, const std::string& name) {
  const filters::Pipeline pipeline = filters::parse_pipeline(json, name);
  const std::vector<filters::Stage> stages = filters::parse_stages(pipeline.stages);
  // Before any writer runs: a later writer over the input would read it half written.
  for (const auto& writer : pipeline.writers) {
    io::refuse_output_over_input(pipeline.input, writer.filename,
                                 "a pipeline's writers write new files (" + name + "); give this one another name");
    if (writer.voxels()) check_voxel_writer(pipeline.input, writer, pipeline.stages);
  }
  std::vector<PipelineOutputReport> reports;
  for (const auto& writer : pipeline.writers) {
    PipelineOutputReport out;
    out.input = pipeline.input;
    out.output = writer.filename;
    out.voxels = writer.voxels();
    if (out.voxels) {
      ConvertReport report;
      convert_file(pipeline.input, writer.filename, convert_options(writer, pipeline.stages), {}, &report);
      out.voxel_count = report.build.voxels;
      out.filter_lines = std::move(report.filters);
      out.stages = std::move(report.filter_stages);
      out.warnings = std::move(report.warnings);
    } else {
      out.warnings = io::translate_points(pipeline.input, writer.filename, {}, [&](io::PointTable& table) {
        filters::FilterResult result = filters::run_stages(stages, table.cloud, table.epsg, table.wkt);
        out.stages = std::move(result.stages);
        return std::move(result.kept);
      });
    }
    reports.push_back(std::move(out));
  }
  return reports;
}

}  // namespace vola
