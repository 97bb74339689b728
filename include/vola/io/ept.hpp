// Entwine Point Tiles (EPT 1.0, https://entwine.io/entwine-point-tile.html): a folder
// holding ept.json (bounds, schema, CRS, data type), an octree of point counts in
// ept-hierarchy/*.json and one data file per node in ept-data/. Read from a local copy:
// dataType "laszip" (each node a LAZ file, through vola's LAS/LAZ reader) and "binary"
// (each node the schema's records back to back); "zstandard" is refused with what to do.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "vola/io/input.hpp"

namespace vola::io {

// One node of the octree with points: its key "D-X-Y-Z" and the count the hierarchy states.
struct EptNode {
  std::string key;
  std::uint64_t points = 0;
};

// The nodes with points, by depth, then x, y, z. A subtree whose count is -1 is read
// from ept-hierarchy/KEY.json. Throws FormatError naming the file for a malformed key,
// a key met twice (a loop of subtree files), a count that is not an integer >= -1 or a
// total past ept.json's "points".
std::vector<EptNode> ept_nodes(const std::string& ept_json);

// Every node's points in one cloud (attributes as the LAS reader names them; binary
// nodes' dimensions named as text columns are), the CRS from "srs". A node whose file
// holds another number of points than the hierarchy states is an error naming the file.
Input read_ept(const std::string& ept_json, const InputOptions& options);

}  // namespace vola::io
