// vola dilate | erode | fill | crop | downsample IN OUT: morphology and resampling on
// the sparse tree. Results keep the input's grid and georeferencing; attributes and
// payloads are dropped.
#include <cstdio>
#include <functional>
#include <string>

#include "commands.hpp"
#include "number_checks.hpp"
#include "open_voxels.hpp"
#include "output_checks.hpp"
#include "progress.hpp"
#include "vola/analysis/crop.hpp"
#include "vola/analysis/downsample.hpp"
#include "vola/analysis/fill.hpp"
#include "vola/analysis/morphology.hpp"
#include "vola/error.hpp"
#include "vola/file.hpp"

namespace vola::cli {

namespace {

constexpr const char* kDropped = "The result keeps the input's grid and CRS; attribute columns and payloads are dropped.";

struct MorphArgs {
  std::string input, output;
  int radius = 1;
  std::string element = "sphere";
  std::vector<std::uint32_t> min, max;
  int depth = 1;
  std::uint64_t min_voxels = 1;
  bool quiet = false;
  bool keep_grid = false;  // dilate: clip to the input's grid
};

CLI::App* add_io(CLI::App& app, const char* name, const char* help, const std::shared_ptr<MorphArgs>& args) {
  auto* cmd = app.add_subcommand(name, help);
  cmd->add_option("input", args->input, "Input .vol")->required()->check(CLI::ExistingFile);
  cmd->add_option("output", args->output, "Output .vol")->required();
  cmd->add_flag("-q,--quiet", args->quiet, "Print nothing on success but warnings (to stderr)");
  return cmd;
}

void add_radius(CLI::App* cmd, const std::shared_ptr<MorphArgs>& args) {
  cmd->add_option("--radius", args->radius, "Radius in voxels")->required()->check(non_negative_number());
  cmd->add_option("--element", args->element, "sphere (dx^2+dy^2+dz^2 <= r^2) or cube (max |d| <= r)")
      ->check(CLI::IsMember({"sphere", "cube"}));
}

// dilate or erode with a progress bar (a radius of tens of voxels takes minutes).
template <Tree (*Op)(const Tree&, int, analysis::Element, const analysis::MorphProgress&)>
Tree morph_with_progress(const MorphArgs& a, const Tree& in, analysis::Element element, const char* name) {
  if (a.quiet) return Op(in, a.radius, element, {});
  Progress progress(name);
  Tree out = Op(in, a.radius, element, [&](std::uint64_t done, std::uint64_t total) { progress.update(done, total); });
  progress.finish();
  return out;
}

analysis::Element element_of(const std::string& name) {
  return name == "cube" ? analysis::Element::cube : analysis::Element::sphere;
}

// The input, once the output is known not to be it (the result would replace it).
Tree open_input(const MorphArgs& a, const char* name) {
  refuse_outputs_over_inputs({a.input}, {a.output}, std::string("vola ") + name);
  return open_voxels_to_write(a.input, std::string("vola ") + name);
}

void finish(const MorphArgs& a, const char* name, const Tree& in, const Tree& out, const std::string& extra = {}) {
  write(out, a.output);
  if (!a.quiet)
    std::printf("%s: %llu voxels -> %llu voxels%s\n", name, static_cast<unsigned long long>(in.voxel_count()),
                static_cast<unsigned long long>(out.voxel_count()), extra.c_str());
}

}  // namespace

void add_morph(CLI::App& app) {
  {
    auto args = std::make_shared<MorphArgs>();
    auto* cmd = add_io(app, "dilate", "Grow the voxels by a radius (inflate obstacles)", args);
    cmd->footer(
        "Where the voxels come within the radius of the grid's faces (a converted map's origin sits on its data's\n"
        "minimum), the grid grows so that nothing is cut: its origin moves down by whole voxels and its depth rises\n"
        "when needed, every voxel staying at its world place (the summary says so); --keep-grid clips instead.\n"
        "Attribute columns and payloads are dropped.\n"
        "Example: vola dilate obstacles.vol --radius 3 inflated.vol");
    add_radius(cmd, args);
    cmd->add_flag("--keep-grid", args->keep_grid,
                  "Keep the input's grid: what the dilation reaches beyond its faces is cut off");
    cmd->callback([args] {
      const Tree in = open_input(*args, "dilate");
      const Tree out =
          args->keep_grid
              ? morph_with_progress<&analysis::dilate>(*args, in, element_of(args->element), "dilating")
              : morph_with_progress<&analysis::dilate_unclipped>(*args, in, element_of(args->element), "dilating");
      std::string grown;
      const Frame before = in.frame(), after = out.frame();
      if (out.depth() != in.depth() || before.origin != after.origin) {
        char text[160];
        std::snprintf(text, sizeof text, " (grid grown: origin moved by %.0f %.0f %.0f voxels, depth %d -> %d)",
                      (after.origin[0] - before.origin[0]) / before.voxel_size,
                      (after.origin[1] - before.origin[1]) / before.voxel_size,
                      (after.origin[2] - before.origin[2]) / before.voxel_size, in.depth(), out.depth());
        grown = text;
      }
      finish(*args, "dilate", in, out, grown);
    });
  }
  {
    auto args = std::make_shared<MorphArgs>();
    auto* cmd = add_io(app, "erode", "Keep the voxels whose whole neighbourhood of a radius is occupied", args);
    cmd->footer(
        std::string("Cells outside the grid count as empty.\n") + kDropped +
        "\nExample: vola erode scan.vol --radius 1 core.vol   (the shell: vola diff scan.vol core.vol shell.vol)");
    add_radius(cmd, args);
    cmd->callback([args] {
      const Tree in = open_input(*args, "erode");
      finish(*args, "erode", in,
             morph_with_progress<&analysis::erode>(*args, in, element_of(args->element), "eroding"));
    });
  }
  {
    auto args = std::make_shared<MorphArgs>();
    auto* cmd = add_io(app, "fill", "Fill enclosed cavities (empty cells the outside cannot reach face to face)", args);
    cmd->footer(std::string("Works in the voxels' bounding box, refused beyond 2^33 cells (crop first).\n") + kDropped +
                "\nExample: vola fill building.vol solid.vol");
    cmd->callback([args] {
      const Tree in = open_input(*args, "fill");
      analysis::FillReport report;
      const Tree out = analysis::fill_cavities(in, &report);
      finish(*args, "fill", in, out, " (" + std::to_string(report.filled) + " cavity cells filled)");
    });
  }
  {
    auto args = std::make_shared<MorphArgs>();
    auto* cmd = add_io(app, "crop", "Keep the voxels inside a box of voxel indices", args);
    cmd->footer(std::string("Example: vola crop scan.vol --min 0,0,0 --max 99,99,20 part.vol\n") + kDropped);
    cmd->add_option("--min", args->min, "x,y,z of the first voxel (inclusive)")->required()->delimiter(',')->expected(3);
    cmd->add_option("--max", args->max, "x,y,z of the last voxel (inclusive)")->required()->delimiter(',')->expected(3);
    cmd->callback([args] {
      const Tree in = open_input(*args, "crop");
      const auto& lo = args->min;
      const auto& hi = args->max;
      finish(*args, "crop", in, analysis::crop(in, {lo[0], lo[1], lo[2]}, {hi[0], hi[1], hi[2]}));
    });
  }
  {
    auto args = std::make_shared<MorphArgs>();
    auto* cmd = add_io(app, "downsample", "Resample to a coarser depth, keeping cells with enough voxels", args);
    cmd->footer(std::string("--min-voxels 1 gives the voxels of vola lod; the voxel size grows 4x per level.\n") +
                "Attribute columns and payloads are dropped.\n"
                "Example: vola downsample survey.vol --depth 4 --min-voxels 8 coarse.vol");
    cmd->add_option("--depth", args->depth, "Depth of the result")->required()->check(CLI::Range(1, 10));
    cmd->add_option("--min-voxels", args->min_voxels, "Voxels a coarse cell needs to be kept")->check(positive_number());
    cmd->callback([args] {
      const Tree in = open_input(*args, "downsample");
      finish(*args, "downsample", in, analysis::downsample(in, args->depth, args->min_voxels));
    });
  }
}

}  // namespace vola::cli
