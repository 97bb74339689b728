#include "vola/tile/tiler.hpp"


#include <algorithm>
#include <cstdio>
#include <array>
#include <bit>
#include <atomic>
#include <chrono>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <limits>
#include <map>
#include <optional>
#include <unordered_map>

#include "generation.hpp"
#include "overviews.hpp"
#include "spill.hpp"
#include "tile_georef.hpp"
#include "vola/builder.hpp"
#include "vola/crs_rules.hpp"
#include "vola/error.hpp"
#include "vola/file.hpp"
#include "vola/parallel.hpp"
#include "vola/tile/tile_index.hpp"
#include "vola/voxel_reducer.hpp"

namespace vola::tile {

namespace fs = std::filesystem;
using detail::Run;
using detail::SpillFile;

namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();
constexpr std::uint64_t kRecordBufferWords = std::uint64_t{8} << 20;  // 64 MiB per worker

struct TileStat {
  std::uint64_t points = 0;
  Box bbox{{kInf, kInf, kInf}, {-kInf, -kInf, -kInf}};
  void merge(const TileStat& o) {
    points += o.points;
    for (int a = 0; a < 3; ++a) {
      bbox.min[a] = std::min(bbox.min[a], o.bbox.min[a]);
      bbox.max[a] = std::max(bbox.max[a], o.bbox.max[a]);
    }
  }
};

using StatMap = std::map<TileIndex, TileStat>;
using RunMap = std::map<TileIndex, std::vector<Run>>;

// Sorts keys and drops repeats, in place.
void sort_unique(std::vector<Key>& keys, int depth) {
  radix_sort(keys, nullptr, 6 * depth);
  keys.erase(std::unique(keys.begin(), keys.end()), keys.end());
}

struct TileHash {
  std::size_t operator()(const TileIndex& t) const noexcept {
    return (static_cast<std::uint32_t>(t.i) * 0x9E3779B1u) ^ (static_cast<std::uint32_t>(t.j) * 0x85EBCA77u) ^
           (static_cast<std::uint32_t>(t.k) * 0xC2B2AE3Du);
  }
};

// Counts what a growing buffer holds room for: `held` grows with its capacity.
template <class Push>
void push_counted(std::vector<std::uint64_t>& buffer, std::uint64_t& held, Push&& push) {
  const std::size_t before = buffer.capacity();
  push();
  held += buffer.capacity() - before;
}

// One worker of the bucket phase: per-tile key buffers spilled as sorted unique runs;
// with attributes, per-tile attribute records too (voxel key, sequence number, values),
// spilled as runs in sequence order.
class Bucketer {
 public:
  Bucketer(const TileGrid& grid, SpillFile& file, SpillFile* value_file, std::uint32_t file_id, std::uint64_t limit_words,
           std::size_t attribute_count)
      : grid_(grid), locator_(grid), file_(file), value_file_(value_file), file_id_(file_id),
        limit_(std::max<std::uint64_t>(limit_words, 1024)), attributes_(attribute_count) {}

  // A chunk's points, point p with sequence number first_sequence + p and values[a][p].
  void add(const std::vector<double>& xyz, const std::vector<std::vector<double>>& values, std::uint64_t first_sequence) {
    const std::size_t n = xyz.size() / 3;
    if (values.size() != attributes_) throw Error("tile: a chunk's attribute values do not match its columns");
    for (const auto& v : values)
      if (v.size() != n) throw Error("tile: a chunk has " + std::to_string(v.size()) + " attribute values for " +
                                     std::to_string(n) + " points");
    for (std::size_t p = 0; p < n; ++p) {
      const Point point{xyz[3 * p], xyz[3 * p + 1], xyz[3 * p + 2]};
      TileIndex t;
      Key key;
      if (!locator_.locate(point, t, key)) {
        ++outside_;
        continue;
      }
      TileBuffers& buffers = *slot_of(t).buffers;
      std::vector<Key>* keys = &buffers.keys;
      TileStat* stat = &buffers.stat;
      // The budget counts what the buffers hold, growth included.
      push_counted(*keys, held_, [&] { keys->push_back(key); });
      if (attributes_) {
        std::vector<std::uint64_t>& records = buffers.records;
        push_counted(records, held_, [&] {
          records.push_back(key);
          records.push_back(first_sequence + p);
          for (std::size_t a = 0; a < attributes_; ++a) records.push_back(std::bit_cast<std::uint64_t>(values[a][p]));
        });
      }
      ++stat->points;
      for (int a = 0; a < 3; ++a) {
        stat->bbox.min[a] = std::min(stat->bbox.min[a], point[a]);
        stat->bbox.max[a] = std::max(stat->bbox.max[a], point[a]);
      }
      if (held_ >= limit_) flush();
    }
  }

