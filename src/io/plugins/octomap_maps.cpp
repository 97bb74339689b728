// OctoMap .bt/.ot read and written through liboctomap (the octomap plugin). vola places the
// voxels (write_octomap decides the shift) and checks the file's structure first
// (octomap_check.hpp); liboctomap does the rest: keys, tree, pruning, the encodings.
#include <octomap/AbstractOcTree.h>
#include <octomap/ColorOcTree.h>
#include <octomap/OcTree.h>

#include <fcntl.h>
#include <unistd.h>

#include <algorithm>
#include <array>
#include <cstdio>
#include <fstream>
#include <iostream>
#include <iterator>
#include <memory>
#include <type_traits>

#include "../reader_plugin.hpp"
#include "node_census.hpp"
#include "octomap_check.hpp"
#include "readers.hpp"
#include "view_buffer.hpp"
#include "vola/error.hpp"

namespace vola::io {

namespace {

std::string read_whole(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw IoError("cannot open " + path);
  std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  if (in.bad()) throw IoError("cannot read " + path);
  return bytes;
}

std::uint32_t coordinate(const Voxel& v, int axis) { return axis == 0 ? v.x : axis == 1 ? v.y : v.z; }

// liboctomap as Debian builds it (without NDEBUG) reports progress while it reads and
// writes: on std::cerr, and with fprintf on stderr (" done." after every .bt). vola's
// errors are its own (what the calls return, the stream's state), so both are silenced
// around the calls; stderr by pointing descriptor 2 at /dev/null for their duration,
// which would hide another thread's message written at that moment too.
class QuietOctomap {
 public:
  QuietOctomap() : saved_cerr_(std::cerr.rdbuf(nullptr)) {
    std::fflush(stderr);
    saved_fd_ = ::dup(STDERR_FILENO);
    const int null = ::open("/dev/null", O_WRONLY | O_CLOEXEC);
    if (saved_fd_ >= 0 && null >= 0) ::dup2(null, STDERR_FILENO);
    if (null >= 0) ::close(null);
  }
  ~QuietOctomap() {
    std::fflush(stderr);
    if (saved_fd_ >= 0) {
      ::dup2(saved_fd_, STDERR_FILENO);
      ::close(saved_fd_);
    }
    std::cerr.rdbuf(saved_cerr_);
  }
  QuietOctomap(const QuietOctomap&) = delete;
  QuietOctomap& operator=(const QuietOctomap&) = delete;

