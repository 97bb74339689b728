// The streaming LAS conversion (build_las): chunks of records into a StreamBuilder, keys
// straight from the stored integers where the grid allows, the points' bounds without
// decoding a coordinate, and one pass instead of two when the header's box can be
// trusted. Attribute columns: that occupancy tree first, then one more pass over the
// records that reduces each point into its voxel's partials in place (VoxelReducer).
#include <algorithm>
#include <array>
#include <bit>
#include <cmath>
#include <limits>
#include <new>
#include <optional>

#if defined(__linux__)
#include <sys/mman.h>
#endif

#include "vola/error.hpp"
#include "vola/io/las.hpp"
#include "vola/little_endian.hpp"
#include "vola/parallel.hpp"
#include "vola/stream_builder.hpp"
#include "vola/voxel_reducer.hpp"

namespace vola::io {

namespace {

// x y z of each record, appended to xyz.
void decode_xyz(const LasHeader& hd, std::span<const std::uint8_t> records, std::vector<double>& xyz) {
  const std::size_t length = hd.record_length, n = records.size() / length;
  const std::size_t at = xyz.size();
  xyz.resize(at + 3 * n);
  double* out = xyz.data() + at;
  const std::uint8_t* r = records.data();
  for (std::size_t i = 0; i < n; ++i, r += length, out += 3) {
    out[0] = static_cast<double>(load_le<std::int32_t>(r)) * hd.scale[0] + hd.offset[0];
    out[1] = static_cast<double>(load_le<std::int32_t>(r + 4)) * hd.scale[1] + hd.offset[1];
    out[2] = static_cast<double>(load_le<std::int32_t>(r + 8)) * hd.scale[2] + hd.offset[2];
  }
}

// Points in a batch of records that stays in cache (LasReader::read_records).
std::size_t batch_points(const LasHeader& hd) { return std::max<std::size_t>(1, kLasRecordBatchBytes / hd.record_length); }

// The next chunk of up to chunk_points points, decoded into xyz (replaced); the points read.
std::size_t read_xyz(LasReader& reader, std::size_t chunk_points, std::vector<double>& xyz) {
  const LasHeader& hd = reader.header();
  xyz.clear();
  const std::size_t batch = batch_points(hd);
  std::size_t done = 0;
  while (done < chunk_points) {
    const std::span<const std::uint8_t> records = reader.read_records(std::min(batch, chunk_points - done));
    if (records.empty()) break;
    decode_xyz(hd, records, xyz);
    done += records.size() / hd.record_length;
  }
  return done;
}

// The bounds of the decoded coordinates, from the rest of the file. x * scale + offset
// is monotonic in the stored integer x (rounding keeps the order; a negative scale
// reverses it), so the extremes of the integers decode to the extremes of the
// coordinates: no point is decoded. A scale or offset that is not finite could make
// NaN, which the comparisons of the decoded path skip: such files take that path.
Box las_bounds(LasReader& reader, std::size_t chunk_points, std::int32_t stored_lo[3], std::int32_t stored_hi[3],
               const std::function<void(std::uint64_t)>& progress) {
  const LasHeader& hd = reader.header();
  constexpr double inf = std::numeric_limits<double>::infinity();
  Box box{{inf, inf, inf}, {-inf, -inf, -inf}};
  bool finite = true;
  for (int a = 0; a < 3; ++a) finite = finite && std::isfinite(hd.scale[a]) && std::isfinite(hd.offset[a]);
  std::int32_t lo[3], hi[3];
  for (int a = 0; a < 3; ++a) {
    lo[a] = std::numeric_limits<std::int32_t>::max();
    hi[a] = std::numeric_limits<std::int32_t>::min();
  }
  std::vector<double> xyz;
  const std::size_t length = hd.record_length, batch = batch_points(hd);
  std::uint64_t reported = 0;
  while (true) {
    const std::span<const std::uint8_t> records = reader.read_records(batch);
    if (records.empty()) break;
    if (finite) {
      std::int32_t l0 = lo[0], l1 = lo[1], l2 = lo[2], h0 = hi[0], h1 = hi[1], h2 = hi[2];
      for (const std::uint8_t* r = records.data(); r < records.data() + records.size(); r += length) {
        const std::int32_t x = load_le<std::int32_t>(r), y = load_le<std::int32_t>(r + 4), z = load_le<std::int32_t>(r + 8);
        l0 = std::min(l0, x), h0 = std::max(h0, x);
        l1 = std::min(l1, y), h1 = std::max(h1, y);
        l2 = std::min(l2, z), h2 = std::max(h2, z);
      }
      lo[0] = l0, lo[1] = l1, lo[2] = l2, hi[0] = h0, hi[1] = h1, hi[2] = h2;
    } else {
      xyz.clear();
      decode_xyz(hd, records, xyz);
      for (std::size_t i = 0; i < xyz.size(); ++i) {
        box.min[i % 3] = std::min(box.min[i % 3], xyz[i]);
        box.max[i % 3] = std::max(box.max[i % 3], xyz[i]);
      }
    }
    if (reader.points_read() - reported >= chunk_points || reader.points_read() == reader.points_total()) {
      reported = reader.points_read();
      progress(reported);
    }
  }
  if (reader.points_read() == 0) return Box{};
  if (finite)
    for (int a = 0; a < 3; ++a) {
      stored_lo[a] = lo[a];
      stored_hi[a] = hi[a];
      const double from_lo = static_cast<double>(lo[a]) * hd.scale[a] + hd.offset[a];
      const double from_hi = static_cast<double>(hi[a]) * hd.scale[a] + hd.offset[a];
      box.min[a] = std::min(from_lo, from_hi);
      box.max[a] = std::max(from_lo, from_hi);
    }
  return box;
}

// The stored integer of one axis -> its voxel's key bits, exactly as decoding the
// coordinate (x * scale + offset, as decode_xyz does) and quantizing it
// (Quantizer::to_voxel) would give, without either per point. Both steps are
// monotonic in the stored integer x (for a positive scale: rounding keeps the order),
// so the cells form runs of consecutive integers: `lower[i]` is the smallest stored
// integer of cell i, found once per cell with the exact decode + to_voxel. Per point,
// one multiply guesses the cell and one or two comparisons correct the guess.
class AxisCells {
 public:
  static constexpr Key kOutside = Key{1} << 63;
  // Cells in [lo, hi], the stored integers of this axis that can occur. False (use the
  // decoded path) when the mapping is not monotonic non-decreasing and finite, or the
  // range spans too many cells for a table.
  bool build(const LasHeader& hd, const Quantizer& quantizer, int axis, std::int64_t lo, std::int64_t hi) {
    const double scale = hd.scale[axis], offset = hd.offset[axis];
    if (!(scale > 0.0) || !std::isfinite(scale) || !std::isfinite(offset)) return false;
    axis_ = axis;
    hd_ = &hd;
    quantizer_ = &quantizer;
    // The other axes at a point known to be inside, so to_voxel speaks of this axis only.
    inside_ = quantizer.center(Voxel{0, 0, 0});
    Voxel v;
    if (!quantizer.to_voxel(inside_, v) || v != Voxel{0, 0, 0}) return false;
    side_ = side_of(quantizer.depth());
    origin_ = quantizer.frame().origin[axis];
    if (!std::isfinite(decode(lo)) || !std::isfinite(decode(hi))) return false;
    const std::int64_t first = cell(lo), last = cell(hi);
    if (first > last || last - first >= kMaxCells) return false;
    const std::size_t cells = static_cast<std::size_t>(last - first + 1);
    lower_.assign(cells + 1, 0);
    key_.assign(cells, 0);
    lower_[0] = std::numeric_limits<std::int64_t>::min();
    lower_[cells] = std::numeric_limits<std::int64_t>::max();
    std::int64_t from = lo, width = 0;
    for (std::size_t i = 1; i < cells; ++i) {
      const std::int64_t at = first_at_least(first + static_cast<std::int64_t>(i), from, hi, from + width);
      if (i >= 2) width = at - from;
      lower_[i] = from = at;
    }
    for (std::size_t i = 0; i < cells; ++i) {
      const std::int64_t c = first + static_cast<std::int64_t>(i);
      key_[i] = c < 0 || c >= side_ ? kOutside : detail::spread(static_cast<std::uint32_t>(c)) << (2 * axis);
    }
    // The guess: cell 1 starts at lower_[1], cells are (lower_[last] - lower_[1]) / (cells - 2) wide.
    base_ = cells >= 2 ? lower_[1] : 0;
    slope_ = cells >= 3 && lower_[cells - 1] > lower_[1]
                 ? static_cast<double>(cells - 2) / static_cast<double>(lower_[cells - 1] - lower_[1])
                 : 0.0;
    last_ = static_cast<std::int64_t>(cells) - 1;
    // Check the guess-and-correct lookup against the exact mapping at every border.
    for (std::size_t i = 1; i < cells; ++i)
      for (const std::int64_t x : {lower_[i] - 1, lower_[i]})
        if (x >= lo && x <= hi && key(static_cast<std::int32_t>(x)) != exact_key(x)) return false;
    return true;
  }

