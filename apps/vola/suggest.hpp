// "Did you mean": the subcommand or option nearest to a mistyped one.
#pragma once

#include <optional>
#include <string>

#include <CLI/CLI.hpp>

namespace vola::cli {

// When argv's first word is not an option and names no subcommand of `app`: the message
// that says so, with the nearest subcommand (edit distance at most 2, or one it begins)
// when there is one. Nothing when the first word is fine.
std::optional<std::string> unknown_subcommand(const CLI::App& app, int argc, char** argv);
// For a command line CLI11 refused: the first long option (--name or --name=value) that
// the subcommand argv[1] does not know, with its nearest known option, as above.
std::optional<std::string> unknown_option(const CLI::App& app, int argc, char** argv);

}  // namespace vola::cli
