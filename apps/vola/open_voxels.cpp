#include "open_voxels.hpp"

#include <cstdio>

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

Tree open_voxels_to_write(const std::string& path, const std::string& command) {
  Tree tree = open_mapped(path);
  if (!map::is_state_map(tree)) return tree;
  std::fprintf(stderr,
               "vola: warning: %s is a state map (occupied, free and unknown space): %s writes its occupied voxels "
               "only, as a plain tree, in which unknown space reads as free (vola plan and collide then take it for "
               "free space)\n",
               path.c_str(), command.c_str());
  Tree occupied = map::occupied_tree(tree);
  check_mapped(tree);
  return occupied;
}

}  // namespace vola::cli
