// vola-view: `vola view` in an executable of its own (cpp-httplib with OpenSSL and
// Brotli), which vola execs for it so that no other command loads them (companions.cpp).
#include <CLI/CLI.hpp>

#include "commands.hpp"
#include "run_app.hpp"
#include "vola/version.hpp"

int main(int argc, char** argv) {
  CLI::App app{"vola " VOLA_VERSION_STRING " - the browser viewer (cpp-httplib)"};
  app.name("vola");
  app.require_subcommand(1);
  app.set_version_flag("--version", VOLA_VERSION_STRING);
  vola::cli::add_view(app);
  return vola::cli::run_app(app, argc, argv);
}
