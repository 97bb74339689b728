#include "suggest.hpp"

#include <algorithm>
#include <utility>
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
  // Words of other tools for what a vola subcommand does under another name.
  static const std::pair<const char*, const char*> kElsewhere[] = {
      {"raster", "vola export FILE.vol OUT.tif --raster dsm"},
      {"dsm", "vola export FILE.vol OUT.tif --raster dsm"},
      {"dtm", "vola export FILE.vol OUT.tif --raster dtm"},
      {"dem", "vola export FILE.vol OUT.tif --raster dtm"},
      {"merge", "vola union A.vol B.vol OUT.vol"},
      {"crop", "vola translate IN OUT --crop ..."},
      {"filter", "vola translate IN OUT --filter ..."},
      {"classify-ground", "vola translate IN OUT --filter smrf"}};
  for (const auto& [other, use] : kElsewhere)
    if (word == other) return message + "; use " + use + " (vola --help lists the subcommands)";
  if (!best.empty()) message += "; did you mean '" + best + "'?";
  return message + " (vola --help lists them)";
}

std::optional<std::string> unknown_option(const CLI::App& app, int argc, char** argv) {
  if (argc < 3 || argv[1][0] == '-') return std::nullopt;
  const CLI::App* command = nullptr;
  for (const CLI::App* sub : app.get_subcommands([](const CLI::App*) { return true; }))
    if (sub->get_name() == argv[1]) command = sub;
  if (!command) return std::nullopt;
  for (int i = 2; i < argc; ++i) {
    const std::string word = argv[i];
    // Long options only: a lone dash and negative numbers are values.
    if (word.size() < 3 || word.rfind("--", 0) != 0) continue;
    const std::string name =
        word.substr(2, word.find('=') == std::string::npos ? std::string::npos : word.find('=') - 2);
    if (command->get_option_no_throw("--" + name) || app.get_option_no_throw("--" + name)) continue;
    std::string best;
    std::size_t best_distance = 3;  // more than 2 edits away is no suggestion
    for (const CLI::Option* option : command->get_options())
      for (const std::string& known : option->get_lnames()) {
        const std::size_t d = known.rfind(name, 0) == 0 ? 1 : edit_distance(name, known);
        if (d < best_distance) {
          best_distance = d;
          best = known;
        }
      }
    std::string message = "'--" + name + "' is not an option of vola " + command->get_name();
    if (!best.empty()) message += "; did you mean '--" + best + "'?";
    return message + " (vola " + command->get_name() + " --help lists them)";
  }
  return std::nullopt;
}

}  // namespace vola::cli
