#include "octomap_agreement.hpp"

#include <cmath>
#include <cstdio>

namespace vola_map_test {

namespace {

constexpr int kOctoMapDepth = 16;
constexpr std::int32_t kKeyOffset = 32768;

}  // namespace

octomap::OcTreeKey octomap_key(const vola::map::VoxelIndex& v) {
  return octomap::OcTreeKey(static_cast<octomap::key_type>(v.i + kKeyOffset),
                            static_cast<octomap::key_type>(v.j + kKeyOffset),
                            static_cast<octomap::key_type>(v.k + kKeyOffset));
}

double Agreement::decision_fraction() const {
  const std::uint64_t either = both + only_vola + only_octomap;
  return either == 0 ? 1.0 : static_cast<double>(same_decision) / static_cast<double>(either);
}

std::string Agreement::summary() const {
  char text[400];
  std::snprintf(text, sizeof text,
                "vola %llu voxels, OctoMap %llu; both %llu, only vola %llu, only OctoMap %llu; same log-odds %llu, "
                "same decision %llu (%.4f%% of voxels known to either)",
                static_cast<unsigned long long>(vola_voxels), static_cast<unsigned long long>(octomap_voxels),
                static_cast<unsigned long long>(both), static_cast<unsigned long long>(only_vola),
                static_cast<unsigned long long>(only_octomap), static_cast<unsigned long long>(same_log_odds),
                static_cast<unsigned long long>(same_decision), 100.0 * decision_fraction());
  return text;
}

Agreement compare(const vola::map::OccupancyMap& map, const octomap::OcTree& tree) {
  Agreement a;
  for (const auto& [v, value] : map.voxels()) {
    ++a.vola_voxels;
    // search() at full depth finds a pruned leaf's ancestor, which holds the leaf's value.
    const octomap::OcTreeNode* node = tree.search(octomap_key(v));
    if (!node) {
      ++a.only_vola;
      continue;
    }
    ++a.both;
    if (std::abs(node->getLogOdds() - value) <= 1e-5f) ++a.same_log_odds;
    if (tree.isNodeOccupied(node) == map.occupied(value)) ++a.same_decision;
  }
  // OctoMap's voxels vola does not know: expand pruned leaves to finest voxels.
  for (auto it = tree.begin_leafs(), end = tree.end_leafs(); it != end; ++it) {
    const octomap::OcTreeKey base = it.getKey();
    const int side = 1 << (kOctoMapDepth - static_cast<int>(it.getDepth()));
    // A leaf at depth d covers keys base & ~(side - 1) .. + side - 1.
    const int mask = ~(side - 1);
    for (int dz = 0; dz < side; ++dz)
      for (int dy = 0; dy < side; ++dy)
        for (int dx = 0; dx < side; ++dx) {
          ++a.octomap_voxels;
          const vola::map::VoxelIndex v{(base[0] & mask) + dx - kKeyOffset, (base[1] & mask) + dy - kKeyOffset,
                                        (base[2] & mask) + dz - kKeyOffset};
          if (!map.log_odds(v)) ++a.only_octomap;
        }
  }
  return a;
}

}  // namespace vola_map_test