  // The table by value, for a hot loop (locals that no store can alias).
  struct Lookup {
    const std::int64_t* lower;
    const Key* key;
    std::int64_t base, last;
    double slope;
    Key operator()(std::int32_t x) const noexcept {
      std::int64_t i = 1 + static_cast<std::int64_t>(static_cast<double>(x - base) * slope);
      i = std::clamp<std::int64_t>(i, 0, last);
      while (x < lower[i]) --i;
      while (x >= lower[i + 1]) ++i;
      return key[i];
    }
  };
  Lookup lookup() const noexcept { return {lower_.data(), key_.data(), base_, last_, slope_}; }
  Key key(std::int32_t x) const noexcept { return lookup()(x); }

 private:
  static constexpr std::int64_t kMaxCells = std::int64_t{1} << 21;

  double decode(std::int64_t x) const noexcept {
    return static_cast<double>(static_cast<std::int32_t>(x)) * hd_->scale[axis_] + hd_->offset[axis_];
  }
  // The cell of stored integer x: -1 below a grid, side above it.
  std::int64_t cell(std::int64_t x) const noexcept {
    Point p = inside_;
    p[axis_] = decode(x);
    Voxel v;
    if (quantizer_->to_voxel(p, v)) return axis_ == 0 ? v.x : axis_ == 1 ? v.y : v.z;
    return p[axis_] < origin_ ? -1 : static_cast<std::int64_t>(side_);
  }
  Key exact_key(std::int64_t x) const noexcept {
    const std::int64_t c = cell(x);
    return c < 0 || c >= side_ ? kOutside : detail::spread(static_cast<std::uint32_t>(c)) << (2 * axis_);
  }
  // The smallest x in [from, to] whose cell is at least c (cell(to) >= c, cell(from - 1) < c).
  std::int64_t first_at_least(std::int64_t c, std::int64_t from, std::int64_t to, std::int64_t guess) const {
    std::int64_t below = from - 1, above = to;  // cell(below) < c <= cell(above)
    guess = std::clamp(guess, from, to);
    std::int64_t step = 1;
    if (cell(guess) >= c) {
      above = guess;
      while (above - step > below) {
        if (cell(above - step) < c) {
          below = above - step;
          break;
        }
        above -= step;
        step *= 2;
      }
    } else {
      below = guess;
      while (below + step < above) {
        if (cell(below + step) >= c) {
          above = below + step;
          break;
        }
        below += step;
        step *= 2;
      }
    }
    while (above - below > 1) {
      const std::int64_t mid = below + (above - below) / 2;
      (cell(mid) >= c ? above : below) = mid;
    }
    return above;
  }

