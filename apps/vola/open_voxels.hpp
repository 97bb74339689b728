// How the commands open a .vol whose voxels they work on (render, collide, plan, census,
// components, export, voxels, coords, lod, set operations, morphology, sonify, ...): a
// state map (vola map, vola/map/state_map.hpp) is its occupied voxels, with their
// attribute rows; any other file is itself, memory-mapped.
#pragma once

#include <string>

#include "vola/tree.hpp"

namespace vola::cli {

Tree open_voxels(const std::string& path);

}  // namespace vola::cli
