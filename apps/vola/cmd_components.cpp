// vola components FILE: connected components (6, 18 or 26 neighbours), listed largest
// first; optionally per classification code, each component as its own .vol, or the
// labels as a per-voxel attribute column.
#include <cstdio>
#include <filesystem>
#include <map>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "commands.hpp"
#include "open_voxels.hpp"
#include "output_checks.hpp"
#include "vola/analysis/census.hpp"
#include "vola/analysis/components.hpp"
#include "vola/builder.hpp"
#include "vola/error.hpp"
#include "vola/file.hpp"

namespace vola::cli {

namespace {

struct ComponentsArgs {
  std::string file;
  int connectivity = 26;
  std::uint64_t min_voxels = 1;
  std::uint64_t largest = 0;  // 0 = all
  std::size_t list = 20;
  std::string split_dir, labels_out;
  bool per_class = false;
  bool json = false;
  bool overwrite = false;  // --split: remove an earlier run's component files first
};

// Components that pass the filters: a prefix of the size-sorted list.
std::size_t kept_count(const analysis::ComponentLabels& r, const ComponentsArgs& a) {
  std::size_t n = 0;
  while (n < r.components.size() && r.components[n].voxels >= a.min_voxels && (a.largest == 0 || n < a.largest)) ++n;
  return n;
}

Tree with_georef_of(Tree t, const Tree& source) {
  t.georef() = source.georef();
  if (source.stored_frame()) t.set_frame(*source.stored_frame());
  return t;
}

// An earlier run's component_NNNNNN.vol files would mix with this run's (a run keeping
// fewer components left the rest behind): refused, or removed with --overwrite.
void clear_or_refuse_split(const std::string& dir, bool overwrite) {
  std::error_code ec;
  if (!std::filesystem::is_directory(dir, ec)) return;
  std::vector<std::filesystem::path> earlier;
  for (const auto& entry : std::filesystem::directory_iterator(dir)) {
    const std::string name = entry.path().filename().string();
    if (name.rfind("component_", 0) == 0 && entry.path().extension() == ".vol") earlier.push_back(entry.path());
  }
  if (earlier.empty()) return;
  if (!overwrite)
    throw InvalidArgument(dir + " holds " + std::to_string(earlier.size()) +
                          " component files of an earlier run, which would mix with this run's: give an empty "
                          "folder, or --overwrite to remove them first");
  for (const auto& path : earlier) std::filesystem::remove(path);
}

void write_split(const Tree& tree, const analysis::ComponentLabels& r, std::size_t kept, const std::string& dir) {
  std::filesystem::create_directories(dir);
  std::vector<std::vector<Key>> keys(kept);
  const std::vector<Key> all = tree.keys();
  for (std::size_t i = 0; i < all.size(); ++i)
    if (r.label[i] < kept) keys[r.label[i]].push_back(all[i]);
  for (std::size_t id = 0; id < kept; ++id) {
    char name[48];
    std::snprintf(name, sizeof name, "component_%06zu.vol", id);
    write(with_georef_of(build_from_sorted_keys(keys[id], tree.depth()), tree), (std::filesystem::path(dir) / name).string());
  }
}

// Each voxel's component, the `kept` ones by their number and the rest (filtered out by
// --min-voxels or --largest) as kNotKept, as --split leaves them out.
constexpr std::uint32_t kNotKept = 4294967295u;

void write_labels(const Tree& tree, const analysis::ComponentLabels& r, std::size_t kept, const std::string& path) {
  Tree labelled = tree;
  if (labelled.attributes().find("component"))
    throw InvalidArgument("the file already has a 'component' column");
  AttributeColumn column("component", ValueType::u32, Reduction::majority, r.label.size());
  for (std::size_t i = 0; i < r.label.size(); ++i) column.set(i, r.label[i] < kept ? r.label[i] : kNotKept);
  labelled.attributes().add(std::move(column));
  write(labelled, path);
}

void per_class(const Tree& tree, const ComponentsArgs& a, analysis::Connectivity c) {
  const AttributeColumn* cls = tree.attributes().find("classification");
  if (!cls) throw InvalidArgument(a.file + " has no classification column");
  std::map<int, std::vector<Key>> keys;
  const std::vector<Key> all = tree.keys();
  for (std::size_t i = 0; i < all.size(); ++i) keys[static_cast<int>(cls->get(i))].push_back(all[i]);
  nlohmann::json j = nlohmann::json::array();
  if (!a.json) std::printf("%5s %-38s %12s %11s %12s\n", "class", "name", "voxels", "components", "largest");
  for (const auto& [code, k] : keys) {
    const auto r = analysis::label_components(build_from_sorted_keys(k, tree.depth()), c);
    const std::size_t kept = kept_count(r, a);
    const std::uint64_t largest = r.components.empty() ? 0 : r.components[0].voxels;
    const std::string name(analysis::asprs_class_name(code));
    if (a.json)
      j.push_back({{"code", code}, {"name", name}, {"voxels", k.size()}, {"components", kept}, {"largest", largest}});
    else
      std::printf("%5d %-38s %12zu %11zu %12llu\n", code, name.c_str(), k.size(), kept,
                  static_cast<unsigned long long>(largest));
  }
  if (a.json) std::printf("%s\n", j.dump(2, ' ', false, nlohmann::json::error_handler_t::replace).c_str());
}

void run_components(const ComponentsArgs& a) {
  refuse_outputs_over_inputs({a.file}, {a.labels_out}, "vola components --labels");
  const Tree tree = open_voxels(a.file);
  const analysis::Connectivity c = analysis::parse_connectivity(a.connectivity);
  if (a.per_class) return per_class(tree, a, c);
  const analysis::ComponentLabels r = analysis::label_components(tree, c);
  const std::size_t kept = kept_count(r, a);
  const Frame frame = tree.frame();
  auto world = [&](double v, int axis) { return frame.origin[axis] + (v + 0.5) * frame.voxel_size; };
  if (a.json) {
    nlohmann::json j{{"file", a.file}, {"connectivity", a.connectivity}, {"voxels", tree.voxel_count()},
                     {"components", r.components.size()}, {"kept", kept}, {"list", nlohmann::json::array()}};
    for (std::size_t i = 0; i < kept && i < a.list; ++i) {
      const auto& k = r.components[i];
      j["list"].push_back({{"id", i}, {"voxels", k.voxels}, {"min", {k.min.x, k.min.y, k.min.z}},
                           {"max", {k.max.x, k.max.y, k.max.z}},
                           {"centroid", {k.centroid[0], k.centroid[1], k.centroid[2]}},
                           {"centroid_world", {world(k.centroid[0], 0), world(k.centroid[1], 1), world(k.centroid[2], 2)}}});
    }
    std::printf("%s\n", j.dump(2, ' ', false, nlohmann::json::error_handler_t::replace).c_str());
  } else {
    std::printf("%s: %llu voxels, %zu components (%d-connected), %zu kept\n", a.file.c_str(),
                static_cast<unsigned long long>(tree.voxel_count()), r.components.size(), a.connectivity, kept);
    if (kept && a.list) std::printf("%6s %12s  %-26s %-26s %s\n", "id", "voxels", "min (voxel)", "max (voxel)", "centroid (world)");
    for (std::size_t i = 0; i < kept && i < a.list; ++i) {
      const auto& k = r.components[i];
      char lo[40], hi[40];
      std::snprintf(lo, sizeof lo, "%u,%u,%u", k.min.x, k.min.y, k.min.z);
      std::snprintf(hi, sizeof hi, "%u,%u,%u", k.max.x, k.max.y, k.max.z);
      std::printf("%6zu %12llu  %-26s %-26s %.9g,%.9g,%.9g\n", i, static_cast<unsigned long long>(k.voxels), lo, hi,
                  world(k.centroid[0], 0), world(k.centroid[1], 1), world(k.centroid[2], 2));
    }
    if (kept > a.list) std::printf("... %zu more (--list N)\n", kept - a.list);
  }
  if (!a.split_dir.empty()) {
    clear_or_refuse_split(a.split_dir, a.overwrite);
    write_split(tree, r, kept, a.split_dir);
  }
  if (!a.labels_out.empty()) write_labels(tree, r, kept, a.labels_out);  // its input refused before the work
}

}  // namespace

void add_components(CLI::App& app) {
  auto args = std::make_shared<ComponentsArgs>();
  auto* cmd = app.add_subcommand("components", "Connected components: sizes, boxes, centroids; split or label them");
  cmd->footer(
      "Components are numbered largest first. --split writes component_NNNNNN.vol per kept\n"
      "component (occupancy only, same grid); --labels writes the input with a u32 'component'\n"
      "column (4294967295 for the voxels of components --min-voxels or --largest leave out). Example: vola components scan.vol --connectivity 26 --min-voxels 50 --split parts/");
  cmd->add_option("file", args->file, "Input .vol")->required()->check(CLI::ExistingFile);
  cmd->add_option("--connectivity", args->connectivity, "6 (faces), 18 (edges) or 26 (corners)")
      ->check(CLI::IsMember({6, 18, 26}));
  cmd->add_option("--min-voxels", args->min_voxels, "Keep components of at least N voxels");
  cmd->add_option("--largest", args->largest, "Keep only the N largest components (0 = all)");
  cmd->add_option("--list", args->list, "Rows to print");
  cmd->add_option("--split", args->split_dir, "Write each kept component as its own .vol into this folder");
  cmd->add_flag("--overwrite", args->overwrite,
                "--split: remove the component_*.vol files an earlier run left in the folder (refused otherwise)");
  cmd->add_option("--labels", args->labels_out, "Write the input with a 'component' attribute column");
  cmd->add_flag("--per-class", args->per_class, "Components per classification code (needs a classification column)");
  cmd->add_flag("--json", args->json, "Print JSON");
  cmd->callback([args] { run_components(*args); });
}

}  // namespace vola::cli