  int axis_ = 0;
  const LasHeader* hd_ = nullptr;
  const Quantizer* quantizer_ = nullptr;
  Point inside_{};
  std::int64_t side_ = 0;
  double origin_ = 0.0;
  std::vector<std::int64_t> lower_;
  std::vector<Key> key_;
  std::int64_t base_ = 0, last_ = 0;
  double slope_ = 0.0;
};

// The streamed tree with its bbox and EPSG code in the header, and what went into it.
Tree finish_tree(StreamBuilder& builder, const Box& bbox, std::uint32_t epsg, BuildReport* report) {
  Tree tree = builder.finish();
  tree.georef().bbox = bbox;
  tree.georef().epsg = epsg;
  BuildReport::of(report, builder.points_in(), builder.points_outside(), tree);
  return tree;
}

// The next chunk of up to chunk_points records -> voxel keys -> the builder, the
// records read in batches that stay in cache. With kRange, also widens [lo, hi], the
// range of stored integers per axis. Returns the points read (0 at the end).
template <bool kRange>
std::size_t add_chunk(LasReader& reader, StreamBuilder& builder, std::size_t chunk_points, const AxisCells (&cells)[3],
                      std::int32_t lo[3], std::int32_t hi[3]) {
  const LasHeader& hd = reader.header();
  const std::size_t length = hd.record_length;
  const std::size_t n =
      static_cast<std::size_t>(std::min<std::uint64_t>(chunk_points, reader.points_total() - reader.points_read()));
  if (n == 0) return 0;
  const std::size_t batch = batch_points(hd);
  const AxisCells::Lookup kx = cells[0].lookup(), ky = cells[1].lookup(), kz = cells[2].lookup();
  Key* out = builder.key_scratch(n).data();
  std::size_t kept = 0, done = 0;
  std::int32_t l0 = lo[0], l1 = lo[1], l2 = lo[2], h0 = hi[0], h1 = hi[1], h2 = hi[2];
  while (done < n) {
    const std::span<const std::uint8_t> records = reader.read_records(std::min(batch, n - done));
    const std::size_t m = records.size() / length;
    if (m == 0) break;
    const std::uint8_t* r = records.data();
    for (std::size_t i = 0; i < m; ++i, r += length) {
      const std::int32_t x = load_le<std::int32_t>(r), y = load_le<std::int32_t>(r + 4), z = load_le<std::int32_t>(r + 8);
      if constexpr (kRange) {
        l0 = std::min(l0, x), h0 = std::max(h0, x);
        l1 = std::min(l1, y), h1 = std::max(h1, y);
        l2 = std::min(l2, z), h2 = std::max(h2, z);
      }
      const Key key = kx(x) | ky(y) | kz(z);
      out[kept] = key;
      kept += (key >> 63) ^ 1;  // AxisCells::kOutside: the point is outside the grid
    }
    done += m;
  }
  if constexpr (kRange) lo[0] = l0, lo[1] = l1, lo[2] = l2, hi[0] = h0, hi[1] = h1, hi[2] = h2;
  builder.add_keys(std::span<Key>(out, kept), done - kept);
  return done;
}

// The box of the decoded coordinates from the range of stored integers (as las_bounds).
Box decoded_box(const LasHeader& hd, const std::int32_t lo[3], const std::int32_t hi[3]) {
  Box box;
  for (int a = 0; a < 3; ++a) {
    const double from_lo = static_cast<double>(lo[a]) * hd.scale[a] + hd.offset[a];
    const double from_hi = static_cast<double>(hi[a]) * hd.scale[a] + hd.offset[a];
    box.min[a] = std::min(from_lo, from_hi);
    box.max[a] = std::max(from_lo, from_hi);
  }
  return box;
}

// Occupancy only, bbox not given: one pass instead of two. The grid is resolved from
// the header's bounds and the points' bounds are taken on the way; when the grid the
// points' bounds resolve to is the same grid (the usual case: a toolkit grid needs the
// same box, a grid-mode one only the same origin, voxel size and depth), the tree is
// what two passes would build. Otherwise nothing is returned and `bounds`, `lo`, `hi`
// hold the points' bounds, so the caller needs only its second pass.
std::optional<Tree> occupancy_in_one_pass(LasReader& reader, const BuildOptions& options, BuildReport* report,
                                          const std::function<void(std::uint64_t, std::uint64_t)>& progress,
                                          std::size_t chunk_points, std::optional<Box>& bounds, std::int32_t lo[3],
                                          std::int32_t hi[3], std::optional<Quantizer>& used) {
  const LasHeader& hd = reader.header();
  if (reader.points_total() == 0) return std::nullopt;
  const Box header_box{hd.min, hd.max};
  for (int a = 0; a < 3; ++a)
    if (!(std::isfinite(hd.min[a]) && std::isfinite(hd.max[a]) && hd.min[a] <= hd.max[a])) return std::nullopt;
  std::optional<Quantizer> quantizer;
  try {
    quantizer = resolve_quantizer(header_box, options);
  } catch (const Error&) {
    return std::nullopt;  // a header box no grid fits: the two-pass path says what is wrong
  }
  AxisCells cells[3];
  for (int a = 0; a < 3; ++a)
    if (!cells[a].build(hd, *quantizer, a, std::numeric_limits<std::int32_t>::min(),
                        std::numeric_limits<std::int32_t>::max()))
      return std::nullopt;
  StreamBuilder builder(*quantizer, {}, false);
  for (int a = 0; a < 3; ++a) {
    lo[a] = std::numeric_limits<std::int32_t>::max();
    hi[a] = std::numeric_limits<std::int32_t>::min();
  }
  reader.rewind();
  while (add_chunk<true>(reader, builder, chunk_points, cells, lo, hi) > 0) {
    if (progress) progress(reader.points_read(), reader.points_total());
    // A point well outside the header's box: the header is stale, stop guessing at once.
    // (Writers that round the header's bounds differently from the stored integers put
    // points a step or so outside it; the grid usually comes out the same.)
    const Box so_far = decoded_box(hd, lo, hi);
    for (int a = 0; a < 3; ++a) {
      const double slack = 2.0 * hd.scale[a];
      if (so_far.min[a] < header_box.min[a] - slack || so_far.max[a] > header_box.max[a] + slack) return std::nullopt;
    }
  }
  const Box box = decoded_box(hd, lo, hi);
  const Quantizer resolved = resolve_quantizer(box, options);
  const bool same = resolved.depth() == quantizer->depth() &&
                    (options.quantization == Quantization::toolkit ? box == header_box
                                                                   : resolved.frame() == quantizer->frame());
  if (!same) {
    bounds = box;
    return std::nullopt;
  }
  used = quantizer;
  return finish_tree(builder, box, options.epsg, report);
}

}  // namespace

namespace {

// COPC in grid mode with a given bbox: the grid is known before any point is read, and a
// node whose cube misses it holds only points the grid drops, so it is never read.
void skip_copc_nodes_outside_the_grid(LasReader& reader, const BuildOptions& requested) {
  if (!reader.header().copc) return;
  if (const std::optional<Box> region = grid_region(requested)) reader.select_copc_nodes(region, reader.copc_level());
}

}  // namespace

namespace {

// The tree through a StreamBuilder: occupancy (keys from the stored integers where the
// grid allows), or with attribute columns and payloads reduced per chunk and merged
// (the path of payloads). `used` gets the grid the keys were made on and stored_lo/hi
// a range holding every stored integer (the points' own when a pass saw them).
// While alive, a LAZ reader decodes only the coordinates of layered chunks
// (LasReader::set_coordinates_only): the passes that need nothing else.
class CoordinatesOnly {
 public:
  CoordinatesOnly(LasReader& reader, bool on) : reader_(reader) { reader_.set_coordinates_only(on); }
  ~CoordinatesOnly() { reader_.set_coordinates_only(false); }
  CoordinatesOnly(const CoordinatesOnly&) = delete;
  CoordinatesOnly& operator=(const CoordinatesOnly&) = delete;

