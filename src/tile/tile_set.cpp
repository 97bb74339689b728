#include "vola/tile/tile_set.hpp"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <limits>
#include <utility>
#include <vector>

#include "vola/builder.hpp"
#include "vola/error.hpp"
#include "vola/file.hpp"
#include "vola/parallel.hpp"
#include "vola/raycast/ray_caster.hpp"
#include "vola/raycast/render.hpp"
#include "vola/raycast/world.hpp"

namespace vola::tile {

namespace fs = std::filesystem;

struct TileSet::Opened {
  Tree tree;
  std::unique_ptr<raycast::RayCaster> caster;      // made on the first ray
  std::unique_ptr<raycast::VoxelColours> colours;  // made with the caster
  std::once_flag caster_once;
};

TileSet::TileSet(const std::string& index_path) : index_(read_tile_index(index_path)) {
  folder_ = fs::path(index_path).parent_path().string();
  if (index_.tiles.empty()) throw FormatError(index_path, 0, "the tile index lists no tiles");
  constexpr double inf = std::numeric_limits<double>::infinity();
  bounds_ = Box{{inf, inf, inf}, {-inf, -inf, -inf}};
  for (std::size_t p = 0; p < index_.tiles.size(); ++p) {
    entries_[index_.tiles[p].tile] = p;
    const Box b = index_.grid.tile_box(index_.tiles[p].tile);
    for (int a = 0; a < 3; ++a) {
      bounds_.min[a] = std::min(bounds_.min[a], b.min[a]);
      bounds_.max[a] = std::max(bounds_.max[a], b.max[a]);
    }
  }
}

TileSet::~TileSet() = default;

const TileSet::Opened* TileSet::open(const TileIndex& tile) const {
  const auto entry = entries_.find(tile);
  if (entry == entries_.end()) return nullptr;
  const std::lock_guard lock(mutex_);
  auto& slot = opened_[tile];
  if (!slot) {
    const TileEntry& e = index_.tiles[entry->second];
    const std::string path = (fs::path(folder_) / e.file).string();
    Tree tree = open_mapped(path);
    if (tree.depth() != index_.grid.depth || tree.frame().quantization != Quantization::grid)
      throw FormatError(path, 0, "tile does not match its index (depth " + std::to_string(tree.depth()) +
                                     ", the index says " + std::to_string(index_.grid.depth) + ")");
    check_tile_place(tree, tile, path);
    slot = std::make_unique<Opened>();
    slot->tree = std::move(tree);
  }
  return slot.get();
}

// A tile file holds its own place (origin and voxel size): it must be the cell the index
// puts it in. A hand-edited index that swapped two files, or gave the grid another tile
// size, answered "empty" for occupied points without a word.
void TileSet::check_tile_place(const Tree& tree, const TileIndex& tile, const std::string& path) const {
  const Frame own = tree.frame(), cell = index_.grid.tile_frame(tile);
  const double tolerance = 1e-6 * cell.voxel_size;
  bool same = std::abs(own.voxel_size - cell.voxel_size) <= tolerance;
  for (int a = 0; a < 3; ++a) same = same && std::abs(own.origin[a] - cell.origin[a]) <= tolerance;
  if (same) return;
  char text[400];
  std::snprintf(text, sizeof text,
                "the tile's grid (origin %.10g %.10g %.10g, voxel %.10g) is not that of the cell [%d, %d, %d] the "
                "index puts it in (origin %.10g %.10g %.10g, voxel %.10g)",
                own.origin[0], own.origin[1], own.origin[2], own.voxel_size, tile.i, tile.j, tile.k, cell.origin[0],
                cell.origin[1], cell.origin[2], cell.voxel_size);
  throw FormatError(path, std::nullopt, text);
}

const Tree* TileSet::tree(const TileIndex& tile) const {
  const Opened* o = open(tile);
  return o ? &o->tree : nullptr;
}

std::size_t TileSet::tiles_opened() const {
  const std::lock_guard lock(mutex_);
  return opened_.size();
}

std::array<double, 3> TileSet::colour(const TileHit& hit) const {
  const Opened* opened = open(hit.tile);
  if (!opened || !opened->colours) throw InvalidArgument("TileSet::colour: give a hit cast() returned");
  return opened->colours->at(hit.voxel);
}

TileLookup TileSet::locate(const Point& world) const {
  TileLookup out;
  Key key;
  if (!index_.grid.locate(world, out.tile, key)) return out;
  out.voxel = decode(key);
  const Tree* t = tree(out.tile);
  if (!t) return out;
  out.in_tile = true;
  out.rank = t->rank(out.voxel);
  check_mapped_often(*t);  // a tile cut since it was opened reads as zeros: an error, not an answer
  return out;
}

std::optional<TileHit> TileSet::cast(const raycast::Ray& world_ray) const {
  raycast::check_ray(world_ray);
  const Point& o = world_ray.origin;
  const Point& d = world_ray.direction;
  // Where the ray is inside the box of all tiles (slab test).
  double t0 = 0.0, t1 = world_ray.t_max;
  for (int a = 0; a < 3; ++a) {
    if (d[a] == 0.0) {
      if (o[a] < bounds_.min[a] || o[a] > bounds_.max[a]) return std::nullopt;
      continue;
    }
    double ta = (bounds_.min[a] - o[a]) / d[a], tb = (bounds_.max[a] - o[a]) / d[a];
    if (ta > tb) std::swap(ta, tb);
    t0 = std::max(t0, ta);
    t1 = std::min(t1, tb);
  }
  if (!(t0 <= t1)) return std::nullopt;
  const TileGrid& g = index_.grid;
  // The DDA below visits every cell the ray crosses in the box of all tiles, listed or
  // not. Where that is more than the listed tiles (a few tiles far apart: an index with
  // one tile at [2^31 - 1, ...] spun for minutes), the listed tiles the ray meets are
  // taken in the ray's order instead.
  double crossed = 1.0;
  for (int a = 0; a < 3; ++a) crossed += std::abs((t1 - t0) * d[a]) / g.tile_size + 1.0;
  if (crossed > 2.0 * static_cast<double>(index_.tiles.size()) + 64.0) return cast_listed(world_ray, t0, t1);
  // A DDA over the tile grid from the entry point; each tile the set has casts the ray
  // itself, and tiles come in the ray's order, so the first hit is the nearest.
  std::array<std::int64_t, 3> cell{}, step{}, lo{}, hi{};
  std::array<double, 3> next{}, delta{};
  for (int a = 0; a < 3; ++a) {
    lo[a] = static_cast<std::int64_t>(std::llround((bounds_.min[a] - g.origin[a]) / g.tile_size));
    hi[a] = static_cast<std::int64_t>(std::llround((bounds_.max[a] - g.origin[a]) / g.tile_size)) - 1;
    const double p = o[a] + t0 * d[a];
    cell[a] = std::clamp(static_cast<std::int64_t>(std::floor((p - g.origin[a]) / g.tile_size)), lo[a], hi[a]);
    step[a] = d[a] > 0 ? 1 : (d[a] < 0 ? -1 : 0);
    if (step[a] == 0) {
      next[a] = delta[a] = std::numeric_limits<double>::infinity();
    } else {
      const double plane = g.origin[a] + static_cast<double>(cell[a] + (step[a] > 0 ? 1 : 0)) * g.tile_size;
      next[a] = (plane - o[a]) / d[a];
      delta[a] = g.tile_size / std::abs(d[a]);
    }
  }
  for (;;) {
    const TileIndex t{static_cast<std::int32_t>(cell[0]), static_cast<std::int32_t>(cell[1]),
                      static_cast<std::int32_t>(cell[2])};
    if (auto hit = cast_in_tile(t, world_ray)) return hit;
    const int a = next[0] < next[1] ? (next[0] < next[2] ? 0 : 2) : (next[1] < next[2] ? 1 : 2);
    if (!(next[a] <= t1)) return std::nullopt;
    cell[a] += step[a];
    if (cell[a] < lo[a] || cell[a] > hi[a]) return std::nullopt;
    next[a] += delta[a];
  }
}

std::optional<TileHit> TileSet::cast_in_tile(const TileIndex& t, const raycast::Ray& world_ray) const {
  const Opened* opened = open(t);
  if (!opened) return std::nullopt;
  std::call_once(const_cast<Opened*>(opened)->caster_once, [opened] {
    const_cast<Opened*>(opened)->caster = std::make_unique<raycast::RayCaster>(opened->tree);
    const_cast<Opened*>(opened)->colours = std::make_unique<raycast::VoxelColours>(opened->tree);
  });
  const raycast::Ray local = raycast::world_ray_to_grid(index_.grid.tile_frame(t), world_ray);
  const auto hit = opened->caster->cast(local);
  check_mapped_often(opened->tree);
  if (!hit) return std::nullopt;
  return TileHit{t, hit->voxel, hit->t * index_.grid.voxel_size(), hit->normal};
}

// The listed tiles whose boxes the ray meets within [t0, t1], by entry distance: tiles do
// not overlap, so a hit in one comes before any in the tiles the ray enters later.
std::optional<TileHit> TileSet::cast_listed(const raycast::Ray& world_ray, double t0, double t1) const {
  const Point& o = world_ray.origin;
  const Point& d = world_ray.direction;
  std::vector<std::pair<double, std::size_t>> met;
  for (std::size_t p = 0; p < index_.tiles.size(); ++p) {
    const Box b = index_.grid.tile_box(index_.tiles[p].tile);
    double enter = t0, leave = t1;
    for (int a = 0; a < 3 && enter <= leave; ++a) {
      if (d[a] == 0.0) {
        if (o[a] < b.min[a] || o[a] > b.max[a]) enter = leave + 1.0;
        continue;
      }
      double ta = (b.min[a] - o[a]) / d[a], tb = (b.max[a] - o[a]) / d[a];
      if (ta > tb) std::swap(ta, tb);
      enter = std::max(enter, ta);
      leave = std::min(leave, tb);
    }
    if (enter <= leave) met.emplace_back(enter, p);
  }
  std::sort(met.begin(), met.end());
  for (const auto& [enter, p] : met)
    if (auto hit = cast_in_tile(index_.tiles[p].tile, world_ray)) return hit;
  return std::nullopt;
}

Tree TileSet::mosaic(const Box& box) const {
  const TileGrid& g = index_.grid;
  std::array<std::int64_t, 3> first{}, last{};
  for (int a = 0; a < 3; ++a) {
    first[a] = static_cast<std::int64_t>(std::floor((std::max(box.min[a], bounds_.min[a]) - g.origin[a]) / g.tile_size));
    last[a] = static_cast<std::int64_t>(std::floor((std::min(box.max[a], bounds_.max[a]) - g.origin[a]) / g.tile_size));
    last[a] = std::min(last[a], static_cast<std::int64_t>(std::llround((bounds_.max[a] - g.origin[a]) / g.tile_size)) - 1);
    if (last[a] < first[a]) throw InvalidArgument("the region lies outside every tile of the set");
  }
  const std::int64_t span = std::max({last[0] - first[0], last[1] - first[1], last[2] - first[2]}) + 1;
  int extra = 0;
  while ((std::int64_t{1} << (2 * extra)) < span) ++extra;
  if (g.depth + extra > kMaxDepth)
    throw InvalidArgument("the region spans " + std::to_string(span) + " tiles per axis; one grid of depth-" +
                          std::to_string(g.depth) + " tiles holds at most " +
                          std::to_string(std::int64_t{1} << (2 * (kMaxDepth - g.depth))) + " (choose a smaller region)");
  const std::uint32_t side = side_of(g.depth);
  std::vector<Key> keys;
  for (const auto& [t, position] : entries_) {
    if (t.i < first[0] || t.i > last[0] || t.j < first[1] || t.j > last[1] || t.k < first[2] || t.k > last[2]) continue;
    const Tree* tree = this->tree(t);
    const auto ox = static_cast<std::uint32_t>((t.i - first[0]) * side);
    const auto oy = static_cast<std::uint32_t>((t.j - first[1]) * side);
    const auto oz = static_cast<std::uint32_t>((t.k - first[2]) * side);
    tree->for_each_voxel([&](const Voxel& v) { keys.push_back(encode(ox + v.x, oy + v.y, oz + v.z)); });
    check_mapped_often(*tree);
  }
  Tree out = build_from_keys(std::move(keys), g.depth + extra);
  const TileIndex corner{static_cast<std::int32_t>(first[0]), static_cast<std::int32_t>(first[1]),
                         static_cast<std::int32_t>(first[2])};
  out.set_frame(g.tile_frame(corner));
  out.georef().epsg = index_.epsg.value_or(2000);
  out.georef().crs_wkt = index_.crs_wkt;
  return out;
}

raycast::Rendering render(const TileSet& tiles, const raycast::PinholeCamera& camera, unsigned threads) {
  camera.check();
  raycast::Rendering out;
  out.width = camera.width;
  out.height = camera.height;
  const std::size_t pixels = std::size_t{camera.width} * camera.height;
  out.depth.assign(pixels, std::numeric_limits<double>::infinity());
  out.rgb.assign(pixels * 3, 0);
  std::atomic<std::uint64_t> hits{0};
  // A tile that cannot be opened (missing, corrupt) fails the first ray that reaches it;
  // parallel_for stops handing out pixels and throws that error here.
  ParallelOptions parallel;
  parallel.threads = threads;
  parallel.grain = raycast::kRaysPerChunk;
  parallel.name = "tile.render";
  const auto render_pixels = [&](std::size_t begin, std::size_t end) {
    std::uint64_t local = 0;
    for (std::size_t p = begin; p < end; ++p) {
      const std::optional<TileHit> hit = tiles.cast(
          camera.ray(static_cast<std::uint32_t>(p % camera.width), static_cast<std::uint32_t>(p / camera.width)));
      if (!hit) continue;
      ++local;
      out.depth[p] = hit->t;
      raycast::shade_pixel(tiles.colour(*hit), hit->normal, &out.rgb[3 * p]);
    }
    hits += local;
  };
  parallel_for(pixels, render_pixels, parallel);
  out.hits = hits;
  return out;
}

raycast::PinholeCamera overview_camera(const TileSet& tiles, const raycast::PinholeCamera& settings) {
  std::vector<Point> corners;  // every tile's box: a survey's empty tiles do not push the camera back
  for (const auto& t : tiles.index().tiles)
    for (int k = 0; k < 8; ++k)
      corners.push_back({k & 1 ? t.bbox.max[0] : t.bbox.min[0], k & 2 ? t.bbox.max[1] : t.bbox.min[1],
                         k & 4 ? t.bbox.max[2] : t.bbox.min[2]});
  return raycast::framing(corners, settings);
}

}  // namespace vola::tile
