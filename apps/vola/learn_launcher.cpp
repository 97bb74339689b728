// The 3D CNN subcommands (dataset, train, classify, evaluate) are built into vola-learn,
// the only executable that links libtorch: loading it costs about half a second, which
// every other command would otherwise pay at start-up. `vola train ...` replaces itself
// with `vola-learn train ...` from the same folder, so the commands, their options and
// their --help are exactly those of vola-learn.
#include <unistd.h>

#include <cerrno>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <string_view>

#include "commands.hpp"

namespace vola::cli {

namespace {

constexpr std::string_view kLearnCommands[] = {"dataset", "train", "classify", "evaluate"};

}  // namespace

void exec_learn_if_asked(int argc, char** argv) {
  if (argc < 2) return;
  bool learn = false;
  for (const std::string_view c : kLearnCommands) learn = learn || argv[1] == c;
  if (!learn) return;
  std::error_code error;
  const std::filesystem::path self = std::filesystem::read_symlink("/proc/self/exe", error);
  const std::filesystem::path target = (error ? std::filesystem::path(argv[0]) : self).parent_path() / "vola-learn";
  ::execv(target.c_str(), argv);
  std::fprintf(stderr, "vola: %s needs %s (built and installed with vola): %s\n", argv[1], target.c_str(),
               std::strerror(errno));
  std::exit(1);
}

void add_learn_launchers(CLI::App& app) {
  // Listed here for `vola --help`; exec_learn_if_asked has run them before parsing.
  app.add_subcommand("dataset", "Make a 3D classification dataset of 64^3 VOLA files (ModelNet10 classes)");
  app.add_subcommand("train", "Train a 3D CNN classifier on a `vola dataset` folder");
  app.add_subcommand("classify", "Classify .vol objects with a 3D CNN (ModelNet10 classes)");
  app.add_subcommand("evaluate", "Accuracy of a 3D CNN on a labelled dataset folder");
}

}  // namespace vola::cli
