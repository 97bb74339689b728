// Brute-force twins of the analysis operations over std::set voxel models, and the
// random grids they are compared on.
#pragma once

#include <cstdint>
#include <map>
#include <random>
#include <vector>

#include "test_support.hpp"
#include "vola/analysis/components.hpp"
#include "vola/analysis/morphology.hpp"

namespace vola_analysis_test {

using vola_test::Xyz;
using vola_test::XyzSet;

struct Grid {
  int depth = 1;
  XyzSet voxels;
  std::string name;
};

// Every cell kept with probability p (dense grids: depth <= 3).
XyzSet bernoulli(std::mt19937_64& rng, int depth, double p);
// Dense grids at depths 1..3 over several fill ratios, plus sparse clustered and
// uniform sets at depths 4 and 6..8.
std::vector<Grid> random_grids(std::uint64_t seed);

vola::Tree tree_of(const XyzSet& voxels, int depth);

// Breadth-first components; returns one label per voxel of `voxels` (map order).
std::map<Xyz, int> model_components(const XyzSet& voxels, int connectivity);
std::vector<std::array<int, 3>> element_offsets(int radius, vola::analysis::Element element);
XyzSet model_dilate(const XyzSet& voxels, int depth, int radius, vola::analysis::Element element);
XyzSet model_erode(const XyzSet& voxels, int depth, int radius, vola::analysis::Element element);
// Flood of the face-connected outside through a dense box around the voxels.
XyzSet model_fill(const XyzSet& voxels);

}  // namespace vola_analysis_test
