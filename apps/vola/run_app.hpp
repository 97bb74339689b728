// Parses and runs a CLI11 app the way every vola executable does: library errors become
// one line "vola: ..." on stderr and exit status 1, usage errors CLI11's status (2).
#pragma once

#include <CLI/CLI.hpp>

namespace vola::cli {

int run_app(CLI::App& app, int argc, char** argv);

}  // namespace vola::cli
