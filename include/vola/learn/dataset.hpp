// Classification datasets as VOLA files: ModelNet10 class names, 32^3 object grids
// (from an .npz or a voxelized mesh) turned into 64^3 trees of depth 3, clean or placed
// in a generated room, a stratified validation split, and the on-disk layout
// DIR/<class name>/<id>.vol that training and evaluation read back.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <optional>
#include <random>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "vola/tree.hpp"

namespace vola::learn {

inline constexpr int kClassCount = 10;
// ModelNet10 in the standard (alphabetical) label order 0..9.
inline constexpr std::array<std::string_view, kClassCount> kClassNames = {
    "bathtub", "bed", "chair", "desk", "dresser", "monitor", "night_stand", "sofa", "table", "toilet"};
std::optional<int> class_index(std::string_view name) noexcept;

// Side of the object grids (the npz's S) and of the dataset trees (depth 3).
inline constexpr int kObjectSide = 32;
inline constexpr int kSceneDepth = 3;
inline constexpr int kSceneSide = 64;

// A clean sample: the side^3 object grid (any side dividing 64) scaled up to fill the
// 64^3 grid, each cell becoming a (64/side)^3 block. Throws InvalidArgument when the
// grid is not side^3 cells or 64 is not a multiple of side.
Tree clean_scene(std::span<const std::uint8_t> grid, int side);

// "Objects with background": the object at 3/2 of its grid size, turned by a random
// angle about the vertical (z) axis, standing at a random place on the floor of a
// 64^3 room with a floor (z = 0), two walls (x = 0 and y = 0) and a few random boxes
// of clutter that do not touch the object. Deterministic for a given generator state.
Tree room_scene(std::span<const std::uint8_t> grid, int side, std::mt19937_64& random);

// Indices of a stratified split: per class, round(count * fraction) samples (at least
// one when the class has two or more) go to `validation`, chosen by a generator seeded
// with `seed`; the rest, in index order, to `train`.
struct Split {
  std::vector<std::size_t> train, validation;
};
Split stratified_split(std::span<const int> labels, double validation_fraction, std::uint64_t seed);
// A class-balanced split: per class min(per_class, half the class) samples go to
// `validation` (the half keeps a small class trainable), chosen as stratified_split
// chooses them (same generator use, so the same seed shuffles alike).
Split balanced_split(std::span<const int> labels, std::size_t per_class, std::uint64_t seed);

// A mesh file (OFF, OBJ, STL, anything vola's mesh reader reads) as a solid side^3 grid
// in the npz's convention: z up, the longest extent spanning the grid, centred.
// Throws FormatError when the file holds no usable triangles.
std::vector<std::uint8_t> mesh_object_grid(const std::string& path, int side = kObjectSide);

// One labelled .vol file of a dataset folder.
struct DatasetEntry {
  std::string path;
  int label = 0;
};
// Every DIR/<class name>/*.vol, sorted by class then file name. Folders that are not a
// class name are an error (a typo would otherwise drop a class silently); so is an
// empty dataset.
std::vector<DatasetEntry> list_dataset(const std::string& dir);

// A class name in a file name: the class whose name appears in it as a whole word
// (separated by '_', '-', '.', or the ends), longest match first (night_stand before
// any shorter class); nullopt when none does.
std::optional<int> class_from_file_name(std::string_view file_name) noexcept;

}  // namespace vola::learn
