// The structure of an OctoMap file, checked before liboctomap parses it. liboctomap reads
// the node stream recursively with no depth limit and no check of the stream's state: a
// truncated file leaves its child bits uninitialised, and a crafted one recurses until the
// stack overflows. This walk reads the header as AbstractOcTree::readHeader does and the
// node stream as readBinaryNode (.bt) and readNodesRecurs (.ot) do, refusing what they
// would misread, so that what reaches liboctomap parses exactly to the end of the file's
// nodes. It parses bytes, not a path, so that a fuzzer can call it.
#pragma once

#include <cstdint>
#include <string>
#include <string_view>

namespace vola::io {

struct OctomapLayout {
  bool binary = false;             // "# Octomap OcTree binary file" (.bt) or "# Octomap OcTree file" (.ot)
  std::string id;                  // the tree type the header names
  bool colour = false;             // a ColorOcTree: each .ot node holds r, g, b after its log-odds
  double resolution = 0.0;
  std::size_t data_offset = 0;     // where the node stream starts
  std::uint64_t nodes = 0;         // nodes in the stream, the root included (0: an empty tree)
  std::uint64_t occupied_cells = 0;  // occupied cells at the finest depth, pruned leaves expanded
};

// OctoMap's trees have 16 levels below the root: a leaf at depth d covers 2^(16 - d) cells
// of the resolution per axis.
inline constexpr int kOctomapDepth = 16;

// Throws FormatError naming `path` and the byte offset: an unknown first line (old binary
// files without it included), no `data` line, a resolution that is not finite and > 0 (or
// whose 65536 cells or inverse are not), an .ot tree type other than OcTree and
// ColorOcTree (its nodes hold other data), a node stream cut short or deeper than 16 levels, a non-finite
// log-odds, a .bt node count that differs from the header's size (liboctomap refuses it
// too), or more than `max_cells` occupied cells.
OctomapLayout check_octomap_bytes(std::string_view bytes, const std::string& path, std::uint64_t max_cells);

}  // namespace vola::io
