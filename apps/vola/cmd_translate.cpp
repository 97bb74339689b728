// vola translate: point files to point files, point by point, no voxels (PDAL's
// translate): LAS, LAZ, COPC, PLY, PCD, XYZ, NPY, KITTI in; LAS, LAZ, PLY, XYZ, CSV out.
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <memory>
#include <string>

#include "commands.hpp"
#include "filter_flags.hpp"
#include "progress.hpp"
#include "vola/error.hpp"
#include "vola/filters/stages.hpp"
#include "vola/io/input.hpp"
#include "vola/io/las.hpp"
#include "vola/io/translate.hpp"

namespace vola::cli {

namespace {

struct TranslateArgs {
  std::string input, output;
  std::vector<std::string> filters;
  std::string format = "auto";
  bool quiet = false;
};


void run_translate(const TranslateArgs& a) {
  const auto start = std::chrono::steady_clock::now();
  std::unique_ptr<Progress> progress;
  if (!a.quiet) progress = std::make_unique<Progress>("translating points");
  const std::vector<filters::Stage> stages = filters::parse_stages(a.filters);
  std::vector<filters::StageReport> reports;
  io::PointEdit edit;
  if (!stages.empty())
    edit = [&](io::PointTable& table) {
      filters::FilterResult result = filters::run_stages(stages, table.cloud, table.epsg, table.wkt);
      reports = std::move(result.stages);
      return std::move(result.kept);
    };
  const std::vector<std::string> warnings = io::translate_points(
      a.input, a.output,
      [&](std::uint64_t done, std::uint64_t total) {
        if (progress) progress->update(done, total);
      },
      edit, a.format);
  if (progress) progress->finish();
  for (const auto& warning : warnings) std::fprintf(stderr, "vola: warning: %s\n", warning.c_str());  // -q too
  if (!progress) return;
  for (const auto& r : reports) {
    std::printf("filter:  %s: %llu -> %llu points", r.spec.c_str(), static_cast<unsigned long long>(r.points_in),
                static_cast<unsigned long long>(r.points_out));
    if (r.spec.rfind("smrf", 0) == 0) std::printf(", %llu ground", static_cast<unsigned long long>(r.ground));
    std::printf("\n");
  }
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  if (io::lower_extension(a.output) == ".las" || io::lower_extension(a.output) == ".laz") {
    const io::LasReader written(a.output);
    std::printf("points:  %llu, point format %u, %u bytes a record\n",
                static_cast<unsigned long long>(written.header().point_count), written.header().point_format,
                written.header().record_length);
  }
  std::printf("file:    %llu bytes (%s), input %llu bytes\n",
              static_cast<unsigned long long>(std::filesystem::file_size(a.output)), a.output.c_str(),
              static_cast<unsigned long long>(std::filesystem::file_size(a.input)));
  std::printf("time:    %.3f s\n", seconds);
}

}  // namespace

void add_translate(CLI::App& app) {
  auto args = std::make_shared<TranslateArgs>();
  auto* cmd = app.add_subcommand("translate", "Point files to point files, point by point, no voxels (LAS <-> LAZ, to PLY, XYZ)");
  cmd->footer(
      "Every point record is copied as it is, in order: coordinates, returns, classes, GPS time,\n"
      "colour, NIR, extra bytes; the header, the CRS and the other (E)VLRs too. A .laz output is\n"
      "LASzip-compressed (compressor 2 for point formats 0-5, 3 for 6-10) in chunks of 50000 points.\n"
      "A .ply (binary), .xyz or .csv output (PDAL's CSV: \"X\",\"Y\",\"Z\",\"Intensity\",...) holds x y z and\n"
      "every field as a named column, from any\n"
      "point file vola reads (LAS, LAZ, COPC, PLY, PCD, XYZ, NPY, KITTI), but not the CRS (a\n"
      "warning says so). Other inputs to LAS/LAZ become LAS 1.4 point format 6 or 7 records with\n"
      "the fields LAS has (colour, intensity, classification, returns, GPS time, ...).\n"
      "Examples:\n"
      "  vola translate survey.laz survey.las     # decompress\n"
      "  vola translate survey.las survey.laz     # compress\n"
      "  vola translate cloud.copc.laz cloud.las  # a COPC file's points, in its chunk order\n"
      "  vola translate survey.laz survey.ply     # for tools that read PLY, every field kept\n"
      "  vola translate autzen.laz ground.laz --filter smrf             # class 2 ground, 1 the rest\n"
      "  vola translate autzen.laz veg.ply --filter smrf --filter hag --where \"HeightAboveGround > 2\"\n"
      "With filters, a LAS/LAZ output keeps the records of the points left, every field as it was\n"
      "but the classification, and the header's counts and bounds follow; a new dimension\n"
      "(height_above_ground) is written to .ply and .xyz outputs.\n" +
      std::string(kFilterHelp));
  cmd->add_option("input", args->input, "Input point file (LAS, LAZ, COPC, PLY, PCD, XYZ, NPY, KITTI)")->required()
      ->check(CLI::ExistingFile);
  cmd->add_option("output", args->output, "Output .las, .laz, .ply, .xyz or .csv")->required();
  cmd->add_option(
         "--format", args->format,
         "Input format: auto (from the first bytes where they name LAS or E57, else the extension) or one of " +
             known_formats())
      ->capture_default_str();
  add_filter_options(*cmd, args->filters);
  cmd->add_flag("-q,--quiet", args->quiet, "Print nothing on success but warnings (to stderr)");
  cmd->callback([args] { run_translate(*args); });
}

}  // namespace vola::cli
