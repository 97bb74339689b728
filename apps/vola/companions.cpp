// Subcommands whose libraries are heavy to load live in companion executables beside
// vola: vola-learn (dataset, train, classify, evaluate: libtorch, ~0.5 s to load),
// vola-view (view: cpp-httplib with OpenSSL and Brotli) and vola-sonify (sonify:
// libsndfile with its codecs, FFTW, libmysofa). Linked into vola, every other command would pay
// their start-up. `vola train ...` replaces itself with `vola-learn train ...` from the
// same folder, so the commands, their options and their --help are exactly the
// companion's.
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

struct Companion {
  std::string_view command;
  const char* executable;
  const char* summary;
};

constexpr Companion kCompanions[] = {
    {"dataset", "vola-learn", kDatasetSummary}, {"train", "vola-learn", kTrainSummary},
    {"classify", "vola-learn", kClassifySummary}, {"evaluate", "vola-learn", kEvaluateSummary},
    {"view", "vola-view", kViewSummary},         {"sonify", "vola-sonify", kSonifySummary},
};

}  // namespace

void exec_companion_if_asked(int argc, char** argv) {
  if (argc < 2) return;
  for (const Companion& c : kCompanions) {
    if (argv[1] != c.command) continue;
    std::error_code error;
    const std::filesystem::path self = std::filesystem::read_symlink("/proc/self/exe", error);
    const std::filesystem::path target = (error ? std::filesystem::path(argv[0]) : self).parent_path() / c.executable;
    ::execv(target.c_str(), argv);
    std::fprintf(stderr, "vola: %s needs %s (built and installed with vola): %s\n", argv[1], target.c_str(),
                 std::strerror(errno));
    std::exit(1);
  }
}

void add_companion_launchers(CLI::App& app) {
  // Listed here for `vola --help`; exec_companion_if_asked has run them before parsing.
  for (const Companion& c : kCompanions) app.add_subcommand(std::string(c.command), c.summary);
}

}  // namespace vola::cli