 private:
  std::streambuf* saved_cerr_;
  int saved_fd_ = -1;
};

// The tree liboctomap reads: an OcTree from a .bt (readBinary) or an .ot of an OcTree, a
// ColorOcTree from an .ot of one (AbstractOcTree's factory knows both).
std::unique_ptr<octomap::AbstractOcTree> parse(const std::string& bytes, const OctomapLayout& layout,
                                               const std::string& path) {
  const QuietOctomap quiet;
  ViewBuffer buffer(bytes);
  std::istream in(&buffer);
  if (layout.binary) {
    auto tree = std::make_unique<octomap::OcTree>(layout.resolution);
    if (!tree->readBinary(in)) throw FormatError(path, std::nullopt, "liboctomap could not read the binary tree");
    return tree;
  }
  std::unique_ptr<octomap::AbstractOcTree> tree(octomap::AbstractOcTree::read(in));
  const bool expected = layout.colour ? dynamic_cast<octomap::ColorOcTree*>(tree.get()) != nullptr
                                      : dynamic_cast<octomap::OcTree*>(tree.get()) != nullptr;
  if (!expected) throw FormatError(path, std::nullopt, "liboctomap could not read an " + layout.id + " from it");
  return tree;
}

// liboctomap's nodes for these keys: a node per distinct cell of every depth 0..16, each
// an OcTreeNode and, above the leaves, an array of 8 child pointers (plus an allocation's
// overhead for each).
std::uint64_t octree_bytes(const std::vector<octomap::OcTreeKey>& keys) {
  std::vector<std::uint64_t> codes;
  codes.reserve(keys.size());
  for (const auto& k : keys) codes.push_back(morton_code(k[0], k[1], k[2]));
  std::vector<int> shifts(kOctomapDepth);
  for (int s = 0; s < kOctomapDepth; ++s) shifts[s] = s;
  const std::vector<std::uint64_t> cells = cells_per_shift(codes, shifts);
  constexpr std::uint64_t kOverhead = 16, kNode = sizeof(octomap::OcTreeNode) + kOverhead,
                          kChildren = 8 * sizeof(void*) + kOverhead;
  std::uint64_t bytes = kNode + kChildren;  // the root
  for (int s = 0; s < kOctomapDepth; ++s) bytes += cells[s] * (kNode + (s > 0 ? kChildren : 0));
  return bytes;
}

}  // namespace

namespace {

// The occupied leaves of `tree` (an OcTree or a ColorOcTree) as the grid's voxels, pruned
// leaves expanded to cells of the resolution; with `attributes`, an .ot's log-odds and a
// ColorOcTree's colour as columns, and an OcTree's free leaves as the grid's free cells
// (with their log-odds from an .ot) when there are at most kMaxMapVoxels of them.
template <class Tree>
void gather_cells(const Tree& tree, const OctomapLayout& layout, bool attributes, const std::string& path,
                  VoxelGrid& grid) {
  constexpr bool kColour = std::is_same_v<Tree, octomap::ColorOcTree>;
  // A leaf at depth d is a cube of 2^(16 - d) cells from its lowest key (getIndexKey).
  struct Bounds {
    std::array<unsigned, 3> low{65535, 65535, 65535}, high{0, 0, 0};
    void add(const octomap::OcTreeKey& key, unsigned span) {
      for (int a = 0; a < 3; ++a) {
        low[a] = std::min<unsigned>(low[a], key[a]);
        high[a] = std::max<unsigned>(high[a], key[a] + span - 1);
      }
    }
  } occupied_bounds, known_bounds;
  std::uint64_t free_cells = 0;
  for (auto it = tree.begin_leafs(), end = tree.end_leafs(); it != end; ++it) {
    const unsigned span = 1u << (kOctomapDepth - it.getDepth());
    known_bounds.add(it.getIndexKey(), span);
    if (tree.isNodeOccupied(*it))
      occupied_bounds.add(it.getIndexKey(), span);
    else
      free_cells += std::uint64_t{span} * span * span;
  }
  const bool keep_free = attributes && !kColour && free_cells <= kMaxMapVoxels;
  if (!keep_free) grid.free_cells_dropped = free_cells;
  if (!keep_free && layout.occupied_cells == 0) return;  // no cell to keep
  const auto& [low, high] = keep_free ? known_bounds : occupied_bounds;
  grid.voxels.reserve(layout.occupied_cells);
  std::vector<PointAttribute> columns;
  const bool keep_log_odds = attributes && !layout.binary;  // a .bt holds occupancy only
  if (keep_log_odds) columns.push_back({"log_odds", ValueType::f32, Reduction::last, {}});
  if (kColour && attributes)
    for (const char* name : {"red", "green", "blue"}) columns.push_back({name, ValueType::u8, Reduction::mean, {}});
  for (auto& column : columns) column.values.reserve(layout.occupied_cells);
  if (keep_free) {
    grid.free.reserve(free_cells);
    if (keep_log_odds) grid.free_log_odds.reserve(free_cells);
  }
  for (auto it = tree.begin_leafs(), end = tree.end_leafs(); it != end; ++it) {
    const bool occupied = tree.isNodeOccupied(*it);
    if (!occupied && !keep_free) continue;
    const octomap::OcTreeKey key = it.getIndexKey();
    const unsigned span = 1u << (kOctomapDepth - it.getDepth());
    const Voxel first{key[0] - low[0], key[1] - low[1], key[2] - low[2]};
    std::vector<Voxel>& cells_of_state = occupied ? grid.voxels : grid.free;
    for (unsigned z = 0; z < span; ++z)
      for (unsigned y = 0; y < span; ++y)
        for (unsigned x = 0; x < span; ++x) cells_of_state.push_back({first.x + x, first.y + y, first.z + z});
    const std::size_t cells = std::size_t{span} * span * span;
    if (!occupied) {
      if (keep_log_odds) grid.free_log_odds.insert(grid.free_log_odds.end(), cells, it->getLogOdds());
      continue;
    }
    if (keep_log_odds) columns[0].values.insert(columns[0].values.end(), cells, it->getLogOdds());
    if constexpr (kColour) {
      if (attributes) {
        const auto colour = it->getColor();
        const std::uint8_t channels[3] = {colour.r, colour.g, colour.b};
        for (std::size_t k = 0; k < 3; ++k) {
          auto& values = columns[(keep_log_odds ? 1 : 0) + k].values;
          values.insert(values.end(), cells, channels[k]);
        }
      }
    }
  }
  if (grid.voxels.size() != layout.occupied_cells)
    throw FormatError(path, std::nullopt,
                      "liboctomap read " + std::to_string(grid.voxels.size()) + " occupied cells where the stream codes " +
                          std::to_string(layout.occupied_cells));
  for (int a = 0; a < 3; ++a) {
    // Key k covers [(k - 32768) R, (k - 32767) R): the origin is a multiple of R.
    grid.origin[a] = (static_cast<double>(low[a]) - static_cast<double>(kOctomapKeyCentre)) * layout.resolution;
    grid.dims[a] = high[a] - low[a] + 1;
  }
  for (auto& column : columns) grid.attributes.push_back(std::move(column));
}

}  // namespace

VoxelGrid read_octomap_with_liboctomap(const std::string& path, bool attributes) {
  const std::string bytes = read_whole(path);
  const OctomapLayout layout = check_octomap_bytes(bytes, path, kMaxMapVoxels);
  VoxelGrid grid;
  grid.voxel_size = layout.resolution;
  grid.fixed_voxel_size = true;
  if (layout.nodes == 0) return grid;  // an empty tree
  const std::unique_ptr<octomap::AbstractOcTree> tree = parse(bytes, layout, path);
  if (layout.colour) gather_cells(static_cast<const octomap::ColorOcTree&>(*tree), layout, attributes, path, grid);
  else gather_cells(static_cast<const octomap::OcTree&>(*tree), layout, attributes, path, grid);
  return grid;
}

void write_octomap_with_liboctomap(const MapVoxels& voxels, bool binary, const Point& shift, const std::string& temporary,
                                   MapExportReport& report) {
  const double size = voxels.frame.voxel_size;
  octomap::OcTree tree(size);
  // OctoMap's own rule, coordToKey of the voxel's centre: half a voxel from every face,
  // so no rounding moves it to a neighbour.
  std::vector<octomap::OcTreeKey> keys;
  keys.reserve(voxels.occupied.size() + voxels.free.size());
  for (const auto* list : {&voxels.occupied, &voxels.free})
    for (const Voxel& v : *list) {
      octomap::OcTreeKey key;
      for (int a = 0; a < 3; ++a) {
        const double centre = voxels.frame.origin[a] + (coordinate(v, a) + 0.5) * size + shift[a];
        if (!tree.coordToKeyChecked(centre, key[a]))
          throw InvalidArgument("voxel (" + std::to_string(v.x) + ", " + std::to_string(v.y) + ", " +
                                std::to_string(v.z) + ") lies beyond OctoMap's keys");
      }
      keys.push_back(key);
    }
  if (const std::uint64_t bytes = octree_bytes(keys); bytes > kMaxMapLibraryBytes)
    throw InvalidArgument("liboctomap would need about " + gib_text(bytes) + " GiB for the tree of these " +
                          std::to_string(keys.size()) + " voxels, more than vola's " + gib_text(kMaxMapLibraryBytes) +
                          " GiB: crop the map or export a coarser --depth");

  const std::size_t occupied = voxels.occupied.size();
  for (std::size_t n = 0; n < occupied; ++n) {
    const float value = voxels.occupied_log_odds.empty() ? tree.getClampingThresMaxLog() : voxels.occupied_log_odds[n];
    tree.setNodeValue(keys[n], value, true);
  }
  for (std::size_t n = 0; n < voxels.free.size(); ++n) {  // none of them occupied: MapVoxels::check
    const octomap::OcTreeKey& key = keys[occupied + n];
    tree.setNodeValue(key, voxels.free_log_odds.empty() ? tree.getClampingThresMinLog() : voxels.free_log_odds[n], true);
  }
  tree.updateInnerOccupancy();  // lazy_eval left the inner nodes' values for one pass here

  std::ofstream out(temporary, std::ios::binary | std::ios::trunc);
  const QuietOctomap quiet;
  if (binary) {
    tree.writeBinary(out);  // maximum likelihood, then pruned, as liboctomap writes .bt
  } else {
    tree.prune();
    tree.write(out);
  }
  out.close();
  if (!out) throw IoError("cannot write " + temporary);
  report.nodes = tree.size();
  report.occupied = voxels.occupied.size();
  report.free = voxels.free.size();
}

}  // namespace vola::io

extern "C" {
const char* vola_plugin_version() { return vola::plugin::kPluginVersion; }
void vola_plugin_read_octomap(const std::string& path, bool attributes, vola::io::VoxelGrid& out,
                              vola::plugin::PluginFailure& failure) {
  vola::plugin::capture_failure(failure, [&] { out = vola::io::read_octomap_with_liboctomap(path, attributes); });
}
void vola_plugin_write_octomap(const vola::io::MapVoxels& voxels, bool binary, const vola::Point& shift,
                               const std::string& temporary, vola::io::MapExportReport& report,
                               vola::plugin::PluginFailure& failure) {
  vola::plugin::capture_failure(
      failure, [&] { vola::io::write_octomap_with_liboctomap(voxels, binary, shift, temporary, report); });
}
}
static_assert(std::is_same_v<decltype(&vola_plugin_read_octomap), vola::io::plugin::ReadOctomapEntry>);
static_assert(std::is_same_v<decltype(&vola_plugin_write_octomap), vola::io::plugin::WriteOctomapEntry>);
