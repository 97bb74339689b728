// vola census FILE: per level blocks and cells, per attribute histograms (classification
// counts with ASPRS names), volume and footprint, voxel counts inside boxes or polygons.
// A state map (vola map) is counted as its occupied voxels, after its occupied, free and
// unknown counts.
#include <cstdio>
#include <nlohmann/json.hpp>
#include <optional>
#include <sstream>
#include <string>
#include <vector>

#include "commands.hpp"
#include "text_output.hpp"
#include "vola/analysis/census.hpp"
#include "vola/error.hpp"
#include "vola/file.hpp"
#include "vola/map/state_map.hpp"

namespace vola::cli {

namespace {

struct CensusArgs {
  std::string file;
  bool json = false;
  int bins = 16;
  std::vector<std::string> boxes, polygons;
};

std::vector<double> parse_numbers(const std::string& text, const std::string& what) {
  std::vector<double> out;
  std::string token;
  std::istringstream in(text);
  while (in >> token) {
    std::size_t start = 0;
    while (start <= token.size()) {
      const std::size_t comma = token.find(',', start);
      const std::string part = token.substr(start, comma == std::string::npos ? std::string::npos : comma - start);
      if (!part.empty()) {
        std::size_t used = 0;
        double v = 0;
        try {
          v = std::stod(part, &used);
        } catch (const std::exception&) {
          used = 0;
        }
        if (used != part.size()) throw InvalidArgument(what + ": '" + part + "' is not a number");
        out.push_back(v);
      }
      if (comma == std::string::npos) break;
      start = comma + 1;
    }
  }
  return out;
}

std::vector<analysis::Region> parse_regions(const CensusArgs& a) {
  std::vector<analysis::Region> regions;
  for (const std::string& b : a.boxes) {
    const auto v = parse_numbers(b, "--box");
    if (v.size() != 6) throw InvalidArgument("--box needs 6 numbers: xmin,ymin,zmin,xmax,ymax,zmax");
    for (int i = 0; i < 3; ++i)  // an upside-down box counted 0 voxels without a word; crop refuses one too
      if (!(v[i] <= v[i + 3]))
        throw InvalidArgument("--box " + b + ": its " + "xyz"[i] + " range runs from " + shortest_text(v[i]) +
                              " down to " + shortest_text(v[i + 3]) + " (give the minima first)");
    regions.push_back({"box " + b, Box{{v[0], v[1], v[2]}, {v[3], v[4], v[5]}}, {}});
  }
  for (const std::string& p : a.polygons) {
    const auto v = parse_numbers(p, "--polygon");
    if (v.size() < 6 || v.size() % 2) throw InvalidArgument("--polygon needs 3 or more x,y pairs");
    analysis::Region r{"polygon " + p, std::nullopt, {}};
    for (std::size_t i = 0; i < v.size(); i += 2) r.polygon.push_back({v[i], v[i + 1]});
    regions.push_back(std::move(r));
  }
  return regions;
}

nlohmann::json histogram_json(const analysis::Histogram& h) {
  return {{"min", h.min}, {"max", h.max}, {"counts", h.counts}};
}

void print_histogram(const analysis::Histogram& h) {
  const double width = h.counts.empty() ? 0 : (h.max - h.min) / static_cast<double>(h.counts.size());
  for (std::size_t i = 0; i < h.counts.size(); ++i)
    std::printf("    [%12.6g, %12.6g%c %12llu\n", h.min + width * static_cast<double>(i),
                h.min + width * static_cast<double>(i + 1), i + 1 == h.counts.size() ? ']' : ')',
                static_cast<unsigned long long>(h.counts[i]));
}

void print_states(const map::StateCounts& s) {
  std::printf("  state map: %llu occupied, %llu free, %llu unknown in the known voxels' box (%u..%u, %u..%u, "
              "%u..%u); the counts below are of the occupied voxels\n",
              static_cast<unsigned long long>(s.occupied), static_cast<unsigned long long>(s.free),
              static_cast<unsigned long long>(s.unknown_in_bounds), s.min.x, s.max.x, s.min.y, s.max.y, s.min.z,
              s.max.z);
}

void run_census(const CensusArgs& a) {
  const Tree file = open_mapped(a.file);
  std::optional<map::StateCounts> states;
  if (map::is_state_map(file)) states = map::state_counts(file);
  const Tree tree = map::occupied_tree(file);
  check_mapped(file);
  analysis::CensusOptions options;
  options.bins = a.bins;
  options.regions = parse_regions(a);
  const analysis::Census c = analysis::take_census(tree, options);

  if (a.json) {
    nlohmann::json j;
    j["file"] = a.file;
    j["depth"] = c.depth;
    j["voxels"] = c.voxels;
    if (states)
      j["states"] = {{"occupied", states->occupied}, {"free", states->free},
                     {"unknown_in_bounds", states->unknown_in_bounds},
                     {"bounds", {{"min", {states->min.x, states->min.y, states->min.z}},
                                 {"max", {states->max.x, states->max.y, states->max.z}}}}};
    for (std::size_t l = 0; l < c.levels.size(); ++l)
      j["levels"].push_back({{"level", l}, {"blocks", c.levels[l].blocks}, {"cells", c.levels[l].cells},
                             {"fill", c.levels[l].fill}});
    j["voxel_size"] = c.voxel_size ? nlohmann::json(*c.voxel_size) : nlohmann::json(nullptr);
    j["columns"] = c.columns;
    j["volume"] = c.voxel_size ? nlohmann::json(c.volume()) : nlohmann::json(nullptr);
    j["footprint_area"] = c.voxel_size ? nlohmann::json(c.footprint_area()) : nlohmann::json(nullptr);
    j["heights"] = histogram_json(c.heights);
    j["attributes"] = nlohmann::json::array();
    for (const auto& at : c.attributes) {
      // A column without a single value (a field that is no_data on every point) has no
      // mean and no histogram: null, not a mean of 0 over 16 empty bins.
      nlohmann::json col{{"name", at.name},
                         {"count", at.count},
                         {"without_value", at.without_value},
                         {"mean", at.count ? nlohmann::json(at.mean) : nlohmann::json(nullptr)},
                         {"histogram", at.count ? histogram_json(at.histogram) : nlohmann::json(nullptr)}};
      if (at.name == "classification") {
        col["classes"] = nlohmann::json::array();
        for (const auto& k : at.classes)
          col["classes"].push_back({{"code", k.code}, {"name", analysis::asprs_class_name(k.code)}, {"voxels", k.voxels}});
      }
      j["attributes"].push_back(std::move(col));
    }
    j["regions"] = nlohmann::json::array();
    for (std::size_t i = 0; i < options.regions.size(); ++i)
      j["regions"].push_back({{"region", options.regions[i].label}, {"voxels", c.region_voxels[i]}});
    std::printf("%s\n", j.dump(2, ' ', false, nlohmann::json::error_handler_t::replace).c_str());
    return;
  }

  std::printf("%s: depth %d, %llu voxels\n", a.file.c_str(), c.depth, static_cast<unsigned long long>(c.voxels));
  if (states) print_states(*states);
  std::printf("  level %12s %14s %8s\n", "blocks", "cells", "fill");
  for (std::size_t l = 0; l < c.levels.size(); ++l)
    std::printf("  %5zu %12llu %14llu %8.4f\n", l, static_cast<unsigned long long>(c.levels[l].blocks),
                static_cast<unsigned long long>(c.levels[l].cells), c.levels[l].fill);
  std::printf("  occupied columns: %llu\n", static_cast<unsigned long long>(c.columns));
  if (c.voxel_size)
    std::printf("  voxel size %.9g: volume %.9g, footprint area %.9g (CRS units)\n", *c.voxel_size, c.volume(),
                c.footprint_area());
  else
    std::printf("  voxel size unknown (no GIS grid recorded): no volume or area\n");
  std::printf("  voxel centre z:\n");
  print_histogram(c.heights);
  for (const auto& at : c.attributes) {
    if (at.count == 0) {
      std::printf("  attribute %s: no value (%llu voxels without one)\n", at.name.c_str(),
                  static_cast<unsigned long long>(at.without_value));
      continue;
    }
    std::printf("  attribute %s: %llu values, mean %.6g%s\n", at.name.c_str(),
                static_cast<unsigned long long>(at.count), at.mean,
                at.without_value ? (" (" + std::to_string(at.without_value) + " voxels without a value)").c_str() : "");
    if (at.name == "classification")
      for (const auto& k : at.classes)
        std::printf("    %3d %-38s %12llu\n", k.code, std::string(analysis::asprs_class_name(k.code)).c_str(),
                    static_cast<unsigned long long>(k.voxels));
    else
      print_histogram(at.histogram);
  }
  for (std::size_t i = 0; i < options.regions.size(); ++i)
    std::printf("  %s: %llu voxels\n", options.regions[i].label.c_str(),
                static_cast<unsigned long long>(c.region_voxels[i]));
}

}  // namespace

void add_census(CLI::App& app) {
  auto args = std::make_shared<CensusArgs>();
  auto* cmd = app.add_subcommand("census", "Count what a .vol holds: levels, attributes, volume, regions");
  cmd->footer(
      "Regions are in world coordinates; a voxel counts when its centre is inside.\n"
      "Volume and footprint area need a GIS grid (vola convert --voxel-size).\n"
      "A state map (vola map) counts its occupied voxels, after a line (JSON: \"states\") with its\n"
      "occupied, free and unknown voxel counts (unknown: within the box of the known voxels).\n"
      "An attribute's figures are over the voxels with a value: a NaN value (no point of the voxel\n"
      "had one, a LAS no_data) is counted apart (JSON: \"without_value\").\n"
      "Example: vola census autzen.vol --box 636000,849000,400,637000,850000,500 --json");
  cmd->add_option("file", args->file, "Input .vol")->required()->check(CLI::ExistingFile);
  cmd->add_flag("--json", args->json, "Print JSON instead of a table");
  cmd->add_option("--bins", args->bins, "Histogram bins")->check(CLI::Range(1, 4096));
  cmd->add_option("--box", args->boxes, "Count voxels in xmin,ymin,zmin,xmax,ymax,zmax (repeatable)");
  cmd->add_option("--polygon", args->polygons, "Count voxels in the x,y polygon 'x1,y1 x2,y2 x3,y3 ...' (repeatable)");
  cmd->callback([args] { run_census(*args); });
}

}  // namespace vola::cli