 private:
  LasReader& reader_;
};

Tree build_streamed(LasReader& reader, const BuildOptions& requested, bool attributes, bool payload,
                    BuildReport* report, const std::function<void(std::uint64_t, std::uint64_t)>& progress,
                    std::size_t chunk_points, std::optional<Quantizer>& used, std::int32_t stored_lo[3],
                    std::int32_t stored_hi[3]) {
  BuildOptions options = requested;  // the bbox is filled in from the points when not given
  const LasHeader& hd = reader.header();
  skip_copc_nodes_outside_the_grid(reader, requested);
  LasChunk chunk;
  const bool occupancy_only = !attributes && !payload;
  const CoordinatesOnly coordinates_only(reader, occupancy_only);
  // Keys are 8 bytes a point; decoded coordinates (the path without key tables) 24.
  const std::size_t decoded_chunk = chunk_points == 0 ? kLasChunkPoints : chunk_points;
  if (chunk_points == 0) chunk_points = occupancy_only ? kLasKeyChunkPoints : kLasChunkPoints;
  for (int a = 0; a < 3; ++a) {
    stored_lo[a] = std::numeric_limits<std::int32_t>::min();
    stored_hi[a] = std::numeric_limits<std::int32_t>::max();
  }
  if (occupancy_only && !options.bbox) {
    std::optional<Box> bounds;
    std::int32_t lo[3], hi[3];
    if (std::optional<Tree> tree =
            occupancy_in_one_pass(reader, options, report, progress, chunk_points, bounds, lo, hi, used)) {
      std::copy(lo, lo + 3, stored_lo);
      std::copy(hi, hi + 3, stored_hi);
      return std::move(*tree);
    }
    if (bounds) {  // the pass above took the points' bounds: only the second pass is left
      options.bbox = bounds;
      std::copy(lo, lo + 3, stored_lo);
      std::copy(hi, hi + 3, stored_hi);
    }
  }
  const std::uint64_t passes = options.bbox ? 1 : 2;
  // Pass 1: the points' bounds, as the reference takes them (the header's may be stale).
  if (!options.bbox) {
    reader.rewind();
    reader.set_coordinates_only(true);
    options.bbox = las_bounds(reader, chunk_points, stored_lo, stored_hi, [&](std::uint64_t done) {
      if (progress) progress(done, passes * reader.points_total());
    });
    reader.set_coordinates_only(occupancy_only);
  }
  const Quantizer quantizer = resolve_quantizer(*options.bbox, options);
  used = quantizer;
  std::vector<AttributeSpec> specs = attributes ? las_attributes(hd) : std::vector<AttributeSpec>{};
  StreamBuilder builder(quantizer, specs, payload);
  if (!occupancy_only) builder.expect_points(reader.points_total());
  std::vector<std::vector<double>> values;
  std::vector<std::span<const double>> views;
  std::vector<std::uint64_t> payloads;
  std::vector<double> xyz;  // occupancy only: coordinates decoded straight from the records
  // Occupancy only: keys straight from the stored integers (AxisCells), over the range
  // of stored integers the bounds pass saw (or any int32 when the bbox was given).
  AxisCells cells[3];
  bool by_table = occupancy_only && reader.points_total() > 0;
  for (int a = 0; a < 3 && by_table; ++a)
    by_table = cells[a].build(hd, quantizer, a, stored_lo[a], stored_hi[a]);
  reader.rewind();
  while (by_table && add_chunk<false>(reader, builder, chunk_points, cells, stored_lo, stored_hi) > 0) {
    if (progress) progress((passes - 1) * reader.points_total() + reader.points_read(), passes * reader.points_total());
  }
  while (!by_table) {
    if (occupancy_only) {
      if (read_xyz(reader, decoded_chunk, xyz) == 0) break;
      builder.add(xyz, {}, {});
    } else {
      if (reader.read(chunk, chunk_points) == 0) break;
      if (attributes) las_attribute_values(hd, chunk, values);
      views.assign(values.begin(), values.end());
      if (payload) las_payloads(hd, chunk, payloads);
      builder.add(chunk.xyz, views, payload ? std::span<const std::uint64_t>(payloads) : std::span<const std::uint64_t>{});
    }
    if (progress) progress((passes - 1) * reader.points_total() + reader.points_read(), passes * reader.points_total());
  }
  // The chunk buffers (~100 bytes a point with attributes) are not needed by the final
  // merges, which are the peak of the conversion.
  chunk = LasChunk{};
  values = {};
  views = {};
  payloads = {};
  xyz = {};
  return finish_tree(builder, *options.bbox, options.epsg, report);
}

// Rank of voxel keys in a tree: per level, each word with the number of set bits before
// it, side by side (one cache line per level and key, not two), on transparent huge
// pages (a random walk over tens of megabytes of 4 KiB pages missed the TLB at every
// level). A batch of keys is walked a level at a time: the loads of one level are
// independent, so their cache misses overlap (the points of a survey come in no
// spatial order).
class RankWalk {
 public:
  explicit RankWalk(const Tree& tree) : depth_(tree.depth()) {
    std::size_t total = 0;
    for (int l = 0; l < depth_; ++l) total += tree.occupancy(l).size();
    entries_ = Entries(total);
    Entry* e = entries_.data();
    for (int l = 0; l < depth_; ++l) {
      const std::span<const std::uint64_t> words = tree.occupancy(l);
      level_[l] = e;
      std::uint64_t count = 0;
      for (const std::uint64_t w : words) {
        *e++ = Entry{w, count};
        count += static_cast<std::uint64_t>(std::popcount(w));
      }
    }
  }
  // ranks[j]: the rank of keys[j]'s voxel. False when a voxel is not in the tree.
  bool operator()(const Key* keys, std::size_t n, std::uint64_t* ranks) const noexcept {
    std::fill(ranks, ranks + n, 0);
    std::uint64_t present = 1;
    for (int l = 0; l < depth_; ++l) {
      const Entry* level = level_[l];
      const int shift = 6 * (depth_ - 1 - l);
      const Entry* below = l + 1 < depth_ ? level_[l + 1] : nullptr;
      for (std::size_t j = 0; j < n; ++j) {
        const Entry& e = level[ranks[j]];
        const unsigned bit = static_cast<unsigned>(keys[j] >> shift) & 63u;
        present &= e.word >> bit;
        ranks[j] = e.before + static_cast<std::uint64_t>(std::popcount(e.word & ((std::uint64_t{1} << bit) - 1)));
        // The next level's entry, requested now: that level's loop finds it in cache.
        if (below) __builtin_prefetch(below + ranks[j]);
      }
      if (!(present & 1u)) return false;  // (and later levels would read past a level's words)
    }
    return true;
  }

