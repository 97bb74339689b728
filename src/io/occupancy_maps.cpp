// Occupancy maps out (OctoMap, OpenVDB) and in: the voxels and where they go are decided
// here; liboctomap and OpenVDB, in their plugins, make the files.
#include "vola/io/occupancy_maps.hpp"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <filesystem>
#include <tuple>

#include "export_columns.hpp"
#include "reader_plugin.hpp"
#include "vola/error.hpp"
#include "vola/io/input.hpp"
#include "vola/output_file.hpp"

namespace vola::io {

namespace {

std::string number_text(double value) {
  std::string text;
  append_number(text, value);
  return text;
}

std::string point_text(const Point& p) {
  std::string text = "(";
  for (int a = 0; a < 3; ++a) {
    if (a) text += ", ";
    append_number(text, p[a]);
  }
  return text + ")";
}

std::uint32_t coordinate(const Voxel& v, int axis) { return axis == 0 ? v.x : axis == 1 ? v.y : v.z; }

// How far the lower frame's origin lies below `origin`, in whole voxels; InvalidArgument
// when the two grids do not share their cells.
std::uint32_t voxels_between(double lower, double origin, double size) {
  const double steps = (origin - lower) / size;
  const double whole = std::round(steps);
  if (std::fabs(steps - whole) > 1e-6 || whole >= 4294967296.0)
    throw InvalidArgument("the free voxels' grid does not line up with the occupied voxels' (origins " +
                          number_text(lower) + " and " + number_text(origin) + " are not whole voxels apart)");
  return static_cast<std::uint32_t>(whole);
}

void append_voxels(const Tree& tree, const std::array<std::uint32_t, 3>& offset, std::vector<Voxel>& voxels,
                   std::vector<float>& log_odds) {
  require_complete_columns(tree);
  const AttributeColumn* column = tree.attributes().find("log_odds");
  voxels.reserve(tree.voxel_count());
  tree.for_each_voxel([&](const Voxel& v) {
    if (column) log_odds.push_back(static_cast<float>(column->get(voxels.size())));  // rank = visit order
    voxels.push_back({v.x + offset[0], v.y + offset[1], v.z + offset[2]});
  });
}

// What write_octomap adds to every world coordinate (vola/io/occupancy_maps.hpp says when).
Point octomap_shift(const MapVoxels& voxels, const std::string& path, std::vector<std::string>& warnings) {
  std::array<std::uint32_t, 3> low{UINT32_MAX, UINT32_MAX, UINT32_MAX}, high{0, 0, 0};
  for (const auto* list : {&voxels.occupied, &voxels.free})
    for (const Voxel& v : *list)
      for (int a = 0; a < 3; ++a) {
        low[a] = std::min(low[a], coordinate(v, a));
        high[a] = std::max(high[a], coordinate(v, a));
      }
  Point shift{0, 0, 0};
  if (voxels.occupied.empty() && voxels.free.empty()) return shift;
  const double size = voxels.frame.voxel_size;
  const Point& origin = voxels.frame.origin;
  bool off_cells = false, beyond = false;
  for (int a = 0; a < 3; ++a) {
    const double lattice = origin[a] / size;
    const double whole = std::round(lattice);
    if (std::fabs(lattice - whole) > 1e-6) {
      off_cells = true;
      shift[a] = whole * size - origin[a];
    }
    const double first_key = whole + low[a] + kOctomapKeyCentre, last_key = whole + high[a] + kOctomapKeyCentre;
    if (first_key < 0 || last_key > 2 * kOctomapKeyCentre - 1) beyond = true;
  }
  if (beyond) {
    for (int a = 0; a < 3; ++a)
      if (high[a] >= kOctomapKeyCentre)
        throw OptionError("depth", path + ": the map reaches " + std::to_string(high[a]) +
                                       " voxels from its grid's corner along " + "xyz"[a] +
                                       ", and lies beyond OctoMap's 65536 cells from 0; OctoMap keeps 32768 cells on " +
                                       "each side of 0: crop it or export a coarser `depth`");
    for (int a = 0; a < 3; ++a) shift[a] = -origin[a];
    warnings.push_back(path + ": the map lies beyond OctoMap's 32768 cells of " + number_text(size) +
                       " around 0, so it moved by " + point_text(shift) + ": the grid's corner " + point_text(origin) +
                       " is OctoMap's (0, 0, 0); add it back to OctoMap's coordinates");
  } else if (off_cells) {
    warnings.push_back(path + ": the grid's origin " + point_text(origin) + " is not a multiple of the voxel size " +
                       number_text(size) + ", as OctoMap's cells are (key = floor(x / R)): the map moved by " +
                       point_text(shift) + " onto the nearest cells");
  }
  return shift;
}

}  // namespace

void MapVoxels::check() const {
  if (!(std::isfinite(frame.voxel_size) && frame.voxel_size > 0.0))
    throw InvalidArgument("a map's voxel size must be a finite number > 0");
  for (double o : frame.origin)
    if (!std::isfinite(o)) throw InvalidArgument("a map's origin must be finite");
  const auto check_list = [](const char* state, const std::vector<Voxel>& voxels, const std::vector<float>& log_odds) {
    if (!log_odds.empty() && log_odds.size() != voxels.size())
      throw InvalidArgument(std::string("the ") + state + " voxels have " + std::to_string(log_odds.size()) +
                            " log-odds for " + std::to_string(voxels.size()) + " voxels");
    for (float value : log_odds)
      if (!std::isfinite(value)) throw InvalidArgument(std::string("a log-odds of the ") + state + " voxels is not finite");
    for (const Voxel& v : voxels)
      if (std::max({v.x, v.y, v.z}) >= side_of(kMaxDepth))
        throw InvalidArgument(std::string("a voxel of the ") + state + " voxels lies beyond a depth-10 grid (" +
                              std::to_string(side_of(kMaxDepth)) + " voxels per axis)");
  };
  check_list("occupied", occupied, occupied_log_odds);
  check_list("free", free, free_log_odds);
  // A voxel cannot be both: every writer would otherwise pick a state of its own (OpenVDB
  // kept it in both grids, OctoMap the one set last).
  if (occupied.empty() || free.empty()) return;
  const auto sorted = [](std::vector<Voxel> list) {
    std::sort(list.begin(), list.end(),
              [](const Voxel& a, const Voxel& b) { return std::tie(a.x, a.y, a.z) < std::tie(b.x, b.y, b.z); });
    return list;
  };
  const std::vector<Voxel> a = sorted(occupied), b = sorted(free);
  for (std::size_t i = 0, j = 0; i < a.size() && j < b.size();) {
    if (std::tie(a[i].x, a[i].y, a[i].z) < std::tie(b[j].x, b[j].y, b[j].z))
      ++i;
    else if (std::tie(b[j].x, b[j].y, b[j].z) < std::tie(a[i].x, a[i].y, a[i].z))
      ++j;
    else
      throw InvalidArgument("voxel (" + std::to_string(a[i].x) + ", " + std::to_string(a[i].y) + ", " +
                            std::to_string(a[i].z) + ") is given as occupied and as free");
  }
}

MapVoxels map_voxels(const Tree& occupied, const Tree* free) {
  const Frame frame = occupied.frame();
  MapVoxels voxels;
  voxels.frame = {Quantization::grid, frame.origin, frame.voxel_size};
  std::array<std::uint32_t, 3> occupied_offset{0, 0, 0}, free_offset{0, 0, 0};
  if (free) {
    const Frame other = free->frame();
    if (std::fabs(other.voxel_size - frame.voxel_size) > 1e-9 * frame.voxel_size)
      throw InvalidArgument("the free voxels' size " + number_text(other.voxel_size) + " differs from the occupied voxels' " +
                            number_text(frame.voxel_size));
    for (int a = 0; a < 3; ++a) {
      voxels.frame.origin[a] = std::min(frame.origin[a], other.origin[a]);
      occupied_offset[a] = voxels_between(voxels.frame.origin[a], frame.origin[a], frame.voxel_size);
      free_offset[a] = voxels_between(voxels.frame.origin[a], other.origin[a], frame.voxel_size);
    }
  }
  append_voxels(occupied, occupied_offset, voxels.occupied, voxels.occupied_log_odds);
  if (free) append_voxels(*free, free_offset, voxels.free, voxels.free_log_odds);
  return voxels;
}

MapExportReport write_octomap(const MapVoxels& voxels, const std::string& path) {
  voxels.check();
  const std::string ext = lower_extension(path);
  if (ext != ".bt" && ext != ".ot")
    throw InvalidArgument(path + ": OctoMap files are named .bt (binary, occupied or free) or .ot (with probabilities)");
  MapExportReport report;
  report.shift = octomap_shift(voxels, path, report.warnings);
  const auto entry = reinterpret_cast<plugin::WriteOctomapEntry>(
      vola::plugin::plugin_symbol("octomap", plugin::kWriteOctomapSymbol, path + ": writing an OctoMap"));
  OutputFile out(path);
  PluginFailure failure;
  entry(voxels, ext == ".bt", report.shift, out.temporary(), report, failure);
  vola::plugin::throw_failure(failure);
  out.commit();
  report.log_odds = ext == ".ot" && (!voxels.occupied_log_odds.empty() || !voxels.free_log_odds.empty());
  return report;
}

MapExportReport write_vdb(const MapVoxels& voxels, const std::string& path) {
  voxels.check();
  if (lower_extension(path) != ".vdb") throw InvalidArgument(path + ": OpenVDB files are named .vdb");
  const auto entry = reinterpret_cast<plugin::WriteVdbEntry>(
      vola::plugin::plugin_symbol("openvdb", plugin::kWriteVdbSymbol, path + ": writing an OpenVDB file"));
  MapExportReport report;
  OutputFile out(path);
  PluginFailure failure;
  entry(voxels, out.temporary(), report, failure);
  vola::plugin::throw_failure(failure);
  out.commit();
  report.log_odds = !voxels.occupied_log_odds.empty() || !voxels.free_log_odds.empty();
  return report;
}

VoxelGrid read_octomap(const std::string& path, const InputOptions& options) {
  const auto entry = reinterpret_cast<plugin::ReadOctomapEntry>(
      vola::plugin::plugin_symbol("octomap", plugin::kReadOctomapSymbol, path + ": reading it"));
  VoxelGrid grid;
  PluginFailure failure;
  entry(path, options.attributes, grid, failure);
  vola::plugin::throw_failure(failure);
  return grid;
}

VoxelGrid read_vdb(const std::string& path, const InputOptions& options) {
  const auto entry = reinterpret_cast<plugin::ReadVdbEntry>(
      vola::plugin::plugin_symbol("openvdb", plugin::kReadVdbSymbol, path + ": reading it"));
  VoxelGrid grid;
  PluginFailure failure;
  entry(path, options.grid, options.attributes, grid, failure);
  vola::plugin::throw_failure(failure);
  return grid;
}

}  // namespace vola::io
