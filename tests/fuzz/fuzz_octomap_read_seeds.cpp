// Seeds for fuzz_octomap_read: OcTrees written by liboctomap itself as .bt and .ot (scattered
// occupied and free cells, a pruned 4^3 octant, cells at both ends of the key range, an
// empty tree). No shared file holds an OctoMap, so golden_seeds adds none. Linked into
// fuzz_octomap_read_replay in place of fuzz_seeds.cpp.
#include <octomap/OcTree.h>

#include <sstream>

#include "fuzz_seeds.hpp"

namespace vola_fuzz {

namespace {

Seed seed_of(const std::string& name, const std::string& text) {
  return {name, std::vector<std::uint8_t>(text.begin(), text.end())};
}

octomap::OcTree sample_tree(double resolution) {
  octomap::OcTree tree(resolution);
  for (octomap::key_type x = 32768; x < 32772; ++x)
    for (octomap::key_type y = 32768; y < 32772; ++y)
      for (octomap::key_type z = 32768; z < 32772; ++z) tree.updateNode(octomap::OcTreeKey(x, y, z), true);
  for (int n = 0; n < 40; ++n) {
    const auto k = static_cast<octomap::key_type>(32700 + 7 * n);
    tree.updateNode(octomap::OcTreeKey(k, static_cast<octomap::key_type>(k - 3 * n), 32760), n % 3 != 0);
  }
  tree.updateNode(octomap::OcTreeKey(0, 0, 0), true);
  tree.updateNode(octomap::OcTreeKey(65535, 65535, 65535), false);
  return tree;
}

}  // namespace

std::vector<Seed> synthetic_seeds() {
  std::vector<Seed> seeds;
  for (double resolution : {0.1, 2.5}) {
    octomap::OcTree tree = sample_tree(resolution);
    std::ostringstream ot, bt;
    tree.write(ot);  // before writeBinary, which turns the tree into maximum likelihood
    tree.writeBinary(bt);
    const std::string tag = resolution < 1 ? "fine" : "coarse";
    seeds.push_back(seed_of(tag + ".ot", ot.str()));
    seeds.push_back(seed_of(tag + ".bt", bt.str()));
  }
  octomap::OcTree empty(0.2);
  std::ostringstream empty_ot, empty_bt;
  empty.write(empty_ot);
  empty.writeBinary(empty_bt);
  seeds.push_back(seed_of("empty.ot", empty_ot.str()));
  seeds.push_back(seed_of("empty.bt", empty_bt.str()));
  return seeds;
}

std::vector<Seed> golden_seeds(const std::filesystem::path&) { return {}; }

}  // namespace vola_fuzz
