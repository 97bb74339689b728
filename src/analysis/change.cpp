#include <vector>

#include "vola/analysis/change.hpp"
#include "vola/error.hpp"

namespace vola::analysis {

ChangeCounts count_changes(const Tree& before, const Tree& after) {
  if (before.depth() != after.depth()) throw InvalidArgument("change: the two trees have different depths");
  const std::vector<Key> a = before.keys();
  const std::vector<Key> b = after.keys();
  ChangeCounts c;
  std::size_t i = 0, j = 0;
  while (i < a.size() && j < b.size()) {
    if (a[i] < b[j]) { ++c.removed; ++i; }
    else if (b[j] < a[i]) { ++c.added; ++j; }
    else { ++c.unchanged; ++i; ++j; }
  }
  c.removed += a.size() - i;
  c.added += b.size() - j;
  return c;
}

}  // namespace vola::analysis
