// Seeds for fuzz_materials_read: one material table per LAS file of the shared data
// folder (beside golden/), mapping the classes EXPECTED.txt lists for it to coefficients
// (alternately one value and six band values), plus tables that reach every branch:
// payload ids, payload-only, defaults only, per-band defaults, negative and large ids.
// Linked into fuzz_materials_read_replay in place of fuzz_seeds.cpp.
#include <algorithm>
#include <fstream>
#include <regex>
#include <string>

#include "fuzz_seeds.hpp"

namespace vola_fuzz {
namespace {

Seed text(const std::string& name, const std::string& s) { return {name, std::vector<std::uint8_t>(s.begin(), s.end())}; }

}  // namespace

std::vector<Seed> synthetic_seeds() {
  return {
      text("doc_example.json",
           "{\n  \"attribute\": \"classification\",\n  \"default\": 0.3,\n  \"materials\": {\n    \"2\": 0.2,\n"
           "    \"6\": [0.98, 0.97, 0.96, 0.95, 0.93, 0.90]\n  }\n}\n"),
      text("payload.json", R"({"attribute": "payload", "materials": {"0": 0.1, "37": 1, "255": [0,0.2,0.4,0.6,0.8,1]}})"),
      text("default_only.json", R"({"default": 0.75, "materials": {}})"),
      text("default_bands.json", R"({"default": [0.5,0.5,0.4,0.4,0.3,0.3], "materials": {}})"),
      text("ids.json", R"({"attribute": "classification", "materials": {"-1": 0.5, "65536": 0.25, "9007199254740993": 0.0, "0": 1e-300}})"),
      text("other_column.json", R"({"attribute": "intensity", "materials": {"1": 0.5}})"),
  };
}

// A table per "<file>.las: ... classes={2: 1, 5: 30}" line of data/EXPECTED.txt.
std::vector<Seed> golden_seeds(const std::filesystem::path& golden) {
  std::vector<Seed> seeds;
  const auto expected = shared_data(golden, "EXPECTED.txt");
  if (expected.empty()) return seeds;
  std::ifstream in(expected);
  const std::regex line_re(R"(^(\S+)\.la[sz]: .*classes=\{([^}]*)\})");
  const std::regex class_re(R"((\d+):)");
  std::string line;
  while (std::getline(in, line)) {
    std::smatch m;
    if (!std::regex_search(line, m, line_re)) continue;
    std::string materials;
    const std::string classes = m[2];
    int k = 0;
    for (auto it = std::sregex_iterator(classes.begin(), classes.end(), class_re); it != std::sregex_iterator(); ++it, ++k) {
      const double c = 0.1 + 0.08 * (k % 10);
      // Appended piece by piece: GCC 12 misreads `"literal" + std::string` (-Wrestrict).
      std::string value = std::to_string(c);
      if (k % 2) value = std::string("[") + value + "," + value + ",0.5,0.5," + std::to_string(c / 2) + ",0]";
      if (!materials.empty()) materials += ", ";
      materials.append("\"").append((*it)[1].str()).append("\": ").append(value);
    }
    seeds.push_back(text("classes_" + m[1].str() + ".json",
                         "{\"attribute\": \"classification\", \"default\": 0.3, \"materials\": {" + materials + "}}"));
  }
  std::sort(seeds.begin(), seeds.end(), [](const Seed& a, const Seed& b) { return a.name < b.name; });
  seeds.erase(std::unique(seeds.begin(), seeds.end(), [](const Seed& a, const Seed& b) { return a.name == b.name; }),
              seeds.end());
  return seeds;
}

}  // namespace vola_fuzz
