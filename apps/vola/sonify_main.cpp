// vola-sonify: `vola sonify` in an executable of its own (libsndfile and its codecs,
// FFTW), which vola execs for it so that no other command loads them (companions.cpp).
#include <CLI/CLI.hpp>

#include "commands.hpp"
#include "run_app.hpp"
#include "vola/version.hpp"

int main(int argc, char** argv) {
  CLI::App app{"vola " VOLA_VERSION_STRING " - auralisation of a scene (libsndfile, FFTW)"};
  app.name("vola");
  app.require_subcommand(1);
  app.set_version_flag("--version", VOLA_VERSION_STRING);
  vola::cli::add_sonify(app);
  return vola::cli::run_app(app, argc, argv);
}