 private:
  struct alignas(16) Entry {
    std::uint64_t word, before;
  };
  // Entries of a large tree on 2 MiB-aligned memory advised as huge pages (Linux); a
  // small tree's on the heap (a huge page would make a small file's conversion 2 MiB
  // larger than its table).
  class Entries {
   public:
    Entries() = default;
    explicit Entries(std::size_t n) : bytes_(n * sizeof(Entry)) {
      if (n == 0) return;
      if (bytes_ < 2 * kHuge) {
        data_ = static_cast<Entry*>(::operator new(bytes_, std::align_val_t{alignof(Entry)}));
        return;
      }
      bytes_ = (bytes_ + kHuge - 1) / kHuge * kHuge;
      data_ = static_cast<Entry*>(::operator new(bytes_, std::align_val_t{kHuge}));
#ifdef MADV_HUGEPAGE
      ::madvise(data_, bytes_, MADV_HUGEPAGE);
#endif
    }
    ~Entries() {
      if (data_) ::operator delete(data_, std::align_val_t{bytes_ < 2 * kHuge ? alignof(Entry) : kHuge});
    }
    Entries(const Entries&) = delete;
    Entries& operator=(Entries&& o) noexcept {
      std::swap(data_, o.data_);
      std::swap(bytes_, o.bytes_);
      return *this;
    }
    Entry* data() const noexcept { return data_; }

