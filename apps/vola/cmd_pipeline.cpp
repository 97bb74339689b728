// vola pipeline FILE.json: a PDAL-style pipeline (vola/filters/pipeline.hpp): one reader,
// filters, writers, run by vola::run_pipeline (vola/pipeline.hpp).
#include <chrono>
#include <cstdio>
#include <fstream>
#include <sstream>

#include "commands.hpp"
#include "option_flags.hpp"
#include "vola/error.hpp"
#include "vola/pipeline.hpp"

namespace vola::cli {

namespace {

struct PipelineArgs {
  std::string file;
  bool quiet = false;
};

void print_stages(const std::vector<filters::StageReport>& reports) {
  for (const auto& r : reports) {
    std::printf("  %s: %llu -> %llu points", r.spec.c_str(), static_cast<unsigned long long>(r.points_in),
                static_cast<unsigned long long>(r.points_out));
    if (r.spec.rfind("smrf", 0) == 0) std::printf(", %llu ground", static_cast<unsigned long long>(r.ground));
    std::printf("\n");
  }
}

void run_pipeline_command(const PipelineArgs& a) {
  const auto start = std::chrono::steady_clock::now();
  std::ifstream in(a.file);
  if (!in) throw IoError(a.file + ": cannot open");
  std::stringstream text;
  text << in.rdbuf();
  for (const PipelineOutputReport& out : vola::run_pipeline(text.str(), a.file)) {
    for (const auto& warning : out.warnings)  // shown with -q too: they are about the result
      std::fprintf(stderr, "vola: warning: %s\n", with_flags(warning).c_str());
    if (a.quiet) continue;
    if (out.voxels) {
      std::printf("%s -> %s: %llu voxels\n", out.input.c_str(), out.output.c_str(),
                  static_cast<unsigned long long>(out.voxel_count));
      for (const auto& line : out.filter_lines) std::printf("  %s\n", line.c_str());
    } else {
      std::printf("%s -> %s\n", out.input.c_str(), out.output.c_str());
      print_stages(out.stages);
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
      "A file named without a type is the input when first, an output when last, and anywhere else\n"
      "another input to PDAL (merged with the first): vola reads one and refuses it. Give the other\n"
      "outputs a type. No output may be the input.\n"
      "Filters: filters.smrf (cell, slope, window, threshold, scalar; metres), filters.range (limits,\n"
      "e.g. \"Classification[2:2]\", \"Z[:500)\", \"Classification![7:7]\"), filters.expression (expression),\n"
      "filters.hag_nn, filters.outlier (mean_k, multiplier; drops the outliers, PDAL marks them class 7),\n"
      "filters.crop (bounds \"([x0, x1], [y0, y1])\", \"[x0, y0, x1, y1]\" or {\"minx\": ...}; or polygon WKT),\n"
      "filters.sample (radius or cell), filters.voxelcenternearestneighbor (cell, 1 by default).\n"
      "Writers: .las/.laz (writers.las: the input's records, classification updated), .ply, .xyz and\n"
      ".csv (writers.text: every column; .xyz space-separated, .csv PDAL's CSV with its quoted header), .vol\n"
      "(writers.vola: voxel_size, depth, compress, dense, attributes).\n"
      "Example (ground.json):\n"
      "  [\"autzen.laz\", {\"type\": \"filters.smrf\"},\n"
      "   {\"type\": \"filters.range\", \"limits\": \"Classification[2:2]\"},\n"
      "   {\"type\": \"writers.las\", \"filename\": \"ground.laz\"},\n"
      "   {\"type\": \"writers.vola\", \"filename\": \"ground.vol\", \"voxel_size\": 3}]\n"
      "  vola pipeline ground.json");
  cmd->add_option("file", args->file, "The pipeline's JSON file")->required()->check(CLI::ExistingFile);
  cmd->add_flag("-q,--quiet", args->quiet, "Print nothing on success but warnings (to stderr)");
  cmd->callback([args] { run_pipeline_command(*args); });
}

}  // namespace vola::cli
