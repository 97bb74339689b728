// vola pipeline FILE.json: a PDAL-style pipeline (vola/filters/pipeline.hpp): one reader,
// filters, writers; point outputs through vola translate's writers, .vol outputs through
// the conversion pipeline with the same filters.
#include <chrono>
#include <cstdio>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>

#include "commands.hpp"
#include "vola/convert.hpp"
#include "vola/error.hpp"
#include "vola/filters/pipeline.hpp"
#include "vola/filters/stages.hpp"
#include "vola/io/translate.hpp"

namespace vola::cli {

namespace {

struct PipelineArgs {
  std::string file;
  bool quiet = false;
};

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
      (key == "compress" ? options.compress : key == "dense" ? options.dense : options.attributes) = value.get<bool>();
    }
  }
  return options;
}

void print_stages(const std::vector<filters::StageReport>& reports) {
  for (const auto& r : reports) {
    std::printf("  %s: %llu -> %llu points", r.spec.c_str(), static_cast<unsigned long long>(r.points_in),
                static_cast<unsigned long long>(r.points_out));
    if (r.spec.rfind("smrf", 0) == 0) std::printf(", %llu ground", static_cast<unsigned long long>(r.ground));
    std::printf("\n");
  }
}

void run_pipeline(const PipelineArgs& a) {
  const auto start = std::chrono::steady_clock::now();
  std::ifstream in(a.file);
  if (!in) throw IoError(a.file + ": cannot open");
  std::stringstream text;
  text << in.rdbuf();
  const filters::Pipeline pipeline = filters::parse_pipeline(text.str(), a.file);
  const std::vector<filters::Stage> stages = filters::parse_stages(pipeline.stages);
  for (const auto& writer : pipeline.writers) {
    if (writer.voxels()) {
      ConvertReport report;
      convert_file(pipeline.input, writer.filename, convert_options(writer, pipeline.stages), {}, &report);
      if (!a.quiet) {
        std::printf("%s -> %s: %llu voxels\n", pipeline.input.c_str(), writer.filename.c_str(),
                    static_cast<unsigned long long>(report.build.voxels));
        for (const auto& line : report.filters) std::printf("  %s\n", line.c_str());
      }
      continue;
    }
    std::vector<filters::StageReport> reports;
    io::translate_points(pipeline.input, writer.filename, {}, [&](io::PointTable& table) {
      filters::FilterResult result = filters::run_stages(stages, table.cloud, table.epsg, table.wkt);
      reports = std::move(result.stages);
      return std::move(result.kept);
    });
    if (!a.quiet) {
      std::printf("%s -> %s\n", pipeline.input.c_str(), writer.filename.c_str());
      print_stages(reports);
    }
  }
  if (!a.quiet)
    std::printf("time: %.3f s\n", std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count());
}

}  // namespace

void add_pipeline(CLI::App& app) {
  auto args = std::make_shared<PipelineArgs>();
  auto* cmd = app.add_subcommand("pipeline", "Run a PDAL-style JSON pipeline: a reader, point filters, writers");
  cmd->footer(
      "A JSON array (or {\"pipeline\": [...]}): the input file first, filters, then outputs.\n"
      "Filters: filters.smrf (cell, slope, window, threshold, scalar; metres), filters.range (limits,\n"
      "e.g. \"Classification[2:2]\", \"Z[:500)\", \"Classification![7:7]\"), filters.expression (expression),\n"
      "filters.hag_nn, filters.outlier (mean_k, multiplier), filters.crop (bounds \"([x0, x1], [y0, y1])\" or\n"
      "polygon WKT), filters.sample (radius), filters.voxelcenternearestneighbor (cell).\n"
      "Writers: .las/.laz (writers.las: the input's records, classification updated), .ply, .xyz\n"
      "(every column), .vol (writers.vola: voxel_size, depth, compress, dense, attributes).\n"
      "Example (ground.json):\n"
      "  [\"autzen.laz\", {\"type\": \"filters.smrf\"},\n"
      "   {\"type\": \"filters.range\", \"limits\": \"Classification[2:2]\"},\n"
      "   \"ground.laz\", {\"type\": \"writers.vola\", \"filename\": \"ground.vol\", \"voxel_size\": 3}]\n"
      "  vola pipeline ground.json");
  cmd->add_option("file", args->file, "The pipeline's JSON file")->required()->check(CLI::ExistingFile);
  cmd->add_flag("-q,--quiet", args->quiet, "Print nothing on success");
  cmd->callback([args] { run_pipeline(*args); });
}

}  // namespace vola::cli