  void flush() {
    for (auto& [tile, buffers] : tiles_) {
      std::vector<Key>& keys = buffers.keys;
      if (keys.empty()) continue;
      sort_unique(keys, grid_.depth);
      runs_[tile].push_back(Run{file_id_, file_.append(keys), keys.size()});
      ++run_count_;
      std::vector<Key>().swap(keys);  // give the memory back: the budget counts it
    }
    for (auto& [tile, buffers] : tiles_) {
      std::vector<std::uint64_t>& records = buffers.records;
      if (records.empty()) continue;
      in_sequence_order(records);
      const std::size_t words = 2 + attributes_;
      value_runs_[tile].push_back(detail::append_records(*value_file_, file_id_, records, words));
      std::vector<std::uint64_t>().swap(records);
    }
    held_ = 0;
  }

  StatMap stats() const {
    StatMap out;
    for (const auto& [tile, buffers] : tiles_) out[tile] = buffers.stat;
    return out;
  }
  const RunMap& runs() const noexcept { return runs_; }
  const RunMap& value_runs() const noexcept { return value_runs_; }
  std::uint64_t outside() const noexcept { return outside_; }
  std::uint64_t run_count() const noexcept { return run_count_; }

 private:
  // A direct-mapped cache in front of the maps: points come from a few tiles at a time,
  // often interleaved, and a map lookup per point would cost more than placing it.
  struct TileBuffers {
    std::vector<Key> keys;
    std::vector<std::uint64_t> records;  // with attributes
    TileStat stat;
  };
  struct Slot {
    TileIndex tile;
    TileBuffers* buffers = nullptr;
  };
  Slot& slot_of(const TileIndex& t) {
    Slot& slot = cache_[(TileHash{}(t) >> 24) & (cache_.size() - 1)];
    if (!slot.buffers || slot.tile != t) slot = Slot{t, &tiles_[t]};  // map nodes never move
    return slot;
  }
  // Records are appended chunk by chunk, and a worker takes chunks in increasing order,
  // so they are in sequence order already; sorted here should that ever not hold.
  void in_sequence_order(std::vector<std::uint64_t>& records) const {
    const std::size_t words = 2 + attributes_, n = records.size() / words;
    bool sorted = true;
    for (std::size_t r = 1; r < n && sorted; ++r) sorted = records[r * words + 1] > records[(r - 1) * words + 1];
    if (sorted) return;
    std::vector<std::size_t> order(n);
    for (std::size_t r = 0; r < n; ++r) order[r] = r;
    std::sort(order.begin(), order.end(), [&](std::size_t x, std::size_t y) { return records[x * words + 1] < records[y * words + 1]; });
    std::vector<std::uint64_t> out(records.size());
    for (std::size_t r = 0; r < n; ++r)
      std::copy_n(records.begin() + static_cast<std::ptrdiff_t>(order[r] * words), words, out.begin() + static_cast<std::ptrdiff_t>(r * words));
    records.swap(out);
  }

  std::array<Slot, 256> cache_{};
  const TileGrid& grid_;
  const Locator locator_;
  SpillFile& file_;
  SpillFile* value_file_;  // with attributes
  std::uint32_t file_id_;
  std::uint64_t limit_;
  std::size_t attributes_;
  std::uint64_t held_ = 0;  // words the buffers have room for
  std::uint64_t outside_ = 0, run_count_ = 0;
  std::unordered_map<TileIndex, TileBuffers, TileHash> tiles_;  // nodes never move
  RunMap runs_, value_runs_;
};

// Little-endian-agnostic packing of plain values (all ranks run the same binary).
template <class T>
void put(std::vector<std::uint8_t>& out, const T& v) {
  const auto* b = reinterpret_cast<const std::uint8_t*>(&v);
  out.insert(out.end(), b, b + sizeof v);
}
template <class T>
T take(const std::vector<std::uint8_t>& in, std::size_t& at) {
  if (at + sizeof(T) > in.size()) throw Error("tile statistics message is truncated");
  T v;
  std::memcpy(&v, in.data() + at, sizeof v);
  at += sizeof v;
  return v;
}

double seconds_since(std::chrono::steady_clock::time_point& mark) {
  const auto now = std::chrono::steady_clock::now();
  const double s = std::chrono::duration<double>(now - mark).count();
  mark = now;
  return s;
}

struct BuiltTile {
  std::uint64_t voxels = 0, bytes = 0;
};

// One run of make_tiles on this rank: what its stages share.
struct Tiling {
  Tiling(const TileOptions& o, Communicator& c, unsigned w)
      : options(o), comm(c), workers(w), rank(c.rank()), ranks(c.size()), talk(rank == 0 && static_cast<bool>(o.progress)) {}

