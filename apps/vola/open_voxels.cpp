#include "open_voxels.hpp"

#include "vola/file.hpp"
#include "vola/map/state_map.hpp"

namespace vola::cli {

Tree open_voxels(const std::string& path) {
  Tree tree = open_mapped(path);
  if (!map::is_state_map(tree)) return tree;
  Tree occupied = map::occupied_tree(tree);
  // The copy was read from the mapping: make sure the file was whole meanwhile.
  check_mapped(tree);
  return occupied;
}

}  // namespace vola::cli
