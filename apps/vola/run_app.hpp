// Parses and runs a CLI11 app the way every vola executable does: library errors become
// one line "vola: ..." on stderr and exit status 1, usage errors CLI11's status (2).
#pragma once

#include <CLI/CLI.hpp>

#include <cstddef>

namespace vola::cli {

int run_app(CLI::App& app, int argc, char** argv);

// The main of a companion executable (companions.cpp): an app named vola, described as
// "vola VERSION - <what>", with the subcommands `add` adds, run by run_app.
int run_companion(int argc, char** argv, const char* what, void (*const* add)(CLI::App&), std::size_t adds);
template <std::size_t N>
int run_companion(int argc, char** argv, const char* what, void (*const (&add)[N])(CLI::App&)) {
  return run_companion(argc, argv, what, add, N);
}

}  // namespace vola::cli
