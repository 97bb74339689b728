// COPC (Cloud Optimized Point Cloud 1.0): a LAZ 1.4 file whose chunks are the nodes of
// an octree, described by the "copc" info VLR (record 1) and a hierarchy of pages
// (EVLR "copc" 1000). Reading the hierarchy lets a reader decode only the nodes a query
// needs: those meeting a box, down to a level of detail.
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "vola/frame.hpp"
#include "vola/io/laz.hpp"

namespace vola::io {

struct LasHeader;

struct CopcInfo {
  Point center{};
  double halfsize = 0.0;  // the root cube: center +- halfsize on each axis
  double spacing = 0.0;   // between points at the root; halves at each level
  std::uint64_t root_page_offset = 0, root_page_size = 0;
  double gps_time_min = 0.0, gps_time_max = 0.0;
};

struct CopcNode {
  std::int32_t level = 0, x = 0, y = 0, z = 0;  // the EPT voxel key
  std::uint64_t offset = 0;                     // the node's LAZ chunk
  std::uint64_t byte_size = 0;
  std::uint64_t point_count = 0;
};

struct CopcHierarchy {
  CopcInfo info;
  std::vector<CopcNode> nodes;  // the nodes that hold points, in page order
  std::size_t pages = 0;
  int levels = 0;               // deepest level + 1
  // The node's cube in the file's coordinates.
  Box bounds(const CopcNode& node) const noexcept;
};

// The hierarchy of a COPC file, nothing when the header has no "copc" info VLR. Pages are
// read with `read_at` and checked against the file: inside it, a whole number of 32-byte
// entries, each page visited once (a loop is an error), data nodes inside the point data
// and on the chunk table. Throws FormatError (file, offset, what) otherwise.
std::optional<CopcHierarchy> read_copc_hierarchy(const LasHeader& header, const laz::ReadAt& read_at,
                                                 std::uint64_t file_size, const std::string& source);

}  // namespace vola::io
