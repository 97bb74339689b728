// One .vol file as `vola view` serves it: the mapped tree, random access to the cells of
// every level, the columns that colour voxels, and picking by ray at any level.
#pragma once

#include <array>
#include <cstdint>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json_fwd.hpp>

#include "vola/attributes.hpp"
#include "vola/file.hpp"
#include "vola/raycast/ray.hpp"
#include "vola/tree.hpp"
#include "vola/viewer/cell_index.hpp"

namespace vola::raycast {
class RayCaster;
}

namespace vola::viewer {

// The binary cell batch (all little-endian): a 32-byte header
//   "VOLC", u32 level, u32 coordinate bytes (2 when the level's side fits 16 bits, else 4),
//   u32 flags (bit 0: classes follow, bit 1: colours follow), u64 first cell, u64 count,
// then count x,y,z triples of the coordinate width on the level's 4^(level+1) grid, then
// count class bytes (flag 0), then count r,g,b byte triples (flag 1). A coarse cell
// carries the class and colour of its first voxel in key order.
inline constexpr std::uint32_t kBatchFlagClasses = 1;
inline constexpr std::uint32_t kBatchFlagColours = 2;
inline constexpr std::size_t kBatchHeaderBytes = 32;
// The most cells one batch may ask for (48 MiB of 32-bit coordinates).
inline constexpr std::uint64_t kMaxBatchCells = std::uint64_t{1} << 22;

// Which voxels of a state map (vola map) a ViewedFile shows; any other file shows all
// its voxels whatever is asked.
enum class MapPart { occupied, free };

class ViewedFile {
 public:
  // Maps the file (FormatError / IoError for a bad one) and scans its colour columns. A
  // state map shows its occupied voxels, or with MapPart::free its free ones (named
  // "NAME (free)"); InvalidArgument for MapPart::free on a file that is not a state map.
  explicit ViewedFile(const std::string& path, MapPart part = MapPart::occupied);
  ~ViewedFile();
  ViewedFile(const ViewedFile&) = delete;
  ViewedFile& operator=(const ViewedFile&) = delete;

  const std::string& path() const noexcept { return path_; }
  // The file's base name: what the server shows of it (never the path it was given,
  // which may say where the user keeps their files).
  const std::string& name() const noexcept { return name_; }
  const Tree& tree() const noexcept { return tree_; }
  bool is_state_map() const noexcept { return state_map_; }
  const CellIndex& cells() const noexcept { return index_; }

  // Name (base name only), counts per level, grid frame, CRS and its unit (crs_units.hpp),
  // attributes, the classes present with their ASPRS names: what the page needs before
  // asking for cells.
  nlohmann::json metadata() const;
  // Cells [first, first + count) of `level` as a binary batch (format above); count is
  // clipped to the cells there are. InvalidArgument for a bad level or count.
  std::string cell_batch(int level, std::uint64_t first, std::uint64_t count) const;
  // What one cell of `level` holds: occupancy, its voxels, world centre, and the
  // attributes of its first voxel. InvalidArgument for a bad level or a cell off the grid.
  nlohmann::json cell_info(int level, const Voxel& cell) const;
  // The first occupied cell of `level` along `ray` (in the level's cell units), with
  // cell_info; {"hit": false} when it meets none. InvalidArgument for a bad ray or level.
  nlohmann::json pick(int level, const raycast::Ray& ray) const;

 private:
  struct LevelView {
    Tree tree;  // the first level+1 levels
    std::unique_ptr<raycast::RayCaster> caster;
  };
  const LevelView& level_view(int level) const;
  void check_level(int level) const;

  std::string path_;
  std::string name_;
  FileLayout layout_;
  bool state_map_ = false;
  Tree tree_;
  CellIndex index_;
  const AttributeColumn* classes_ = nullptr;
  std::array<const AttributeColumn*, 3> rgb_{};  // all three or none
  unsigned rgb_shift_ = 0;                       // 8 for 16-bit colours (LAS), else 0
  std::vector<std::uint64_t> class_counts_;      // voxels per class code 0..255
  Voxel voxels_min_{}, voxels_max_{};            // bounds of the occupied voxels
  mutable std::mutex levels_mutex_;
  mutable std::vector<std::unique_ptr<LevelView>> levels_;
};

}  // namespace vola::viewer