  const TileOptions& options;
  Communicator& comm;
  unsigned workers;
  int rank, ranks;
  bool talk;  // this rank reports progress
  std::vector<std::unique_ptr<SpillFile>> files;  // one per worker, the last for runs from other ranks
  std::vector<const SpillFile*> file_views;
  RunMap runs;             // this rank's sorted runs per tile
  // With attributes: the columns every tile gets, and their records' spill files and runs
  // (as for keys).
  std::vector<AttributeSpec> specs;
  std::map<const PointSource*, std::vector<std::size_t>> columns_of;  // spec a -> the source's column
  std::vector<std::unique_ptr<SpillFile>> value_files;
  std::vector<const SpillFile*> value_file_views;
  RunMap value_runs;
  StatMap all_stats;       // every rank's points and bbox per tile
  std::vector<TileIndex> tiles;  // every tile, in order; tile p belongs to rank p % ranks
  TileSummary summary;
  std::chrono::steady_clock::time_point mark = std::chrono::steady_clock::now();
  std::optional<detail::TileGeoref> georef;  // the tiles' and overviews' CRS and lat/lon
  fs::path tile_dir;  // this run's generation folder: tiles and overviews are written there

  int owner(std::size_t position) const { return static_cast<int>(position % static_cast<std::size_t>(ranks)); }
  std::uint64_t per_worker() const { return options.memory_budget / workers; }
  // Keys a k-way merge buffers per run: a quarter of a worker's budget over the runs.
  std::size_t merge_buffer(std::size_t run_count) const {
    return static_cast<std::size_t>(std::clamp<std::uint64_t>(
        per_worker() / 4 / sizeof(Key) / std::max<std::size_t>(run_count, 1), 512, std::uint64_t{1} << 16));
  }
  std::vector<Key> merged(const std::vector<Run>& tile_runs) const {
    return detail::merge_runs(tile_runs, file_views, merge_buffer(tile_runs.size()));
  }
  std::size_t record_words() const { return 2 + specs.size(); }
  // A tile's attribute records in sequence order, each visited once.
  void visit_records(const std::vector<Run>& tile_runs,
                     const std::function<void(const std::uint64_t*, std::size_t)>& visit) const {
    detail::merge_records(tile_runs, value_file_views, record_words(), merge_buffer(tile_runs.size()) / record_words(),
                          visit);
  }
  void reduce_attributes(const TileIndex& t, Tree& tree) const;
  // A chunk's points and its values of `specs`, in their order.
  void read_values(const PointSource& source, std::uint64_t chunk, std::vector<double>& xyz,
                   std::vector<std::vector<double>>& values) const {
    thread_local std::vector<std::vector<double>> all;
    source.read_chunk_with_values(chunk, xyz, all);
    const std::vector<std::size_t>& column = columns_of.at(&source);
    values.resize(column.size());
    for (std::size_t a = 0; a < column.size(); ++a) values[a].swap(all.at(column[a]));
  }

