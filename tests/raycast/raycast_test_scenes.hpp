// Scenes and rays shared by the raycast tests: random trees, the converted Autzen
// survey, and random rays mixed with the edge cases (axis-aligned rays, rays through
// edges and corners, rays starting inside occupied voxels or outside the grid).
#pragma once

#include <optional>
#include <random>
#include <string>
#include <vector>

#include "vola/raycast/ray.hpp"
#include "vola/tree.hpp"

namespace raycast_test {

// A random tree of `depth` from a seed: uniform noise, clusters or slabs.
vola::Tree random_tree(std::uint64_t seed, int depth);
// A LAS file of the shared data (las/FILE_NAME) built at `depth` (grid quantization);
// nullopt when the shared data folder is missing.
std::optional<vola::Tree> autzen_tree(const std::string& file_name, int depth);
// `count` rays for a tree of side `side`, a quarter of each kind: random, axis-aligned
// and integer-aligned (through edges and corners), from inside occupied voxels.
std::vector<vola::raycast::Ray> mixed_rays(const vola::Tree& tree, std::size_t count, std::mt19937_64& rng);

}  // namespace raycast_test
