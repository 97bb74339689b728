// vola-learn: the 3D CNN subcommands of vola (libtorch). Users run them as `vola dataset`,
// `vola train`, `vola classify`, `vola evaluate`; vola hands them over to this binary
// (companions.cpp).
#include "commands.hpp"
#include "run_app.hpp"

int main(int argc, char** argv) {
  constexpr void (*kCommands[])(CLI::App&) = {vola::cli::add_dataset, vola::cli::add_train, vola::cli::add_classify};
  return vola::cli::run_companion(argc, argv, "3D CNN classification of VOLA grids (libtorch)", kCommands);
}
