#include "suggest.hpp"

#include <algorithm>
#include <vector>

namespace vola::cli {

namespace {

// Levenshtein distance (insertions, deletions, substitutions), one row at a time.
std::size_t edit_distance(const std::string& a, const std::string& b) {
  std::vector<std::size_t> row(b.size() + 1);
  for (std::size_t j = 0; j <= b.size(); ++j) row[j] = j;
  for (std::size_t i = 1; i <= a.size(); ++i) {
    std::size_t diagonal = row[0];
    row[0] = i;
    for (std::size_t j = 1; j <= b.size(); ++j) {
      const std::size_t above = row[j];
      row[j] = std::min({row[j] + 1, row[j - 1] + 1, diagonal + (a[i - 1] == b[j - 1] ? 0 : 1)});
      diagonal = above;
    }
  }
  return row[b.size()];
}

}  // namespace

std::optional<std::string> unknown_subcommand(const CLI::App& app, int argc, char** argv) {
  const auto subcommands = app.get_subcommands([](const CLI::App*) { return true; });
  if (argc < 2 || argv[1][0] == '-' || subcommands.empty()) return std::nullopt;
  const std::string word = argv[1];
  std::string best;
  std::size_t best_distance = 3;  // more than 2 edits away is no suggestion
  for (const CLI::App* sub : subcommands) {
    const std::string& name = sub->get_name();
    if (name == word) return std::nullopt;
    const std::size_t d = name.rfind(word, 0) == 0 ? 1 : edit_distance(word, name);
    if (d < best_distance) {
      best_distance = d;
      best = name;
    }
  }
  std::string message = "'" + word + "' is not a vola subcommand";
  if (!best.empty()) message += "; did you mean '" + best + "'?";
  return message + " (vola --help lists them)";
}

}  // namespace vola::cli
