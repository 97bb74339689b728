// OpenVDB .vdb read and written through OpenVDB (the openvdb plugin): vola says which
// voxels and which transform; OpenVDB builds the trees, prunes them and encodes the file.
#include <openvdb/io/File.h>
#include <openvdb/openvdb.h>
#include <openvdb/tools/Prune.h>

#include <array>
#include <cmath>
#include <cstdio>
#include <mutex>
#include <optional>
#include <string>
#include <type_traits>

#include "../reader_plugin.hpp"
#include "node_census.hpp"
#include "readers.hpp"
#include "vola/error.hpp"

namespace vola::io {

namespace {

void initialise_openvdb() {
  static std::once_flag once;
  std::call_once(once, [] { openvdb::initialize(); });
}

// The grid types a .vdb's active voxels are read from (points grids are not).
using ReadableGrids = openvdb::TypeList<openvdb::FloatGrid, openvdb::DoubleGrid, openvdb::Int32Grid, openvdb::Int64Grid,
                                        openvdb::Vec3IGrid, openvdb::Vec3SGrid, openvdb::Vec3DGrid, openvdb::BoolGrid,
                                        openvdb::MaskGrid>;

// vola voxel i is OpenVDB index i + offset, whose centre (OpenVDB: at the integer index)
// the transform puts on the vola voxel's world centre. offset = round(origin / R), so
// that grids of one voxel size share an index space, unless that would leave int32.
struct Placement {
  openvdb::Coord offset;
  double size = 1.0;
  openvdb::Vec3d translation;
  // A new transform per grid: Transform::copy() of a translated scale is not exact in
  // OpenVDB 10 (0.05 comes back as 0.05000000000000001).
  openvdb::math::Transform::Ptr transform() const {
    auto transform = openvdb::math::Transform::createLinearTransform(size);
    transform->postTranslate(translation);
    return transform;
  }
};

Placement placement_of(const Frame& frame) {
  const double size = frame.voxel_size;
  Placement placement;
  placement.size = size;
  for (int a = 0; a < 3; ++a) {
    const double lattice = std::round(frame.origin[a] / size);
    const bool fits = std::isfinite(lattice) && std::fabs(lattice) < static_cast<double>(1 << 30);
    placement.offset[a] = fits ? static_cast<openvdb::Int32>(lattice) : 0;
    placement.translation[a] = frame.origin[a] - placement.offset[a] * size + 0.5 * size;
  }
  return placement;
}

template <class GridT, class ValueOf>
typename GridT::Ptr make_grid(const std::string& name, const std::vector<Voxel>& voxels, const Placement& placement,
                              typename GridT::ValueType background, ValueOf value_of) {
  auto grid = GridT::create(background);
  grid->setName(name);
  grid->setTransform(placement.transform());
  auto accessor = grid->getAccessor();
  for (std::size_t n = 0; n < voxels.size(); ++n) {
    const Voxel& v = voxels[n];
    accessor.setValueOn(openvdb::Coord(static_cast<openvdb::Int32>(v.x) + placement.offset.x(),
                                       static_cast<openvdb::Int32>(v.y) + placement.offset.y(),
                                       static_cast<openvdb::Int32>(v.z) + placement.offset.z()),
                        value_of(n));
  }
  openvdb::tools::prune(grid->tree());  // uniform leaves become tiles
  return grid;
}

// OpenVDB's nodes for one grid of these voxels: leaves of 8^3 voxels, internal nodes of
// 128^3 and 4096^3 (node boundaries at multiples of those in index space, hence the
// offset modulo 4096), each with an allocation's overhead; a non-bool leaf's values sit
// in a buffer of their own.
template <class GridT>
std::uint64_t grid_bytes(const std::vector<Voxel>& voxels, const Placement& placement) {
  using Tree = typename GridT::TreeType;
  using Upper = typename Tree::RootNodeType::ChildNodeType;
  using Lower = typename Upper::ChildNodeType;
  using Leaf = typename Tree::LeafNodeType;
  std::array<std::uint32_t, 3> phase{};
  for (int a = 0; a < 3; ++a) phase[a] = static_cast<std::uint32_t>(((placement.offset[a] % 4096) + 4096) % 4096);
  std::vector<std::uint64_t> codes;
  codes.reserve(voxels.size());
  for (const Voxel& v : voxels) codes.push_back(morton_code(v.x + phase[0], v.y + phase[1], v.z + phase[2]));
  const std::vector<std::uint64_t> cells = cells_per_shift(codes, {Leaf::TOTAL, Lower::TOTAL, Upper::TOTAL});
  constexpr std::uint64_t kOverhead = 16;
  const std::uint64_t buffer = std::is_same_v<typename GridT::ValueType, bool> ? 0 : Leaf::SIZE * sizeof(typename GridT::ValueType) + kOverhead;
  return cells[0] * (sizeof(Leaf) + kOverhead + buffer) + cells[1] * (sizeof(Lower) + kOverhead) +
         cells[2] * (sizeof(Upper) + kOverhead);
}

// One state's grid: BoolGrid of true voxels, or FloatGrid of their log-odds (background 0:
// probability 0.5, OctoMap's prior for unknown space).
openvdb::GridBase::Ptr state_grid(const std::string& name, const std::vector<Voxel>& voxels,
                                  const std::vector<float>& log_odds, const Placement& placement) {
  if (log_odds.empty())
    return make_grid<openvdb::BoolGrid>(name, voxels, placement, false, [](std::size_t) { return true; });
  return make_grid<openvdb::FloatGrid>(name == "occupied" ? "log_odds" : name + "_log_odds", voxels, placement, 0.0f,
                                       [&](std::size_t n) { return log_odds[n]; });
}

// The grid's voxel size and the world position of index (0, 0, 0)'s centre, after
// checking that the transform is a uniform scale plus a translation.
std::pair<double, openvdb::Vec3d> uniform_frame(const openvdb::GridBase& grid, const std::string& path) {
  const openvdb::math::Transform& transform = grid.transform();
  const auto refuse = [&](const std::string& why) {
    return FormatError(path, std::nullopt, "grid '" + grid.getName() + "': " + why + "; vola grids are axis-aligned cubes");
  };
  if (!transform.isLinear()) throw refuse("its transform is not linear (a frustum?)");
  // The linear part alone (the Jacobian), so that a large translation costs no precision.
  const auto map = transform.baseMap();
  const double size = map->applyJacobian(openvdb::Vec3d(1, 0, 0))[0];
  if (!(std::isfinite(size) && size > 0.0 && std::isfinite(1.0 / size) && std::isfinite(size * 4294967296.0)))
    throw refuse("its voxel size is not a finite number > 0 whose 2^32 voxels are finite");
  for (int a = 0; a < 3; ++a) {
    openvdb::Vec3d unit(0, 0, 0);
    unit[a] = 1.0;
    const openvdb::Vec3d step = map->applyJacobian(unit);
    for (int b = 0; b < 3; ++b)
      if (std::fabs(step[b] - (a == b ? size : 0.0)) > 1e-9 * size)
        throw refuse("its transform rotates, shears or scales the axes unequally");
  }
  const openvdb::Vec3d zero = transform.indexToWorld(openvdb::Vec3d(0, 0, 0));
  for (int a = 0; a < 3; ++a)
    if (!std::isfinite(zero[a])) throw refuse("its translation is not finite");
  return {size, zero};
}

template <class GridT>
void collect_active(const GridT& grid, bool keep_values, const std::string& path, VoxelGrid& out) {
  using Value = typename GridT::ValueType;
  constexpr bool numeric = std::is_same_v<Value, float> || std::is_same_v<Value, double> ||
                           std::is_same_v<Value, openvdb::Int32> || std::is_same_v<Value, openvdb::Int64>;
  const openvdb::Index64 count = grid.activeVoxelCount();
  if (count > kMaxMapVoxels)
    throw FormatError(path, std::nullopt,
                      "grid '" + grid.getName() + "' has " + std::to_string(count) + " active voxels, more than vola's " +
                          std::to_string(kMaxMapVoxels) + " for a map");
  if (count == 0) return;
  const openvdb::CoordBBox box = grid.evalActiveVoxelBoundingBox();
  const openvdb::Coord low = box.min();
  PointAttribute column{grid.getName(), ValueType::f32, Reduction::last, {}};
  if constexpr (std::is_same_v<Value, double>) column.type = ValueType::f64;
  if constexpr (std::is_same_v<Value, openvdb::Int32>) column.type = ValueType::i32;
  if constexpr (std::is_same_v<Value, openvdb::Int64>) column.type = ValueType::i64;
  out.voxels.reserve(count);
  const auto add = [&](const openvdb::Coord& c, [[maybe_unused]] const Value& value) {
    out.voxels.push_back({static_cast<std::uint32_t>(c.x() - low.x()), static_cast<std::uint32_t>(c.y() - low.y()),
                          static_cast<std::uint32_t>(c.z() - low.z())});
    if constexpr (numeric)
      if (keep_values) column.values.push_back(static_cast<double>(value));
  };
  for (auto it = grid.cbeginValueOn(); it; ++it) {
    if (it.isVoxelValue()) {
      add(it.getCoord(), *it);
      continue;
    }
    openvdb::CoordBBox tile;
    it.getBoundingBox(tile);
    for (auto c = tile.begin(); c; ++c) add(*c, *it);
  }
  for (int a = 0; a < 3; ++a) out.dims[a] = static_cast<std::uint32_t>(box.dim()[a]);
  if (numeric && keep_values) out.attributes.push_back(std::move(column));
}

// The grid read when none is named: the only one, or the occupied grid of a map vola
// wrote ("log_odds", else "occupied"; its free grid sorts before it); none when the file
// holds several others. OpenVDB lists grids by name, so "the first" would be the first
// name, not the first written: refusing is clearer than guessing.
std::optional<std::string> default_grid(const openvdb::GridPtrVec& grids) {
  if (grids.size() == 1) return grids.front()->getName();
  for (const char* own : {"log_odds", "occupied"})
    for (const auto& g : grids)
      if (g->getName() == own) return own;
  return std::nullopt;
}

}  // namespace

VoxelGrid read_vdb_with_openvdb(const std::string& path, const std::string& name, bool attributes) {
  initialise_openvdb();
  VoxelGrid out;
  out.fixed_voxel_size = true;
  try {
    openvdb::io::File file(path);
    file.open(false);  // no delayed loading: a damaged file fails here, not halfway through the voxels
    const openvdb::GridPtrVecPtr grids = file.readAllGridMetadata();  // by name, not in file order
    if (!grids || grids->empty()) throw FormatError(path, std::nullopt, "holds no grid");
    std::string names;
    for (const auto& g : *grids) names += (names.empty() ? "'" : ", '") + g->getName() + "'";
    const std::optional<std::string> found = name.empty() ? default_grid(*grids) : name;
    if (!found)
      throw FormatError(path, std::nullopt,
                        "holds " + std::to_string(grids->size()) + " grids (" + names + "): choose one with --grid NAME");
    const std::string& chosen = *found;
    if (!file.hasGrid(chosen))
      throw FormatError(path, std::nullopt, "has no grid named '" + chosen + "' (its grids: " + names + ")");
    // The count OpenVDB's writer records, checked before the grid's voxels are read.
    const openvdb::GridBase::Ptr meta = file.readGridMetadata(chosen);
    if (const auto recorded = meta->getMetadata<openvdb::Int64Metadata>(openvdb::GridBase::META_FILE_VOXEL_COUNT))
      if (recorded->value() < 0 || static_cast<std::uint64_t>(recorded->value()) > kMaxMapVoxels)
        throw FormatError(path, std::nullopt,
                          "grid '" + chosen + "' records " + std::to_string(recorded->value()) +
                              " active voxels, more than vola's " + std::to_string(kMaxMapVoxels) + " for a map");
    const openvdb::GridBase::Ptr grid = file.readGrid(chosen);
    file.close();
    const auto [size, zero] = uniform_frame(*grid, path);
    const bool known = grid->apply<ReadableGrids>([&](const auto& typed) { collect_active(typed, attributes, path, out); });
    if (!known)
      throw FormatError(path, std::nullopt, "grid '" + chosen + "' is of type " + grid->type() + ", which vola does not read");
    if (out.voxels.empty()) {
      out.voxel_size = size;
      return out;
    }
    const openvdb::CoordBBox box = grid->evalActiveVoxelBoundingBox();
    for (int a = 0; a < 3; ++a) {
      // The corner of index `low`: index i's cell is [i - 1/2, i + 1/2) in OpenVDB. A corner
      // within rounding of a multiple of the voxel size is that multiple, as vola writes it.
      const double corner = (zero[a] - 0.5 * size) / size + box.min()[a];
      const double lattice = std::round(corner);
      out.origin[a] = (std::fabs(corner - lattice) < 1e-9 * std::max(1.0, std::fabs(lattice)) ? lattice : corner) * size;
      if (!std::isfinite(out.origin[a]))
        throw FormatError(path, std::nullopt, "grid '" + chosen + "': its voxels lie beyond finite coordinates");
    }
    out.voxel_size = size;
    return out;
  } catch (const openvdb::Exception& e) {
    throw FormatError(path, std::nullopt, std::string("OpenVDB cannot read it: ") + e.what());
  }
}

void write_vdb_with_openvdb(const MapVoxels& voxels, const std::string& temporary, MapExportReport& report) {
  initialise_openvdb();
  const Placement placement = placement_of(voxels.frame);
  const auto bytes_of = [&](const std::vector<Voxel>& list, const std::vector<float>& log_odds) {
    return log_odds.empty() ? grid_bytes<openvdb::BoolGrid>(list, placement) : grid_bytes<openvdb::FloatGrid>(list, placement);
  };
  const std::uint64_t bytes =
      bytes_of(voxels.occupied, voxels.occupied_log_odds) + bytes_of(voxels.free, voxels.free_log_odds);
  if (bytes > kMaxMapLibraryBytes)
    throw InvalidArgument("OpenVDB would need about " + gib_text(bytes) + " GiB for the grids of these " +
                          std::to_string(voxels.occupied.size() + voxels.free.size()) +
                          " voxels (scattered thinly: OpenVDB's internal nodes cover 128^3 and 4096^3 voxels each), "
                          "more than vola's " + gib_text(kMaxMapLibraryBytes) + " GiB: crop the map or export a coarser --depth");
  openvdb::GridPtrVec grids;
  grids.push_back(state_grid("occupied", voxels.occupied, voxels.occupied_log_odds, placement));
  if (!voxels.free.empty()) grids.push_back(state_grid("free", voxels.free, voxels.free_log_odds, placement));
  try {
    openvdb::io::File file(temporary);
    file.write(grids);
    file.close();
  } catch (const openvdb::Exception& e) {
    throw IoError("cannot write " + temporary + ": " + e.what());
  }
  for (const auto& grid : grids) report.grids.push_back(grid->getName());
  report.occupied = voxels.occupied.size();
  report.free = voxels.free.size();
}

}  // namespace vola::io

extern "C" {
const char* vola_plugin_version() { return vola::plugin::kPluginVersion; }
void vola_plugin_read_vdb(const std::string& path, const std::string& grid, bool attributes, vola::io::VoxelGrid& out,
                          vola::plugin::PluginFailure& failure) {
  vola::plugin::capture_failure(failure, [&] { out = vola::io::read_vdb_with_openvdb(path, grid, attributes); });
}
void vola_plugin_write_vdb(const vola::io::MapVoxels& voxels, const std::string& temporary,
                           vola::io::MapExportReport& report, vola::plugin::PluginFailure& failure) {
  vola::plugin::capture_failure(failure, [&] { vola::io::write_vdb_with_openvdb(voxels, temporary, report); });
}
}
static_assert(std::is_same_v<decltype(&vola_plugin_read_vdb), vola::io::plugin::ReadVdbEntry>);
static_assert(std::is_same_v<decltype(&vola_plugin_write_vdb), vola::io::plugin::WriteVdbEntry>);
