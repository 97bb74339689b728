#include "octomap_check.hpp"

#include <cmath>
#include <cstring>
#include <istream>

#include "view_buffer.hpp"
#include "vola/error.hpp"

namespace vola::io {

namespace {

constexpr std::string_view kBinaryHeader = "# Octomap OcTree binary file";  // AbstractOccupancyOcTree::binaryFileHeader
constexpr std::string_view kTextHeader = "# Octomap OcTree file";           // AbstractOcTree::fileHeader

void skip_line(std::istream& s) {
  char c;
  do {
    c = static_cast<char>(s.get());
  } while (s.good() && c != '\n');
}

// AbstractOcTree::readHeader, token for token; returns false where it does.
bool read_header(std::istream& s, std::string& id, unsigned& size, double& resolution) {
  id.clear();
  size = 0;
  resolution = 0.0;
  std::string token;
  while (s.good()) {
    s >> token;
    if (token == "data") {
      skip_line(s);
      return true;
    }
    if (token == "id") s >> id;
    else if (token == "res") s >> resolution;
    else if (token == "size") s >> size;
    else skip_line(s);  // a comment ('#...') or a keyword liboctomap skips
  }
  return false;
}

class NodeWalk {
 public:
  NodeWalk(std::string_view bytes, std::size_t offset, const std::string& path, std::uint64_t max_cells, bool colour)
      : bytes_(bytes), at_(offset), path_(path), max_cells_(max_cells), node_data_(colour ? 7 : 4) {}

  // readBinaryNode: two bytes of 2-bit child codes, child i's code = bit 2i + 2 * bit 2i+1
  // of the little-endian 16 (1 free leaf, 2 occupied leaf, 3 inner node, 0 unknown), then
  // the inner children in order, depth first.
  void binary_node(int depth) {
    const std::size_t at = need(2, depth);
    const unsigned codes = static_cast<unsigned char>(bytes_[at]) | static_cast<unsigned>(static_cast<unsigned char>(bytes_[at + 1])) << 8;
    int inner = 0;
    for (int i = 0; i < 8; ++i) {
      const unsigned code = (codes >> (2 * i)) & 3u;
      if (code == 0) continue;
      ++nodes_;
      if (code == 2) add_occupied(depth + 1);
      if (code == 3) {
        if (depth + 1 >= kOctomapDepth) fail(at, "an inner node below OctoMap's 16 levels");
        ++inner;
      }
    }
    for (int n = 0; n < inner; ++n) binary_node(depth + 1);
  }

  // readNodesRecurs: the node's data (OcTreeNode: a float log-odds; ColorOcTreeNode: the
  // log-odds and three bytes r, g, b), one byte of child bits, the children.
  void text_node(int depth) {
    const std::size_t at = need(node_data_ + 1, depth);
    float value;
    std::memcpy(&value, bytes_.data() + at, sizeof value);
    if (!std::isfinite(value)) fail(at, "a log-odds that is not finite");
    const auto children = static_cast<unsigned char>(bytes_[at + node_data_]);
    ++nodes_;
    if (children == 0) {
      if (value >= 0.0f) add_occupied(depth);  // OcTree's default threshold: probability 0.5
      return;
    }
    if (depth >= kOctomapDepth) fail(at + node_data_, "children below OctoMap's 16 levels");
    for (int i = 0; i < 8; ++i)
      if (children & (1u << i)) text_node(depth + 1);
  }

  std::uint64_t nodes() const noexcept { return nodes_; }
  std::size_t offset() const noexcept { return at_; }
  std::uint64_t occupied() const noexcept { return occupied_; }
  std::size_t end() const noexcept { return at_; }
  [[noreturn]] void fail(std::size_t at, const std::string& why) const { throw FormatError(path_, at, why); }

 private:
  std::size_t need(std::size_t count, int depth) {
    if (bytes_.size() - at_ < count)
      fail(at_, "the node stream ends inside a node at depth " + std::to_string(depth) + " (a cut file?)");
    const std::size_t at = at_;
    at_ += count;
    return at;
  }
  void add_occupied(int depth) {
    const std::uint64_t cells = std::uint64_t{1} << (3 * (kOctomapDepth - depth));
    occupied_ += cells;
    if (occupied_ > max_cells_)
      fail(at_, "more than " + std::to_string(max_cells_) +
                    " occupied cells once pruned nodes are expanded to the resolution (vola's limit for a map)");
  }