   private:
    static constexpr std::size_t kHuge = std::size_t{2} << 20;
    Entry* data_ = nullptr;
    std::size_t bytes_ = 0;
  };
  int depth_;
  Entries entries_;
  std::array<const Entry*, kMaxDepth> level_{};
};

// The voxels dealt to the threads of the second pass: blocks of 2^bits consecutive
// ranks (2^16, fewer for a small tree so that every thread gets some), block g to part
// g % parts, each part's blocks side by side in its own VoxelReducer (local ranks).
// Dealt by blocks, each part gets about as many points and rows as the others wherever
// the points are dense, and the columns can be written a few blocks of every part at a
// time (finish_parts).
struct RankParts {
  int bits = 16;
  std::uint64_t block = 0, voxels = 0;
  unsigned parts = 1;
  std::vector<std::uint32_t> part;   // per block
  std::vector<std::uint64_t> local;  // per block: the local rank of its first voxel
  std::vector<std::uint64_t> size;   // per part: its voxels

  RankParts(std::uint64_t voxel_count, unsigned threads) : voxels(voxel_count) {
    while (bits > 6 && (voxels >> bits) < std::uint64_t{8} * threads) --bits;
    block = std::uint64_t{1} << bits;
    const std::uint64_t blocks = (voxels + block - 1) / block;
    parts = static_cast<unsigned>(std::clamp<std::uint64_t>(blocks, 1, threads));
    part.resize(blocks);
    local.resize(blocks);
    size.assign(parts, 0);
    for (std::uint64_t g = 0; g < blocks; ++g) {
      part[g] = static_cast<std::uint32_t>(g % parts);
      local[g] = g / parts * block;
      size[g % parts] += std::min(block, voxels - g * block);
    }
  }
  std::uint64_t blocks() const noexcept { return part.size(); }
};

// Ask the kernel for the pages wholly inside [from, to), written (zeroed) now on this
// thread, so the thread that then writes them does not fault on each (Linux 5.14+; a
// no-op elsewhere or when refused).
void populate(std::byte* from, std::byte* to) noexcept {
#if defined(__linux__)
#ifndef MADV_POPULATE_WRITE
#define MADV_POPULATE_WRITE 23
#endif
  constexpr std::uintptr_t kPage = 4096;
  const std::uintptr_t a = (reinterpret_cast<std::uintptr_t>(from) + kPage - 1) / kPage * kPage;
  const std::uintptr_t b = reinterpret_cast<std::uintptr_t>(to) / kPage * kPage;
  if (b > a) ::madvise(reinterpret_cast<void*>(a), b - a, MADV_POPULATE_WRITE);
#else
  (void)from, (void)to;
#endif
}

// The parts' columns into the tree, written in rounds of a few blocks of every part:
// the columns grow (on this thread) by a round, then every part writes its blocks of it
// on its own thread and releases the rows it read, so rows and columns are never both
// whole in memory. Each part also has the kernel supply (zero) the pages of its blocks
// of the next round, so that first touch is shared by the threads as well.
void finish_parts(std::vector<VoxelReducer>& reducers, const RankParts& parts, const std::vector<AttributeSpec>& specs,
                  Tree& tree) {
  const std::size_t na = specs.size();
  std::vector<std::vector<std::byte>> bytes(na);
  std::vector<std::size_t> size(na);
  for (std::size_t a = 0; a < na; ++a) {
    size[a] = size_of(specs[a].type);
    bytes[a].reserve(static_cast<std::size_t>(parts.voxels) * size[a]);  // address space only
  }
  // Blocks per round: 4 of every part, or more for a large tree (at most ~32 rounds).
  const std::uint64_t round =
      std::max<std::uint64_t>(4, (parts.blocks() + 32 * parts.parts - 1) / (32 * parts.parts)) * parts.parts;
  const auto blocks_of = [&](std::uint64_t r, unsigned k, const auto& each) {
    for (std::uint64_t g = r * round + k; g < std::min(parts.blocks(), (r + 1) * round); g += parts.parts)
      each(g, std::min(parts.voxels, (g + 1) * parts.block));
  };
  for (std::uint64_t r = 0; r * round < parts.blocks(); ++r) {
    const std::uint64_t end = std::min(parts.voxels, (r + 1) * round * parts.block);
    for (std::size_t a = 0; a < na; ++a) bytes[a].resize(static_cast<std::size_t>(end) * size[a]);
    parallel_for(
        parts.parts,
        [&](const Chunk& c) {
          const auto k = static_cast<unsigned>(c.index);
          std::vector<std::byte*> to(na);
          blocks_of(r, k, [&](std::uint64_t g, std::uint64_t last) {
            const std::uint64_t first = g * parts.block;
            for (std::size_t a = 0; a < na; ++a) to[a] = bytes[a].data() + first * size[a];
            reducers[k].finish_range(parts.local[g], parts.local[g] + (last - first), to);
          });
          blocks_of(r + 1, k, [&](std::uint64_t g, std::uint64_t last) {
            for (std::size_t a = 0; a < na; ++a)
              populate(bytes[a].data() + g * parts.block * size[a], bytes[a].data() + last * size[a]);
          });
        },
        {.threads = parts.parts, .chunks = parts.parts, .name = "las.attributes.finish"});
  }
  reducers.clear();
  for (std::size_t a = 0; a < na; ++a)
    tree.attributes().add(AttributeColumn(specs[a].name, specs[a].type, specs[a].reduction, std::move(bytes[a])));
}

// The second pass: every record again, its voxel's rank in the tree of the first, and
// its attribute values straight from the record bytes into a VoxelReducer, which
// updates each voxel's partials in place. Points fold in input order: the columns are
// vola::build's over the same points, bit for bit.
//
// On T threads (vola::thread_count()) the voxels are dealt to T parts (RankParts), one
// VoxelReducer each. The records come in groups read once (a LAZ chunk is decoded
// once); the threads first find the group's ranks, a slice each, then every thread
// takes the group's points whose voxel is in its part, in input order. Each voxel's
// points still fold in input order in one reducer, so the columns are the same bytes
// whatever the threads; the fresh rows' first touch, the row updates and the finish are
// shared by the threads.
void reduce_attributes(LasReader& reader, const Quantizer& quantizer, const std::int32_t stored_lo[3],
                       const std::int32_t stored_hi[3], Tree& tree,
                       const std::function<void(std::uint64_t)>& progress) {
  const LasHeader& hd = reader.header();
  const std::vector<AttributeSpec> specs = las_attributes(hd);
  std::vector<RecordField> fields;
  const bool by_fields = las_record_fields(hd, fields);
  const RankParts parts(tree.voxel_count(), thread_count());
  std::vector<VoxelReducer> reducers;
  for (unsigned k = 0; k < parts.parts; ++k) reducers.emplace_back(specs, parts.size[k]);
  AxisCells cells[3];
  bool by_table = reader.points_total() > 0;
  for (int a = 0; a < 3 && by_table; ++a) by_table = cells[a].build(hd, quantizer, a, stored_lo[a], stored_hi[a]);
  const AxisCells::Lookup kx = cells[0].lookup(), ky = cells[1].lookup(), kz = cells[2].lookup();
  std::optional<RankWalk> walk(std::in_place, tree);
  const std::size_t length = hd.record_length, batch = batch_points(hd);
  // Records read at once: few enough to cost little memory, enough that the threads
  // meet (twice a group) rarely.
  const std::size_t group = parts.parts == 1 ? batch : std::max<std::size_t>(batch, (std::size_t{8} << 20) / length);
  std::vector<std::uint8_t> copy;                  // a group gathered from several reads (LAZ)
  struct Slice {  // per slice of a group (one a thread): its points of each part
    std::vector<std::vector<std::uint32_t>> index;  // in the group
    std::vector<std::vector<std::uint64_t>> ranks;  // local to the part
  };
  std::vector<Slice> slices(parts.parts, Slice{std::vector<std::vector<std::uint32_t>>(parts.parts),
                                               std::vector<std::vector<std::uint64_t>>(parts.parts)});
  struct Scratch {                                 // per thread
    std::vector<Key> keys;
    std::vector<std::uint32_t> index;
    std::vector<std::uint64_t> ranks;
    std::vector<double> xyz;
    std::vector<std::vector<double>> values;
    std::vector<std::span<const double>> views;
  };
  std::vector<Scratch> scratch(parts.parts);
  std::uint64_t reported = 0;
  reader.rewind();
  while (true) {
    std::span<const std::uint8_t> records = reader.read_records(group);
    if (records.empty()) break;
    if (records.size() < group * length && reader.points_read() < reader.points_total()) {
      copy.assign(records.begin(), records.end());
      while (copy.size() < group * length) {
        const std::span<const std::uint8_t> more = reader.read_records(group - copy.size() / length);
        if (more.empty()) break;
        copy.insert(copy.end(), more.begin(), more.end());
      }
      records = copy;
    }
    const std::size_t m = records.size() / length;
    for (Slice& slice : slices)
      for (unsigned k = 0; k < parts.parts; ++k) slice.index[k].clear(), slice.ranks[k].clear();
    // The ranks, a slice of records per thread, walked in groups of 512 keys whose words
    // and counts stay in L1/L2 between levels.
    parallel_for(
        m,
        [&](const Chunk& c) {
          Scratch& s = scratch[c.worker];
          constexpr std::size_t kGroup = 512;
          for (std::size_t from = c.begin; from < c.end; from += batch) {
            const std::size_t n = std::min(batch, c.end - from);
            const std::uint8_t* r = records.data() + from * length;
            s.keys.clear();
            s.index.clear();
            if (by_table) {
              s.keys.resize(n);
              s.index.resize(n);
              std::size_t kept = 0;
              for (std::size_t i = 0; i < n; ++i, r += length) {
                const Key key =
                    kx(load_le<std::int32_t>(r)) | ky(load_le<std::int32_t>(r + 4)) | kz(load_le<std::int32_t>(r + 8));
                s.keys[kept] = key;
                s.index[kept] = static_cast<std::uint32_t>(i);
                kept += (key >> 63) ^ 1;  // AxisCells::kOutside: the point is outside the grid
              }
              s.keys.resize(kept);
              s.index.resize(kept);
            } else {
              s.xyz.clear();
              decode_xyz(hd, records.subspan(from * length, n * length), s.xyz);
              quantizer.to_keys(s.xyz, s.keys, &s.index);
            }
            const std::size_t kept = s.keys.size();
            s.ranks.resize(kept);
            for (std::size_t at = 0; at < kept; at += kGroup)
              if (!(*walk)(s.keys.data() + at, std::min(kGroup, kept - at), s.ranks.data() + at))
                VOLA_THROW(Error("LAS attributes: a point's voxel is not in the tree of the first pass (" +
                                 reader.path() + ")"));
            // Each point to its part's list, in input order.
            Slice& slice = slices[c.index];
            for (std::size_t j = 0; j < kept; ++j) {
              const std::uint64_t rank = s.ranks[j], g = rank >> parts.bits;
              const std::uint32_t k = parts.part[g];
              slice.index[k].push_back(static_cast<std::uint32_t>(from + s.index[j]));
              slice.ranks[k].push_back(parts.local[g] | (rank & (parts.block - 1)));
            }
          }
        },
        {.threads = parts.parts, .chunks = parts.parts, .name = "las.attributes.ranks"});
    // Every part's points of the group, slice after slice (input order), into its reducer.
    parallel_for(
        parts.parts,
        [&](const Chunk& c) {
          const auto k = static_cast<std::uint32_t>(c.index);
          Scratch& s = scratch[c.worker];
          for (const Slice& slice : slices) {
            const std::vector<std::uint32_t>& index = slice.index[k];
            const std::vector<std::uint64_t>& local = slice.ranks[k];
            if (by_fields) {  // the values straight from the records into the rows
              reducers[k].add_records(local, records.data(), length, index, fields);
              continue;
            }
            for (std::size_t from = 0; from < index.size(); from += batch) {
              const std::size_t n = std::min(batch, index.size() - from);
              las_record_attribute_values(hd, records.data(), std::span(index).subspan(from, n), s.values);
              s.views.assign(s.values.begin(), s.values.end());
              reducers[k].add(std::span(local).subspan(from, n), s.views);
            }
          }
        },
        {.threads = parts.parts, .chunks = parts.parts, .name = "las.attributes.reduce"});
    if (progress && (reader.points_read() - reported >= kLasChunkPoints || reader.points_read() == reader.points_total())) {
      reported = reader.points_read();
      progress(reported);
    }
  }
  walk.reset();
  copy = {};
  slices = {};
  scratch = {};
  finish_parts(reducers, parts, specs, tree);
}

}  // namespace

// Payloads: one streamed pass (or two) through the StreamBuilder, attributes with them.
// Otherwise occupancy first, then, with attributes, a second pass over the records
// into the voxels now known (reduce_attributes).
Tree build_las(LasReader& reader, const BuildOptions& requested, bool attributes, bool payload, BuildReport* report,
               const std::function<void(std::uint64_t, std::uint64_t)>& progress, std::size_t chunk_points) {
  std::optional<Quantizer> used;
  std::int32_t lo[3], hi[3];
  if (payload || !attributes)
    return build_streamed(reader, requested, attributes, payload, report, progress, chunk_points, used, lo, hi);
  // A LAZ file is read twice or three times (bounds, occupancy, attributes): its records
  // are decoded once and kept in a temporary file for the other passes.
  reader.keep_decoded_records();
  // The attribute pass is one more over the points: progress counts it after the others.
  const std::uint64_t total = reader.points_total();
  std::uint64_t before = 0;
  Tree tree = build_streamed(
      reader, requested, false, false, report,
      [&](std::uint64_t done, std::uint64_t of) {
        before = of;
        if (progress) progress(done, of + total);
      },
      chunk_points, used, lo, hi);
  if (!used) return tree;
  reduce_attributes(reader, *used, lo, hi, tree, [&](std::uint64_t done) {
    if (progress) progress(before + done, before + total);
  });
  return tree;
}

}  // namespace vola::io