  void bucket(const std::vector<const PointSource*>& sources);
  void share_statistics(const StatMap& stats, std::uint64_t points_read, std::uint64_t outside);
  void exchange();
  std::vector<BuiltTile> build();
  TileIndexFile index(const std::vector<BuiltTile>& built);
};

// 1. Bucket this rank's chunks on all its threads: keys per tile, sorted runs spilled.
void Tiling::bucket(const std::vector<const PointSource*>& sources) {
  const TileGrid& grid = options.grid;
  // Every worker's buffers share 35% of the budget: sorting a buffer needs as much
  // again, and the chunk being read, the maps and the allocator take the rest.
  std::uint64_t limit_words = options.memory_budget * 35 / 100 / workers / sizeof(Key);
  // Attribute records are spilled whole in the end however large the buffers (they are
  // read back in sequence order, not reduced in memory), so buffers beyond a few tens of
  // megabytes only save runs; memory is kept for the build.
  if (!specs.empty()) limit_words = std::min<std::uint64_t>(limit_words, kRecordBufferWords);
  struct SourceChunk {
    const PointSource* source;
    std::uint64_t chunk, global;  // global chunk g -> rank g % ranks
  };
  std::vector<SourceChunk> chunks;
  std::uint64_t global = 0;
  for (const PointSource* s : sources)
    for (std::uint64_t c = 0; c < s->chunk_count(); ++c, ++global)
      if (owner(global) == rank) chunks.push_back({s, c, global});

  std::vector<std::unique_ptr<Bucketer>> bucketers;
  for (unsigned w = 0; w < workers; ++w)
    bucketers.push_back(std::make_unique<Bucketer>(grid, *files[w], specs.empty() ? nullptr : value_files[w].get(), w,
                                                   limit_words, specs.size()));
  std::atomic<std::uint64_t> chunks_done{0}, points_read{0};
  // Worker w fills bucketers[w]; progress is reported by worker 0, the calling thread.
  ParallelOptions bucketing;
  bucketing.threads = workers;
  bucketing.name = "tile.bucket";
  std::vector<std::vector<double>> xyz(workers);
  std::vector<std::vector<std::vector<double>>> values(workers);
  const auto bucket_chunks = [&](const Chunk& chunk) {
    for (std::size_t c = chunk.begin; c < chunk.end; ++c) {
      std::vector<double>& points = xyz[chunk.worker];
      std::vector<std::vector<double>>& point_values = values[chunk.worker];
      if (specs.empty()) chunks[c].source->read_chunk(chunks[c].chunk, points);
      else read_values(*chunks[c].source, chunks[c].chunk, points, point_values);
      if (points.size() / 3 > std::numeric_limits<std::uint32_t>::max())
        throw Error(chunks[c].source->name() + ": a chunk of more than 2^32 points");
      points_read += points.size() / 3;
      // A point's sequence number: its chunk's place among all inputs' chunks, then its
      // place in the chunk: the order of the points whoever reads them.
      bucketers[chunk.worker]->add(points, point_values, chunks[c].global << 32);
      const std::uint64_t done = ++chunks_done;
      if (talk && chunk.worker == 0) options.progress("bucketing points", done, chunks.size());
    }
  };
  parallel_for(chunks.size(), bucket_chunks, bucketing);
  xyz.clear();
  values.clear();
  ParallelOptions flushing;  // every bucketer's last buffer, sorted and spilled
  flushing.threads = workers;
  flushing.chunks = workers;
  flushing.name = "tile.flush";
  const auto flush_bucketer = [&](const Chunk& chunk) { bucketers[chunk.index]->flush(); };
  parallel_for(workers, flush_bucketer, flushing);

  StatMap stats;
  std::uint64_t outside = 0;
  for (const auto& b : bucketers) {
    for (const auto& [t, st] : b->stats()) stats[t].merge(st);
    for (const auto& [t, r] : b->runs()) runs[t].insert(runs[t].end(), r.begin(), r.end());
    for (const auto& [t, r] : b->value_runs()) value_runs[t].insert(value_runs[t].end(), r.begin(), r.end());
    outside += b->outside();
    summary.spill_runs += b->run_count();
  }
  bucketers.clear();
  summary.seconds_bucket = seconds_since(mark);
  share_statistics(stats, points_read.load(), outside);
  // Inputs of points of which none is left (filters that keep none, a crop polygon in
  // another CRS, no finite point) made an empty tile set, exit 0: refused, before the
  // index replaces the previous one.
  std::uint64_t offered = 0;
  for (const PointSource* s : sources) offered += s->point_count();
  if (tiles.empty() && offered == 0 && points_read.load() == 0)
    throw InvalidArgument(
        "the inputs hold no point: nothing to tile (an existing tile set in the output folder is left "
        "as it was)");
  if (tiles.empty()) {
    char size[32];
    std::snprintf(size, sizeof size, "%.6g", options.grid.tile_size);
    throw InvalidArgument("none of the inputs' " + std::to_string(offered) +
                          " points is left to tile: the filters kept none (a crop polygon in another CRS than "
                          "the points'?), none has finite coordinates, or every one lies beyond the 2^31 tiles of " +
                          size + " the grid can index from its origin (a tile size too small for the coordinates)");
  }
}

// 2. Every rank learns every tile's statistics (and so the list of tiles).
void Tiling::share_statistics(const StatMap& stats, std::uint64_t points_read, std::uint64_t outside) {
  std::vector<std::uint8_t> mine;
  put(mine, points_read);
  put(mine, outside);
  for (const auto& [t, st] : stats) {
    put(mine, t);
    put(mine, st.points);
    put(mine, st.bbox);
  }
  for (const auto& message : comm.all_gather(mine)) {
    std::size_t at = 0;
    summary.points_in += take<std::uint64_t>(message, at);
    summary.points_outside += take<std::uint64_t>(message, at);
    while (at < message.size()) {
      const auto t = take<TileIndex>(message, at);
      TileStat st;
      st.points = take<std::uint64_t>(message, at);
      st.bbox = take<Box>(message, at);
      all_stats[t].merge(st);
    }
  }
  for (const auto& [t, st] : all_stats) tiles.push_back(t);
  if (options.max_tiles != 0 && tiles.size() > options.max_tiles) {
    char text[400];
    std::snprintf(text, sizeof text,
                  "the %llu points fall into %zu tiles of %.10g (%.3g points a tile): more than the limit of %llu "
                  "tiles; give a larger tile size (or raise the limit, 0 for none)",
                  static_cast<unsigned long long>(summary.points_in - summary.points_outside), tiles.size(),
                  options.grid.tile_size,
                  static_cast<double>(summary.points_in - summary.points_outside) / static_cast<double>(tiles.size()),
                  static_cast<unsigned long long>(options.max_tiles));
    throw OptionError("max_tiles", text);
  }
  // --memory bounds the buffers, sorts and merges; a tile being built holds its own voxels
  // (about 10 bytes each, 12 more a column: SCALING.md) beyond it. Said when the largest
  // tile's points could need more than the whole budget (it ran silently at 88 MiB under 1M).
  std::uint64_t largest = 0;
  for (const auto& [t, st] : all_stats) largest = std::max(largest, st.points);
  const std::uint64_t need = largest * (10 + 12 * specs.size());
  if (rank == 0 && need > options.memory_budget)
    summary.warnings.push_back("the largest tile holds " + std::to_string(largest) +
                               " points: building it may take up to " + std::to_string(need >> 20) +
                               " MiB beyond --memory's " + std::to_string(options.memory_budget >> 20) +
                               " MiB (which bounds the buffers, sorts and merges); a smaller --tile-size or --depth "
                               "bounds it");
}

// 3. Each tile's keys go to its owner (one gather per tile, all ranks in step).
void Tiling::exchange() {
  if (ranks > 1) {
    const auto received = static_cast<std::uint32_t>(workers);
    for (std::size_t p = 0; p < tiles.size(); ++p) {
      const int root = owner(p);
      std::vector<Key> keys;
      if (root != rank) {
        if (const auto it = runs.find(tiles[p]); it != runs.end()) {
          keys = merged(it->second);
          runs.erase(it);
        }
      }
      auto gathered = comm.gather(root, keys);
      if (root == rank)
        for (int r = 0; r < ranks; ++r)
          if (r != rank && !gathered[r].empty())
            runs[tiles[p]].push_back(Run{received, files[received]->append(gathered[r]), gathered[r].size()});
      if (!specs.empty()) {  // the attribute records, merged into one run in sequence order
        std::vector<std::uint64_t> records;
        if (root != rank) {
          if (const auto it = value_runs.find(tiles[p]); it != value_runs.end()) {
            visit_records(it->second, [&](const std::uint64_t* r, std::size_t n) {
              records.insert(records.end(), r, r + n * record_words());
            });
            value_runs.erase(it);
          }
        }
        auto gathered_records = comm.gather(root, records);
        if (root == rank)
          for (int r = 0; r < ranks; ++r)
            if (r != rank && !gathered_records[r].empty())
              value_runs[tiles[p]].push_back(
                  detail::append_records(*value_files[received], received, gathered_records[r], record_words()));
      }
      if (root != rank) continue;
      if (talk) options.progress("exchanging tiles", p + 1, tiles.size());
    }
  }
  for (const auto& f : files) summary.spill_bytes += f->size();
  for (const auto& f : value_files) summary.spill_bytes += f->size();
  summary.seconds_exchange = seconds_since(mark);
}

// 4. Build and write this rank's tiles; every rank learns every tile's voxels and bytes.
std::vector<BuiltTile> Tiling::build() {
  const TileGrid& grid = options.grid;
  std::vector<std::size_t> owned;
  for (std::size_t p = 0; p < tiles.size(); ++p)
    if (owner(p) == rank) owned.push_back(p);
  std::vector<BuiltTile> built(tiles.size());
  std::atomic<std::size_t> tiles_done{0};
  ParallelOptions building;
  building.threads = workers;
  building.name = "tile.build";
  const auto build_tiles = [&](const Chunk& chunk) {
    for (std::size_t n = chunk.begin; n < chunk.end; ++n) {
      const std::size_t p = owned[n];
      const TileIndex& t = tiles[p];
      std::vector<Key> keys;
      if (const auto it = runs.find(t); it != runs.end()) {
        std::uint64_t total = 0;
        for (const Run& r : it->second) total += r.count;
        const bool one_run = it->second.size() == 1;  // already sorted and unique
        if (!one_run && 2 * total * sizeof(Key) > per_worker()) {
          keys = merged(it->second);
        } else {  // one read (and for many runs a radix sort, which beats a k-way merge)
          keys.resize(total);
          std::size_t at = 0;
          for (const Run& r : it->second) {
            files[r.file]->read(r.offset, std::span<Key>(keys.data() + at, r.count));
            at += r.count;
          }
          if (!one_run) sort_unique(keys, grid.depth);
        }
      }
      Tree tree = build_from_sorted_keys(keys, grid.depth);
      std::vector<Key>().swap(keys);
      reduce_attributes(t, tree);
      tree.set_frame(grid.tile_frame(t));
      georef->apply(tree, all_stats.at(t).bbox);
      const std::string path = (tile_dir / tile_file_name(t)).string();
      write(tree, path);
      built[p] = {tree.voxel_count(), static_cast<std::uint64_t>(fs::file_size(path))};
      const std::size_t done = ++tiles_done;
      if (talk && chunk.worker == 0) options.progress("writing tiles", done, owned.size());
    }
  };
  parallel_for(owned.size(), build_tiles, building);
  files.clear();  // the spill files go as soon as the tiles are written
  file_views.clear();
  value_files.clear();
  value_file_views.clear();
  summary.seconds_build = seconds_since(mark);

  std::vector<std::uint8_t> results;
  for (const std::size_t p : owned) {
    put(results, static_cast<std::uint64_t>(p));
    put(results, built[p]);
  }
  for (const auto& message : comm.all_gather(results)) {
    std::size_t at = 0;
    while (at < message.size()) {
      const auto p = take<std::uint64_t>(message, at);
      if (p >= built.size()) throw Error("tile result message names an unknown tile");
      built[p] = take<BuiltTile>(message, at);
    }
  }
  return built;
}

// The tile's attribute columns: its records reduced into its voxels in sequence order,
// so that a voxel's value does not depend on which worker, run or rank held its points.
void Tiling::reduce_attributes(const TileIndex& t, Tree& tree) const {
  if (specs.empty()) return;
  VoxelReducer reducer(specs, tree.voxel_count());
  if (const auto it = value_runs.find(t); it != value_runs.end()) {
    const std::size_t words = record_words();
    std::vector<std::uint64_t> voxel_ranks;
    // The values are the records' words 2.. (doubles), read in place by the reducer.
    std::vector<RecordField> fields(specs.size());
    for (std::size_t a = 0; a < specs.size(); ++a)
      fields[a] = {.kind = RecordField::Kind::f64,
                   .offset = static_cast<std::uint32_t>((2 + a) * sizeof(std::uint64_t)),
                   .scaled = false};
    visit_records(it->second, [&](const std::uint64_t* records, std::size_t n) {
      voxel_ranks.resize(n);
      for (std::size_t r = 0; r < n; ++r) {
        const std::optional<std::uint64_t> voxel = tree.rank(decode(records[r * words]));
        if (!voxel) throw Error("tile: an attribute record names a voxel the tile does not hold");
        voxel_ranks[r] = *voxel;
      }
      reducer.add_records(voxel_ranks, reinterpret_cast<const std::uint8_t*>(records), words * sizeof(std::uint64_t), {},
                          fields);
    });
  }
  reducer.finish_into(tree);
}

// The tile index (without overviews) and the summary's totals.
TileIndexFile Tiling::index(const std::vector<BuiltTile>& built) {
  TileIndexFile index;
  index.grid = options.grid;
  index.epsg = options.epsg;
  index.crs_wkt = options.crs_wkt;
  index.points_in = summary.points_in;
  index.points_outside = summary.points_outside;
  index.attributes = summary.attributes;
  for (std::size_t p = 0; p < tiles.size(); ++p) {
    TileEntry e;
    e.tile = tiles[p];
    e.file = tile_file_name(tiles[p]);
    e.points = all_stats[tiles[p]].points;
    e.voxels = built[p].voxels;
    e.bytes = built[p].bytes;
    e.bbox = all_stats[tiles[p]].bbox;
    summary.voxels += e.voxels;
    summary.tile_bytes += e.bytes;
    index.tiles.push_back(std::move(e));
  }
  summary.tiles = tiles.size();
  return index;
}

// The attribute columns every source carries (same name, type and reduction), in the
// order the sources name them; a column some source lacks is left out, with a warning.
std::vector<AttributeSpec> common_attributes(const std::vector<const PointSource*>& sources,
                                             std::vector<std::string>& warnings) {
  std::vector<std::vector<AttributeSpec>> of;
  for (const PointSource* s : sources) of.push_back(s->attributes());
  std::vector<AttributeSpec> common;
  std::vector<std::string> seen;
  for (const auto& specs : of)
    for (const AttributeSpec& spec : specs) {
      if (std::find(seen.begin(), seen.end(), spec.name) != seen.end()) continue;
      seen.push_back(spec.name);
      std::size_t lacking = 0;
      while (lacking < of.size() && std::any_of(of[lacking].begin(), of[lacking].end(), [&](const AttributeSpec& o) {
               return o.name == spec.name && o.type == spec.type && o.reduction == spec.reduction;
             }))
        ++lacking;
      if (lacking == of.size()) {
        common.push_back(spec);
        continue;
      }
      // Say what differs: a column of the same name in another type (a PCD's 16-bit
      // intensity read as f32) was reported as missing from the file that has it.
      const auto same_name = std::find_if(of[lacking].begin(), of[lacking].end(),
                                          [&](const AttributeSpec& o) { return o.name == spec.name; });
      if (same_name == of[lacking].end())
        warnings.push_back("attribute '" + spec.name + "' is left out: " + sources[lacking]->name() +
                           " has no such column");
      else
        warnings.push_back("attribute '" + spec.name + "' is left out: " + sources[lacking]->name() + " holds it as " +
                           std::string(name_of(same_name->type)) + " (" + std::string(name_of(same_name->reduction)) +
                           ") where another input holds it as " + std::string(name_of(spec.type)) + " (" +
                           std::string(name_of(spec.reduction)) + "); tiles keep a column every input holds alike");
    }
  return common;
}

// What to tell the user when the tiles' points lie beyond any longitude and latitude under
// a geographic CRS, or nowhere near the earth's surface under a geocentric one (a label
// that is likely wrong): the index can place none of them.
std::string implausible_label(const TileIndexFile& index) {
  if (index.tiles.empty()) return "";
  const std::string crs = !index.crs_wkt.empty() ? index.crs_wkt
                          : index.epsg           ? "EPSG:" + std::to_string(*index.epsg)
                                                 : "";
  Box extent = index.tiles.front().bbox;
  for (const TileEntry& t : index.tiles)
    for (int a = 0; a < 3; ++a) {
      extent.min[a] = std::min(extent.min[a], t.bbox.min[a]);
      extent.max[a] = std::max(extent.max[a], t.bbox.max[a]);
    }
  const std::string label = implausible_degrees(crs, extent.min[0], extent.min[1], extent.max[0], extent.max[1]);
  if (!label.empty())
    return "the points' " + label + "; " + kIndexFileName + " gives tiles beyond them no footprint (a null geometry)";
  const std::string far = implausible_geocentric(crs, extent);
  return far.empty() ? far : far + "; " + kIndexFileName + " gives the tiles no footprint (a null geometry)";
}

// This run's spill folder, removed with its files; its parent too when it is vola's own
// (OUTDIR/.spill, or a --tmp folder this run made) and left empty (other ranks' folders
// keep it).
struct RemovedFolder {
  fs::path dir;
  bool made_parent = false;
  ~RemovedFolder() {
    std::error_code ec;
    fs::remove_all(dir, ec);
    if (made_parent) fs::remove(dir.parent_path(), ec);  // fails, as it should, unless empty
  }
};

}  // namespace

