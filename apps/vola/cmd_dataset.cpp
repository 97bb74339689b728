// vola dataset: ModelNet-style classification data (.npz grids or mesh files) as 64^3
// VOLA files in DIR/<class>/ folders, clean or in generated rooms.
#include <cstdio>
#include <filesystem>
#include <random>
#include <string>
#include <vector>

#include "commands.hpp"
#include "progress.hpp"
#include "vola/error.hpp"
#include "vola/file.hpp"
#include "vola/learn/dataset.hpp"
#include "vola/learn/npz.hpp"
#include "vola/learn/segment.hpp"

namespace vola::cli {

namespace {

namespace fs = std::filesystem;

struct DatasetArgs {
  std::string input, output, split, class_name;
  bool background = false;
  bool segment = false;  // write the object `vola classify --segment` finds in each scene
  bool overwrite = false;  // remove the .vol files of the folders this run writes first
  double validation_fraction = 0.1;
  std::size_t validation_per_class = 0;  // > 0: a class-balanced split instead of the fraction
  std::uint64_t seed = 1;
};

// Each sample's room comes from (seed, sample index) alone.
std::mt19937_64 sample_random(std::uint64_t seed, std::size_t index) {
  std::seed_seq sequence{std::uint32_t(seed), std::uint32_t(seed >> 32), std::uint32_t(index),
                         std::uint32_t(std::uint64_t(index) >> 32)};
  return std::mt19937_64(sequence);
}

// Writes the sample; false (nothing written) when --segment finds no object in it.
bool write_sample(std::span<const std::uint8_t> grid, int side, const DatasetArgs& a, std::size_t index,
                  const fs::path& path) {
  std::mt19937_64 random = sample_random(a.seed, index);
  Tree tree = a.background ? learn::room_scene(grid, side, random) : learn::clean_scene(grid, side);
  if (a.segment) {
    const learn::Segmentation found = learn::segment_object(tree);
    if (!found.found()) return false;
    tree = learn::normalise_object(found.object, found.footprint_angle);
  }
  fs::create_directories(path.parent_path());
  write(tree, path.string());
  return true;
}

std::string sample_name(int label, std::size_t index) {
  char number[32];
  std::snprintf(number, sizeof number, "_%05zu.vol", index);
  return std::string(learn::kClassNames[std::size_t(label)]) + number;
}

// The .vol files under `folder` (any depth).
std::vector<fs::path> samples_in(const fs::path& folder) {
  std::vector<fs::path> found;
  std::error_code error;
  if (!fs::is_directory(folder, error)) return found;
  for (const auto& item : fs::recursive_directory_iterator(folder))
    if (item.is_regular_file() && item.path().extension() == ".vol") found.push_back(item.path());
  return found;
}

// A run writes only the samples of its own split and seed: files an earlier run left in
// the same folders (another seed, another validation size) would mix into them, and the
// same object could then be in train/ and val/ at once. So a folder with samples in it is
// refused, or emptied of them with --overwrite (other files stay).
void clear_or_refuse(const std::vector<fs::path>& folders, bool overwrite) {
  for (const fs::path& folder : folders) {
    const std::vector<fs::path> old = samples_in(folder);
    if (old.empty()) continue;
    if (!overwrite)
      throw InvalidArgument(folder.string() + " already holds " + std::to_string(old.size()) +
                            " samples (.vol) of an earlier run, which would mix with this one's (an object in " +
                            "train/ and val/ at once); give an empty folder, or --overwrite to remove them first");
    for (const fs::path& f : old) fs::remove(f);
  }
}

void run_npz(const DatasetArgs& a) {
  const learn::LabelledGrids grids = learn::read_labelled_grids(a.input, a.split);
  if (learn::kSceneSide % grids.side != 0)
    throw FormatError(a.input, std::nullopt, "grids of side " + std::to_string(grids.side) + ": expected a divisor of 64 (32, 16, ...)");
  // The training split gives up a stratified validation split; any other is written whole.
  const bool carve = grids.split == "train" && (a.validation_fraction > 0 || a.validation_per_class > 0);
  std::vector<char> held_out(grids.size(), 0);
  if (carve) {
    const learn::Split split = a.validation_per_class > 0
                                   ? learn::balanced_split(grids.labels, a.validation_per_class, a.seed)
                                   : learn::stratified_split(grids.labels, a.validation_fraction, a.seed);
    for (std::size_t i : split.validation) held_out[i] = 1;
  }
  const fs::path root(a.output);
  std::vector<fs::path> written{root / grids.split};
  if (carve) written.push_back(root / "val");
  clear_or_refuse(written, a.overwrite);
  std::vector<std::size_t> per_split[2];
  std::size_t not_found = 0;
  Progress progress("dataset");
  for (std::size_t i = 0; i < grids.size(); ++i) {
    const std::string split = held_out[i] ? "val" : grids.split;
    if (write_sample(grids.grid(i), grids.side, a, i,
                     root / split / std::string(learn::kClassNames[std::size_t(grids.labels[i])]) /
                         sample_name(grids.labels[i], i)))
      per_split[held_out[i] ? 1 : 0].push_back(i);
    else
      ++not_found;
    progress.update(i + 1, grids.size());
  }
  progress.finish();
  if (not_found) std::printf("%zu scenes without an object to segment were left out\n", not_found);
  std::printf("%zu %s samples -> %s\n", per_split[0].size(), grids.split.c_str(), (root / grids.split).string().c_str());
  if (carve && a.validation_per_class > 0)
    std::printf("%zu validation samples (%zu of each class, at most half of it, seed %llu) -> %s\n", per_split[1].size(),
                a.validation_per_class, static_cast<unsigned long long>(a.seed), (root / "val").string().c_str());
  else if (carve)
    std::printf("%zu validation samples (%.0f%% of each class, seed %llu) -> %s\n", per_split[1].size(),
                a.validation_fraction * 100, static_cast<unsigned long long>(a.seed), (root / "val").string().c_str());
  std::printf("%s%s, 64^3 at depth 3\n", a.background ? "objects in generated rooms" : "clean objects",
              a.segment ? ", segmented and normalised as vola classify --segment does" : "");
}

void run_meshes(const DatasetArgs& a) {
  std::vector<fs::path> files;
  if (fs::is_directory(a.input)) {
    for (const auto& item : fs::directory_iterator(a.input))
      if (item.is_regular_file()) files.push_back(item.path());
    std::sort(files.begin(), files.end());
  } else {
    files.emplace_back(a.input);
  }
  if (files.empty()) throw InvalidArgument(a.input + ": no mesh files");
  std::optional<int> fixed;
  if (!a.class_name.empty()) {
    fixed = learn::class_index(a.class_name);
    if (!fixed) throw InvalidArgument("--class " + a.class_name + " is not a ModelNet10 class");
  }
  for (std::size_t i = 0; i < files.size(); ++i) {
    const auto label = fixed ? fixed : learn::class_from_file_name(files[i].filename().string());
    if (!label)
      throw InvalidArgument(files[i].string() + ": no class name in the file name; give --class NAME");
    const std::vector<std::uint8_t> grid = learn::mesh_object_grid(files[i].string(), learn::kObjectSide);
    const fs::path out = fs::path(a.output) / std::string(learn::kClassNames[std::size_t(*label)]) /
                         (files[i].stem().string() + ".vol");
    if (write_sample(grid, learn::kObjectSide, a, i, out))
      std::printf("%s -> %s\n", files[i].string().c_str(), out.string().c_str());
    else
      std::printf("%s: no object found to segment, left out\n", files[i].string().c_str());
  }
}

void run_dataset(const DatasetArgs& a) {
  if (fs::path(a.input).extension() == ".npz")
    run_npz(a);
  else
    run_meshes(a);
}

}  // namespace

void add_dataset(CLI::App& app) {
  auto args = std::make_shared<DatasetArgs>();
  auto* cmd = app.add_subcommand("dataset", kDatasetSummary);
  cmd->footer(
      "INPUT is an .npz holding X_<split> (N,S,S,S) 0/1 grids (S = 32, 16, ...) and y_<split> labels 0-9\n"
      "(bathtub bed chair desk dresser monitor night_stand sofa table toilet), or a mesh file (OFF, OBJ,\n"
      "STL, ...) or a folder of them, voxelized solid at 32^3 like the npz grids (z up, centred).\n"
      "Each object becomes a 64^3 tree of depth 3: clean (each cell a 2x2x2 block), or with --background\n"
      "at 5/4 size, turned by a random angle about z and put on the floor of a room with two walls\n"
      "and random boxes of clutter (the paper's objects with background). With --segment, each scene\n"
      "gives the object vola classify --segment finds in it, normalised as that option classifies it\n"
      "(data to train a model for --segment on; scenes where nothing is found are left out).\n"
      "Layout: OUTDIR/<split>/<class>/<class>_<row>.vol for an npz; the train split gives up a\n"
      "stratified, seeded validation split in OUTDIR/val/ (10% of each class, or N of each with\n"
      "--validation-per-class N). Meshes: OUTDIR/<class>/<file name>.vol, the\n"
      "class from --class or from a class name in the file name (files of earlier runs stay: a folder\n"
      "of meshes can be added to). For an npz, a split folder this run writes (train/ and val/, or\n"
      "test/) that already holds samples is refused: they would mix with this run's (--overwrite\n"
      "removes them first; the other splits' folders are left alone).\n"
      "Examples:\n"
      "  vola dataset modelnet10_32_train.npz data/clean                  # data/clean/train, data/clean/val\n"
      "  vola dataset modelnet10_32_train.npz data/room --background\n"
      "  vola dataset modelnet10_32_train.npz data/room-seg --background --segment   # for --segment models\n"
      "  vola dataset modelnet10_32_test.npz data/clean                   # data/clean/test\n"
      "  vola dataset meshes/ data/meshes                                 # bathtub_0001.off -> data/meshes/bathtub/");
  cmd->add_option("input", args->input, ".npz, mesh file or folder of mesh files")->required()->check(CLI::ExistingPath);
  cmd->add_option("outdir", args->output, "Output folder")->required();
  cmd->add_flag("--background", args->background, "Place each object in a generated room");
  cmd->add_flag("--segment", args->segment,
                "Write the object found in each scene (floor and walls removed), normalised as "
                "vola classify --segment gives it to the model");
  cmd->add_option("--split", args->split, "npz: which X_<split>/y_<split> (default: the only one)");
  cmd->add_option("--validation-fraction", args->validation_fraction,
                  "npz train split: the part of each class held out in val/")
      ->capture_default_str()
      ->check(CLI::Range(0.0, 0.9));
  cmd->add_option("--validation-per-class", args->validation_per_class,
                  "npz train split: hold out N of each class instead (at most half of a class; 0: use the fraction)")
      ->capture_default_str()
      ->check(CLI::Range(0, 100000));
  cmd->add_option("--seed", args->seed, "Seed of the validation split and the rooms")->capture_default_str();
  cmd->add_option("--class", args->class_name, "Meshes: the class of every file");
  cmd->add_flag("--overwrite", args->overwrite,
                "npz: remove the samples an earlier run left in the split folders this run writes, instead of "
                "refusing");
  cmd->callback([args] { run_dataset(*args); });
}

}  // namespace vola::cli
