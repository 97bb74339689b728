// One function per subcommand file: each adds its subcommand to the app.
#pragma once

#include <CLI/CLI.hpp>

#include <string>

namespace vola::cli {

void add_convert(CLI::App& app);
void add_info(CLI::App& app);
void add_voxels(CLI::App& app);  // voxels and coords
void add_get(CLI::App& app);
void add_lod(CLI::App& app);
void add_setops(CLI::App& app);  // union, intersect, diff
void add_generate(CLI::App& app);
void add_export(CLI::App& app);
void add_census(CLI::App& app);
void add_components(CLI::App& app);
void add_morph(CLI::App& app);  // dilate, erode, fill, crop, downsample
void add_render(CLI::App& app);
void add_plan(CLI::App& app);
void add_view(CLI::App& app);
void add_fuse(CLI::App& app);
void add_rgbd_generate(CLI::App& app);
void add_rgbd_eval(CLI::App& app);
void add_sonify(CLI::App& app);
void add_dataset(CLI::App& app);
void add_train(CLI::App& app);
void add_classify(CLI::App& app);  // classify and evaluate
void add_collide(CLI::App& app);
void add_tile(CLI::App& app);
void add_translate(CLI::App& app);
void add_pipeline(CLI::App& app);
void add_map(CLI::App& app);

// "las (.las .laz), text (.xyz ...), ...": every input reader this build has, for the
// --format options' help (cmd_convert.cpp).
std::string known_formats();

// One-line summaries of the subcommands that run in companion executables, shared by the
// companion (its --help) and vola (its list of subcommands).
inline constexpr const char* kDatasetSummary = "Make a 3D classification dataset of 64^3 VOLA files (ModelNet10 classes)";
inline constexpr const char* kTrainSummary = "Train a 3D CNN classifier on a `vola dataset` folder";
inline constexpr const char* kClassifySummary = "Classify .vol objects with a 3D CNN (ModelNet10 classes)";
inline constexpr const char* kEvaluateSummary = "Accuracy of a 3D CNN on a labelled dataset folder";
inline constexpr const char* kViewSummary = "Show .vol files and tile sets in 3D in a web browser (a local page on 127.0.0.1)";
inline constexpr const char* kSonifySummary = "Hear a scene: pass a dry recording through the scene's acoustics";

// vola-learn, vola-view and vola-sonify hold the subcommands above (companions.cpp): vola
// execs the right one for them (returns only when argv names none of them) and lists
// them in its help.
void exec_companion_if_asked(int argc, char** argv);
void add_companion_launchers(CLI::App& app);
}  // namespace vola::cli
