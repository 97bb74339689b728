// vola-learn: the 3D CNN subcommands of vola (libtorch). Users run them as `vola dataset`,
// `vola train`, `vola classify`, `vola evaluate`; vola hands them over to this binary
// (companions.cpp).
#include <CLI/CLI.hpp>

#include "commands.hpp"
#include "run_app.hpp"
#include "vola/version.hpp"

int main(int argc, char** argv) {
  CLI::App app{"vola " VOLA_VERSION_STRING " - 3D CNN classification of VOLA grids (libtorch)"};
  app.name("vola");
  app.require_subcommand(1);
  app.set_version_flag("--version", VOLA_VERSION_STRING);
  vola::cli::add_dataset(app);
  vola::cli::add_train(app);
  vola::cli::add_classify(app);
  return vola::cli::run_app(app, argc, argv);
}