std::size_t chunk_points_for(const TileOptions& options) {
  constexpr std::uint64_t kMost = std::uint64_t{1} << 18, kLeast = 4096, kBytesInFlight = 160;
  if (!options.attributes) return std::uint64_t{1} << 20;
  const std::uint64_t workers = resolve_thread_count(options.threads);
  return static_cast<std::size_t>(std::clamp<std::uint64_t>(options.memory_budget / 4 / workers / kBytesInFlight, kLeast, kMost));
}

TileSummary make_tiles(const std::vector<const PointSource*>& sources, const TileOptions& options,
                       Communicator& comm) {
  const TileGrid& grid = options.grid;
  grid.check();
  if (options.output_dir.empty()) throw OptionError("output_dir", "no output folder given");
  if (options.memory_budget < (std::uint64_t{1} << 20))
    throw OptionError("memory_budget", "must be at least 1 MiB (got " + std::to_string(options.memory_budget) + " bytes)");
  const unsigned workers = resolve_thread_count(options.threads);
  std::error_code error;
  if (fs::exists(options.output_dir, error) && !fs::is_directory(options.output_dir, error))
    throw OptionError("output_dir", options.output_dir +
                                        " is a file, not a folder: give a folder for the tiles and their index (new "
                                        "or one an earlier vola tile wrote)");
  fs::create_directories(options.output_dir);
  const detail::OutputLock lock(options.output_dir, comm);
  const detail::Generation generation = detail::begin_generation(options.output_dir, comm);
  const fs::path spill_root = options.spill_dir.empty() ? fs::path(options.output_dir) / ".spill" : fs::path(options.spill_dir);
  detail::remove_stale_spill(spill_root);
  // Declared before the run, so that the spill files close before their folder goes, on
  // every exit but a kill (which the next run's remove_stale_spill covers).
  std::error_code absent;
  const RemovedFolder spill{spill_root / detail::spill_folder_name(comm.rank()),
                            options.spill_dir.empty() || !fs::exists(spill_root, absent)};
  fs::create_directories(spill.dir);
  Tiling run(options, comm, workers);
  run.tile_dir = generation.dir();
  for (unsigned w = 0; w <= workers; ++w)
    run.files.push_back(std::make_unique<SpillFile>((spill.dir / ("worker-" + std::to_string(w) + ".keys")).string()));
  for (const auto& f : run.files) run.file_views.push_back(f.get());
  if (options.attributes) run.specs = common_attributes(sources, run.summary.warnings);
  for (const PointSource* source : sources) {
    const std::vector<AttributeSpec> own = source->attributes();
    for (const AttributeSpec& spec : run.specs)
      run.columns_of[source].push_back(static_cast<std::size_t>(
          std::find_if(own.begin(), own.end(), [&](const AttributeSpec& o) { return o.name == spec.name; }) - own.begin()));
  }
  if (!run.specs.empty())
    for (unsigned w = 0; w <= workers; ++w)
      run.value_files.push_back(
          std::make_unique<SpillFile>((spill.dir / ("worker-" + std::to_string(w) + ".values")).string()));
  for (const auto& f : run.value_files) run.value_file_views.push_back(f.get());
  for (const AttributeSpec& spec : run.specs) run.summary.attributes.push_back(spec.name);
  run.georef.emplace(options.epsg, options.crs_wkt);

  run.bucket(sources);
  run.exchange();
  const std::vector<BuiltTile> built = run.build();
  TileIndexFile index = run.index(built);
  TileSummary& summary = run.summary;

  // 5. The overview pyramid, level by level (each level reads the one below).
  if (options.overviews) {
    comm.barrier();  // every rank's tiles are on disk
    const OverviewContext context{grid, generation.dir().string(), *run.georef, workers};
    index.overviews = build_overviews(index.tiles, context, comm, options.progress);
    summary.overview_files = index.overviews.size();
    summary.seconds_overviews = seconds_since(run.mark);
  }
  // Files were named inside the generation folder; the index lives one level up.
  for (TileEntry& t : index.tiles) t.file = generation.name + "/" + t.file;
  for (OverviewEntry& o : index.overviews) o.file = generation.name + "/" + o.file;
  if (run.rank == 0) {
    if (const std::string label = implausible_label(index); !label.empty()) summary.warnings.push_back(label);
    if (summary.points_outside > 0)  // a warning, so that -q says it too
      summary.warnings.push_back(std::to_string(summary.points_outside) + " of the " +
                                 std::to_string(summary.points_in) +
                                 " points are not tiled: a coordinate not finite, or beyond the 2^31 tiles the grid "
                                 "indexes from its origin");
    summary.index_path = (fs::path(options.output_dir) / kIndexFileName).string();
    write_tile_index(index, summary.index_path);  // the switch: whole, by rename
  }
  comm.barrier();
  if (run.rank == 0) detail::retire_previous(generation);
  return summary;
}

}  // namespace vola::tile
