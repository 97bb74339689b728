// Helpers of the vola_learn tests: .npz archives written through libzip, small labelled
// object grids, and the paths of the committed model.
#pragma once

#include <cstdint>
#include <string>
#include <utility>
#include <vector>

#include "io_test_data.hpp"
#include "vola/learn/classifier.hpp"

namespace vola_learn_test {

using vola_io_test::Bytes;

// Writes an .npz (deflated members) holding `members` as name.npy.
void write_npz(const std::string& path, const std::vector<std::pair<std::string, Bytes>>& members);

// N grids of side^3 uint8 cells as an npy of shape (N, side, side, side).
Bytes grids_npy(const std::vector<std::vector<std::uint8_t>>& grids, int side, const std::string& dtype = "|u1");
Bytes labels_npy(const std::vector<std::int64_t>& labels);

// A 32^3 grid of one of ten simple shapes (one per class, told apart by form and
// height), with a small random jitter of position from `seed`.
std::vector<std::uint8_t> shape_grid(int shape, std::uint64_t seed);

// The committed small model (the source tree's models/ folder).
std::string committed_model_path();

}  // namespace vola_learn_test
