// How the commands open a .vol whose voxels they work on (render, collide, plan, census,
// components, export, voxels, coords, lod, set operations, morphology, sonify, ...): a
// state map (vola map, vola/map/state_map.hpp) is its occupied voxels, with their
// attribute rows; any other file is itself, memory-mapped.
#pragma once

#include <string>

#include "vola/tree.hpp"

namespace vola::cli {

Tree open_voxels(const std::string& path);
// The same for a command that writes a new .vol of the voxels (lod, morphology, set
// operations): for a state map it warns (stderr, even with -q) that the output holds the
// occupied voxels only, so that its unknown space, then read as free, is not a surprise.
Tree open_voxels_to_write(const std::string& path, const std::string& command);

}  // namespace vola::cli
