// vola: the command-line tool. Each subcommand lives in its own file; errors from the
// library become one line on stderr and exit status 1 (2 for usage errors). The 3D CNN
// subcommands, view and sonify run in companion executables beside this binary
// (companions.cpp), so that no other command pays for loading their libraries.
#include <CLI/CLI.hpp>

#include "commands.hpp"
#include "run_app.hpp"
#include "vola/version.hpp"

int main(int argc, char** argv) {
  vola::cli::exec_companion_if_asked(argc, argv);
  CLI::App app{"vola " VOLA_VERSION_STRING
               " - the VOLA volumetric format: 3D space as levels of 64-bit words,\n"
               "one word per 4x4x4 block, one bit per voxel, children found by counting bits.\n\n"
               "Examples:\n"
               "  vola convert scan.xyz scan.vol --voxel-size 0.25 --assign-crs 29902   # GIS grid, 25 cm voxels\n"
               "  vola convert pts.txt pts.vol --quantize toolkit --depth 5         # as the reference toolkit\n"
               "  vola info scan.vol\n"
               "  vola get scan.vol 10 20 3\n"
               "  vola lod scan.vol --depth 4 coarse.vol\n"
               "  vola diff before.vol after.vol --outputs change/                  # added, removed, unchanged\n"
               "  vola generate city city.xyz --points 1000000\n"
               "  vola tile *.las --tile-size 1000 --depth 6 -o tiles/           # a whole survey as tiles\n"};
  app.require_subcommand(1);
  app.set_version_flag("--version", VOLA_VERSION_STRING);
  app.footer("Run 'vola SUBCOMMAND --help' for the options of one subcommand.");
  vola::cli::add_convert(app);
  vola::cli::add_info(app);
  vola::cli::add_voxels(app);
  vola::cli::add_get(app);
  vola::cli::add_lod(app);
  vola::cli::add_setops(app);
  vola::cli::add_generate(app);
  vola::cli::add_export(app);
  vola::cli::add_census(app);
  vola::cli::add_components(app);
  vola::cli::add_morph(app);
  vola::cli::add_render(app);
  vola::cli::add_plan(app);
  vola::cli::add_fuse(app);
  vola::cli::add_rgbd_generate(app);
  vola::cli::add_rgbd_eval(app);
  vola::cli::add_companion_launchers(app);
  vola::cli::add_collide(app);
  vola::cli::add_tile(app);
  vola::cli::add_translate(app);
  vola::cli::add_pipeline(app);
  vola::cli::add_map(app);
  return vola::cli::run_app(app, argc, argv);
}
