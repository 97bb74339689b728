// vola union | intersect | diff A B OUT: set operations on voxels of one grid.
#include <cstdio>
#include <string>

#include "commands.hpp"
#include "vola/file.hpp"
#include "vola/setops.hpp"

namespace vola::cli {

namespace {

struct SetArgs {
  std::string a, b, output;
  bool ignore_frame = false;
  bool quiet = false;
};

template <class Op>
void add_one(CLI::App& app, const char* name, const char* help, Op op) {
  auto args = std::make_shared<SetArgs>();
  auto* cmd = app.add_subcommand(name, help);
  cmd->footer(
      "Both files must have the same depth and grid (origin and voxel size); payloads and\n"
      "attributes are not carried into the result.");
  cmd->add_option("a", args->a, "First .vol")->required()->check(CLI::ExistingFile);
  cmd->add_option("b", args->b, "Second .vol")->required()->check(CLI::ExistingFile);
  cmd->add_option("output", args->output, "Output .vol")->required();
  cmd->add_flag("--ignore-frame", args->ignore_frame, "Combine voxel indices even when the grids differ");
  cmd->add_flag("-q,--quiet", args->quiet, "Print nothing on success");
  cmd->callback([args, op, name] {
    const Tree a = open_mapped(args->a);
    const Tree b = open_mapped(args->b);
    const Tree result = op(a, b, args->ignore_frame ? FrameCheck::ignore : FrameCheck::require_equal);
    write(result, args->output);
    if (!args->quiet)
      std::printf("%s: %llu and %llu voxels -> %llu voxels\n", name, static_cast<unsigned long long>(a.voxel_count()),
                  static_cast<unsigned long long>(b.voxel_count()), static_cast<unsigned long long>(result.voxel_count()));
  });
}

}  // namespace

void add_setops(CLI::App& app) {
  add_one(app, "union", "Voxels in A or B", [](const Tree& a, const Tree& b, FrameCheck c) { return unite(a, b, c); });
  add_one(app, "intersect", "Voxels in both A and B",
          [](const Tree& a, const Tree& b, FrameCheck c) { return intersect(a, b, c); });
  add_one(app, "diff", "Voxels in A but not in B (e.g. what a later survey added)",
          [](const Tree& a, const Tree& b, FrameCheck c) { return subtract(a, b, c); });
}

}  // namespace vola::cli
