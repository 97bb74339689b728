// vola lod: a coarser copy (level of detail): each voxel is one cell of a coarser level.
#include <cstdio>
#include <string>

#include "commands.hpp"
#include "open_voxels.hpp"
#include "output_checks.hpp"
#include "vola/error.hpp"
#include "vola/file.hpp"

namespace vola::cli {

namespace {

struct LodArgs {
  std::string input, output;
  int depth = 0;
  bool quiet = false;
};

void run_lod(const LodArgs& a) {
  refuse_outputs_over_inputs({a.input}, {a.output}, "vola lod");
  const Tree tree = open_voxels_to_write(a.input, "vola lod");
  if (a.depth > tree.depth())
    throw InvalidArgument("--depth " + std::to_string(a.depth) + " is deeper than the file's depth " +
                          std::to_string(tree.depth()));
  const Tree coarse = tree.level_of_detail(a.depth);
  write(coarse, a.output);
  if (!a.quiet)
    std::printf("depth %d -> %d: %llu voxels -> %llu voxels, voxel size %.9g\n", tree.depth(), a.depth,
                static_cast<unsigned long long>(tree.voxel_count()), static_cast<unsigned long long>(coarse.voxel_count()),
                coarse.frame().voxel_size);
}

}  // namespace

void add_lod(CLI::App& app) {
  auto args = std::make_shared<LodArgs>();
  auto* cmd = app.add_subcommand("lod", "Write a coarser copy: the first DEPTH levels, each voxel a 4^k-voxel cell");
  cmd->footer(
      "The copy keeps the occupancy and the georeference; attribute columns are not kept (vola downsample\n"
      "keeps cells by how many voxels they hold).\n"
      "Example: vola lod city.vol --depth 4 city_lod4.vol");
  cmd->add_option("input", args->input, "Input .vol")->required()->check(CLI::ExistingFile);
  cmd->add_option("--depth", args->depth, "Depth of the copy, 1..depth of the input")->required()->check(CLI::Range(1, 10));
  cmd->add_option("output", args->output, "Output .vol")->required();
  cmd->add_flag("-q,--quiet", args->quiet, "Print nothing on success but warnings (to stderr)");
  cmd->callback([args] { run_lod(*args); });
}

}  // namespace vola::cli
