// vola union | intersect | diff A B OUT: set operations on voxels of one grid. diff
// also counts the change between two surveys (A = before, B = after).
#include <cstdio>
#include <filesystem>
#include <string>

#include "commands.hpp"
#include "open_voxels.hpp"
#include "output_checks.hpp"
#include "vola/analysis/change.hpp"
#include "vola/error.hpp"
#include "vola/file.hpp"
#include "vola/geo/crs.hpp"
#include "vola/setops.hpp"

namespace vola::cli {

namespace {

struct SetArgs {
  std::string a, b, output;
  std::string outputs_dir;  // diff only
  bool ignore_frame = false;
  bool quiet = false;
};

// Voxel indices of one grid in two CRSs are not the same places: refuse, naming both
// (as `vola tile` does), unless PROJ finds the two CRSs equivalent. A file that states
// no CRS is taken to be in the other's, with a warning.
void check_same_crs(const std::string& path_a, const Tree& a, const std::string& path_b, const Tree& b) {
  const std::optional<std::string> crs_a = geo::crs_definition(a.georef()), crs_b = geo::crs_definition(b.georef());
  if (crs_a.has_value() != crs_b.has_value())
    std::fprintf(stderr, "vola: warning: %s states no CRS; taken to be %s's\n", (crs_a ? path_b : path_a).c_str(),
                 (crs_a ? path_a : path_b).c_str());
  if (const auto differ = geo::different_crs(a.georef(), b.georef()))
    throw InvalidArgument(path_a + " is in " + differ->a + ", " + path_b + " in " + differ->b +
                          ": the same voxel indices are different places. Convert both into one CRS "
                          "(vola convert --target-crs) or relabel one (--assign-crs); --ignore-frame combines "
                          "them anyway");
}

template <class Op>
void add_one(CLI::App& app, const char* name, const char* help, Op op) {
  auto args = std::make_shared<SetArgs>();
  auto* cmd = app.add_subcommand(name, help);
  cmd->footer(
      "Both files must be on one grid and in one CRS (PROJ decides whether two spellings name one\n"
      "CRS): the same voxel size, origins a whole number of voxels apart (maps of separate vola map\n"
      "runs are: their origins follow their data; the result takes the lower origin and the depth\n"
      "that holds both). Payloads and attributes are not carried into the result.\n"
      "Example: vola " +
      std::string(name) + " a.vol b.vol out.vol");
  cmd->add_option("a", args->a, "First .vol")->required()->check(CLI::ExistingFile);
  cmd->add_option("b", args->b, "Second .vol")->required()->check(CLI::ExistingFile);
  cmd->add_option("output", args->output, "Output .vol")->required();
  cmd->add_flag("--ignore-frame", args->ignore_frame, "Combine voxel indices even when the grids or CRSs differ");
  cmd->add_flag("-q,--quiet", args->quiet, "Print nothing on success but warnings (to stderr)");
  cmd->callback([args, op, name] {
    refuse_outputs_over_inputs({args->a, args->b}, {args->output}, std::string("vola ") + name);
    const Tree a = open_voxels_to_write(args->a, std::string("vola ") + name);
    const Tree b = open_voxels_to_write(args->b, std::string("vola ") + name);
    if (!args->ignore_frame) check_same_crs(args->a, a, args->b, b);
    const Tree result = op(a, b, args->ignore_frame ? FrameCheck::ignore : FrameCheck::require_equal);
    write(result, args->output);
    if (!args->quiet)
      std::printf("%s: %llu and %llu voxels -> %llu voxels\n", name, static_cast<unsigned long long>(a.voxel_count()),
                  static_cast<unsigned long long>(b.voxel_count()), static_cast<unsigned long long>(result.voxel_count()));
  });
}

// diff: OUT (optional) is A - B as always; the counts are printed either way.
void add_diff(CLI::App& app) {
  auto args = std::make_shared<SetArgs>();
  auto* cmd = app.add_subcommand("diff", "Voxels in A but not in B, and the change between two surveys");
  cmd->footer(
      "With A the earlier survey and B the later one: added = B - A, removed = A - B,\n"
      "unchanged = both. OUTPUT (optional) receives A - B, the 'removed' set (swap A and B\n"
      "to get what was added). --outputs DIR writes added.vol, removed.vol, unchanged.vol.\n"
      "Both files must be on one grid (one voxel size, origins whole voxels apart) and in one CRS;\n"
      "payloads and attributes are not carried.\n"
      "Example: vola diff before.vol after.vol --outputs change/");
  cmd->add_option("a", args->a, "First .vol (before)")->required()->check(CLI::ExistingFile);
  cmd->add_option("b", args->b, "Second .vol (after)")->required()->check(CLI::ExistingFile);
  cmd->add_option("output", args->output, "Output .vol: A - B");
  cmd->add_option("--outputs", args->outputs_dir, "Write added.vol, removed.vol and unchanged.vol into this folder");
  cmd->add_flag("--ignore-frame", args->ignore_frame, "Combine voxel indices even when the grids or CRSs differ");
  cmd->add_flag("-q,--quiet", args->quiet, "Print nothing on success but warnings (to stderr)");
  cmd->callback([args] {
    std::vector<std::string> outputs{args->output};
    if (!args->outputs_dir.empty())
      for (const char* file : {"added.vol", "removed.vol", "unchanged.vol"})
        outputs.push_back((std::filesystem::path(args->outputs_dir) / file).string());
    refuse_outputs_over_inputs({args->a, args->b}, outputs, "vola diff");
    const bool writes = !args->output.empty() || !args->outputs_dir.empty();
    const Tree a = writes ? open_voxels_to_write(args->a, "vola diff") : open_voxels(args->a);
    const Tree b = writes ? open_voxels_to_write(args->b, "vola diff") : open_voxels(args->b);
    if (!args->ignore_frame) check_same_crs(args->a, a, args->b, b);
    const FrameCheck check = args->ignore_frame ? FrameCheck::ignore : FrameCheck::require_equal;
    const Tree removed = subtract(a, b, check);  // also checks depths and frames
    if (!args->output.empty()) write(removed, args->output);
    if (!args->outputs_dir.empty()) {
      std::filesystem::create_directories(args->outputs_dir);
      const std::filesystem::path dir(args->outputs_dir);
      write(subtract(b, a, check), (dir / "added.vol").string());
      write(removed, (dir / "removed.vol").string());
      write(intersect(a, b, check), (dir / "unchanged.vol").string());
    }
    if (args->quiet) return;
    if (!args->output.empty())
      std::printf("diff: %llu and %llu voxels -> %llu voxels\n", static_cast<unsigned long long>(a.voxel_count()),
                  static_cast<unsigned long long>(b.voxel_count()), static_cast<unsigned long long>(removed.voxel_count()));
    // On one grid, one merge of the key lists counts; on one lattice with other origins or
    // depths, the set operations (which move the voxels into one frame) do.
    analysis::ChangeCounts c;
    if (args->ignore_frame || (a.depth() == b.depth() && a.frame() == b.frame())) {
      c = analysis::count_changes(a, b);
    } else {
      c.added = subtract(b, a, check).voxel_count();
      c.removed = removed.voxel_count();
      c.unchanged = intersect(a, b, check).voxel_count();
    }
    std::printf("added %llu, removed %llu, unchanged %llu voxels\n", static_cast<unsigned long long>(c.added),
                static_cast<unsigned long long>(c.removed), static_cast<unsigned long long>(c.unchanged));
  });
}

}  // namespace

void add_setops(CLI::App& app) {
  add_one(app, "union", "Voxels in A or B", [](const Tree& a, const Tree& b, FrameCheck c) { return unite(a, b, c); });
  add_one(app, "intersect", "Voxels in both A and B",
          [](const Tree& a, const Tree& b, FrameCheck c) { return intersect(a, b, c); });
  add_diff(app);
}

}  // namespace vola::cli
