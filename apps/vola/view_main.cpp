// vola-view: `vola view` in an executable of its own (cpp-httplib with OpenSSL and
// Brotli), which vola execs for it so that no other command loads them (companions.cpp).
#include "commands.hpp"
#include "run_app.hpp"

int main(int argc, char** argv) {
  constexpr void (*kCommands[])(CLI::App&) = {vola::cli::add_view};
  return vola::cli::run_companion(argc, argv, "the browser viewer (cpp-httplib)", kCommands);
}
