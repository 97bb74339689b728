// One function per subcommand file: each adds its subcommand to the app.
#pragma once

#include <CLI/CLI.hpp>

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

// vola-learn holds dataset, train, classify and evaluate (learn_launcher.cpp): vola execs
// it for them (returns only when argv names none of them) and lists them in its help.
void exec_learn_if_asked(int argc, char** argv);
void add_learn_launchers(CLI::App& app);
}  // namespace vola::cli