  std::string_view bytes_;
  std::size_t at_;
  const std::string& path_;
  std::uint64_t max_cells_;
  std::size_t node_data_;
  std::uint64_t nodes_ = 0;
  std::uint64_t occupied_ = 0;
};

}  // namespace

OctomapLayout check_octomap_bytes(std::string_view bytes, const std::string& path, std::uint64_t max_cells) {
  OctomapLayout layout;
  const std::size_t first_line = std::min(bytes.find('\n'), bytes.size());
  const std::string_view first = bytes.substr(0, first_line);
  if (first.starts_with(kBinaryHeader)) {
    layout.binary = true;
  } else if (!first.starts_with(kTextHeader)) {
    throw FormatError(path, 0,
                      "not an OctoMap file: the first line is not '" + std::string(kBinaryHeader) + "' (.bt) or '" +
                          std::string(kTextHeader) +
                          "' (.ot); binary files from before OctoMap 1.4 need OctoMap's convert_octree first");
  }
  ViewBuffer buffer(bytes);
  std::istream s(&buffer);
  s.seekg(static_cast<std::streamoff>(std::min(first_line + 1, bytes.size())));
  unsigned size = 0;
  if (!read_header(s, layout.id, size, layout.resolution)) throw FormatError(path, std::nullopt, "no 'data' line ends the header");
  const auto data = s.tellg();
  layout.data_offset = data < 0 ? bytes.size() : static_cast<std::size_t>(data);
  if (layout.id.empty()) throw FormatError(path, std::nullopt, "the header names no tree type ('id')");
  if (layout.id == "1") layout.id = "OcTree";  // liboctomap's fix for an old id
  // The 65536 cells of an axis and the keys' scale (1 / res) must be finite numbers too.
  if (!(std::isfinite(layout.resolution) && layout.resolution > 0.0 && std::isfinite(layout.resolution * 65536.0) &&
        std::isfinite(1.0 / layout.resolution)))
    throw FormatError(path, std::nullopt, "the resolution ('res') is not a finite number > 0 whose 65536 cells are finite");
  if (!layout.binary && layout.id != "OcTree" && layout.id != "ColorOcTree")
    throw FormatError(path, std::nullopt,
                      "an .ot file of a " + layout.id +
                          ": vola reads OcTree and ColorOcTree maps (occupancy log-odds per node, and colour)");
  layout.colour = !layout.binary && layout.id == "ColorOcTree";

  NodeWalk walk(bytes, layout.data_offset, path, max_cells, layout.colour);
  if (layout.binary) {
    if (size == 0) return layout;  // readBinary reads no nodes then
    walk.binary_node(0);           // the root's children (the root itself is not coded)
    // A root with no children is a leaf spanning every key, which liboctomap reads as
    // occupied (its log-odds stay 0, the threshold): 2^48 cells, which vola went on to
    // list one by one.
    if (walk.nodes() == 0)
      walk.fail(layout.data_offset,
                "the root has no children: liboctomap reads it as one occupied leaf of 2^48 "
                "cells, more than " +
                    std::to_string(max_cells) + " (vola's limit for a map)");
    if (walk.nodes() + 1 != size)
      walk.fail(layout.data_offset, "the header says " + std::to_string(size) + " nodes, the stream holds " +
                                        std::to_string(walk.nodes() + 1));
    layout.nodes = walk.nodes() + 1;
  } else {
    // An empty OcTree is written as a header alone; readData would read a root anyway.
    if (layout.data_offset == bytes.size()) return layout;
    walk.text_node(0);
    layout.nodes = walk.nodes();
  }
  // liboctomap stops reading where the tree ends; bytes after it are another file's or
  // damage (a .bt given an .ot first line read as an empty map).
  if (walk.offset() != bytes.size())
    walk.fail(walk.offset(),
              std::to_string(bytes.size() - walk.offset()) +
                  " bytes follow the end of the tree (the header's kind or size does not match the data?)");
  layout.occupied_cells = walk.occupied();
  return layout;
}

}  // namespace vola::io
