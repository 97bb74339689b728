// Entwine Point Tiles (EPT 1.0, https://entwine.io/entwine-point-tile.html): a folder
// holding ept.json (bounds, schema, CRS, data type), an octree of point counts in
// ept-hierarchy/*.json and one data file per node in ept-data/. Read from a local copy:
// dataType "laszip" (each node a LAZ file, through vola's LAS/LAZ reader) and "binary"
// (each node the schema's records back to back); "zstandard" is refused with what to do.
#pragma once

#include <array>
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "vola/io/input.hpp"

namespace vola::io {

// One node of the octree with points: its key "D-X-Y-Z", its depth D, its place X, Y, Z
// among the 2^D cubes along each axis and the count the hierarchy states.
struct EptNode {
  std::string key;
  int depth = 0;
  std::array<std::uint64_t, 3> place{0, 0, 0};
  std::uint64_t points = 0;
};

// What ept.json says of the dataset.
struct EptDataset {
  std::string version;    // "1.0.0", or empty when not stated
  std::string data_type;  // laszip, binary or zstandard
  std::uint64_t points = 0;
  std::array<double, 6> bounds{};                   // the octree's cube: min x y z, max x y z
  std::optional<std::array<double, 6>> conforming;  // the points' own bounds, when stated
  std::vector<std::string> dimensions;              // the schema's names, in order
  std::string wkt;                                  // srs.wkt
  std::optional<std::uint32_t> epsg;                // srs.horizontal when srs.authority is EPSG
};
// Throws FormatError naming the file when it is no EPT ept.json.
EptDataset ept_dataset(const std::string& ept_json);

// The nodes with points, by depth, then x, y, z. A subtree whose count is -1 is read
// from ept-hierarchy/KEY.json. Throws FormatError naming the file for a malformed key,
// a key met twice (a loop of subtree files), a count that is not an integer >= -1 or a
// total past ept.json's "points".
std::vector<EptNode> ept_nodes(const std::string& ept_json);

// The cube of `node` inside the dataset's (bounds cut in 2^depth along each axis): min
// x y z, max x y z. Entwine keeps every point of a node inside its cube.
std::array<double, 6> ept_node_bounds(const EptDataset& dataset, const EptNode& node);

// Every node's points in one cloud (attributes as the LAS reader names them; binary
// nodes' dimensions named as text columns are), the CRS from "srs"; with
// options.copc_level, only the nodes of depth 0..level (a coarser sample, as for COPC);
// with options.region, only the nodes whose cube meets it. Input::bytes_read counts the
// node files' bytes read, Input::bytes_total those of every node file.
// A node whose file holds another number of points than the hierarchy states is an error
// naming the file.
Input read_ept(const std::string& ept_json, const InputOptions& options);

}  // namespace vola::io
