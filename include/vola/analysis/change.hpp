// Change between two surveys of the same grid: A = before, B = after.
#pragma once

#include <cstdint>

#include "vola/tree.hpp"

namespace vola::analysis {

struct ChangeCounts {
  std::uint64_t added = 0;      // in B, not in A
  std::uint64_t removed = 0;    // in A, not in B
  std::uint64_t unchanged = 0;  // in both
};

// One merge of the two sorted key lists; depths must match (InvalidArgument).
// Frames are the caller's concern (vola::subtract checks them for the sets).
ChangeCounts count_changes(const Tree& before, const Tree& after);

}  // namespace vola::analysis
