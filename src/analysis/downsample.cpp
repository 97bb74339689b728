// Keys sorted in storage order keep the voxels of one coarse cell together: the coarse
// key is a prefix, so one pass counts each run.
#include <string>
#include <vector>

#include "vola/analysis/downsample.hpp"
#include "vola/builder.hpp"
#include "vola/error.hpp"

namespace vola::analysis {

Tree downsample(const Tree& tree, int depth, std::uint64_t min_voxels) {
  if (depth < 1 || depth > tree.depth())
    throw InvalidArgument("downsample: depth " + std::to_string(depth) + " outside 1.." + std::to_string(tree.depth()));
  if (min_voxels < 1) throw InvalidArgument("downsample: the minimum voxel count must be at least 1");
  std::vector<Key> coarse;
  Key current = 0;
  std::uint64_t run = 0;
  tree.for_each_voxel([&](const Voxel& v) {
    const Key k = node_at(encode(v), depth - 1, tree.depth());
    if (run > 0 && k != current) {
      if (run >= min_voxels) coarse.push_back(current);
      run = 0;
    }
    current = k;
    ++run;
  });
  if (run >= min_voxels && run > 0) coarse.push_back(current);
  Tree out = build_from_sorted_keys(coarse, depth);
  const Tree lod = tree.level_of_detail(depth);  // the coarser frame and georef
  out.georef() = lod.georef();
  if (lod.stored_frame()) out.set_frame(*lod.stored_frame());
  return out;
}

}  // namespace vola::analysis
