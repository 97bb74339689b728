// Records the largest single heap allocation made while a probe is alive, through a
// replacement of the global operator new linked into the test executable. Used to show
// that a lying header cannot make the reader allocate what the file does not hold.
#pragma once

#include <cstddef>

namespace vola_test {

class LargestAllocation {
 public:
  LargestAllocation();
  ~LargestAllocation();
  LargestAllocation(const LargestAllocation&) = delete;
  LargestAllocation& operator=(const LargestAllocation&) = delete;
  // Largest request in bytes since construction.
  std::size_t bytes() const noexcept;
};

}  // namespace vola_test
