// LasReader over LAZ: the point records of a compressed file, decoded chunk by chunk
// with vola's own codec (vola/io/laz.hpp). Chunks are independent, so a batch of them
// (one per core) is read and decoded at once, and read_records() hands the records out
// in file order, exactly as from an uncompressed file: every reader of records (the
// attribute columns, the streaming builder, export) works on LAZ unchanged.
#include <algorithm>
#include <limits>

#include "vola/error.hpp"
#include "vola/io/las.hpp"
#include "vola/parallel.hpp"

namespace vola::io {

namespace {

// The decoded bytes of one chunk a file can justify: a chunk's records may not exceed
// 1 GiB unless its compressed bytes are at least 1/4096 of them (LASzip compresses
// a record to a few bytes; only a lying chunk table claims more), so that a small file
// never makes the reader allocate gigabytes.
void check_chunk_size(const std::string& path, const LasHeader& hd, std::size_t chunk) {
  const laz::ChunkEntry& c = hd.laz_chunks[chunk];
  // A compressor 1 file is one chunk of the header's 64-bit point count, whose bytes
  // may not even fit 64 bits.
  const bool overflows = c.point_count > std::numeric_limits<std::uint64_t>::max() / hd.record_length;
  const std::uint64_t bytes = overflows ? std::numeric_limits<std::uint64_t>::max() : c.point_count * hd.record_length;
  if (bytes > (std::uint64_t{1} << 30) && bytes / 4096 > c.byte_size)
    throw FormatError(path, c.byte_offset,
                      "LAZ chunk " + std::to_string(chunk) + " claims " + std::to_string(c.point_count) +
                          " points from " + std::to_string(c.byte_size) + " compressed bytes: more than the file can hold");
}

}  // namespace

void LasReader::decode_laz_chunk(std::size_t chunk, std::vector<std::uint8_t>& records, bool coordinates_only) const {
  const LasHeader& hd = header_;
  if (chunk >= hd.laz_chunks.size()) throw InvalidArgument(path_ + ": no LAZ chunk " + std::to_string(chunk));
  check_chunk_size(path_, hd, chunk);
  const laz::ChunkEntry& c = hd.laz_chunks[chunk];
  std::vector<std::uint8_t> compressed(static_cast<std::size_t>(c.byte_size));
  try {
    fetch(c.byte_offset, c.byte_size, compressed.data());
  } catch (const FormatError&) {
    throw FormatError(path_, c.byte_offset, "cannot read LAZ chunk " + std::to_string(chunk) + " (truncated file)");
  }
  records.resize(static_cast<std::size_t>(c.point_count) * hd.record_length);
  laz::decode_chunk(*hd.laszip, compressed, c.point_count, records.data(), hd.record_length, chunk, c.byte_offset,
                    path_, coordinates_only);
}

void LasReader::select_copc_nodes(const std::optional<Box>& region, std::optional<int> max_level) {
  const LasHeader& hd = header_;
  if (max_level && !hd.copc)
    throw InvalidArgument(path_ + ": a level of detail needs a COPC file (an octree of chunks); this one is not");
  settle_laz_prefetch();  // the batch decoded ahead reads chunk_order_
  chunk_order_.clear();
  points_total_ = 0;
  copc_level_ = max_level;
  kept_points_ = 0;  // records kept were another selection's
  kept_complete_ = false;
  std::vector<std::uint64_t> wanted;  // byte offsets of the selected nodes' chunks
  if (hd.copc)
    for (const CopcNode& node : hd.copc->nodes) {
      if (max_level && node.level > *max_level) continue;
      if (region) {
        const Box cube = hd.copc->bounds(node);
        bool meets = true;
        for (int a = 0; a < 3; ++a) meets = meets && cube.min[a] <= region->max[a] && cube.max[a] >= region->min[a];
        if (!meets) continue;
      }
      wanted.push_back(node.offset);
    }
  std::sort(wanted.begin(), wanted.end());
  for (std::size_t c = 0; c < hd.laz_chunks.size(); ++c) {
    if (hd.copc && !std::binary_search(wanted.begin(), wanted.end(), hd.laz_chunks[c].byte_offset)) continue;
    chunk_order_.push_back(c);
    points_total_ += hd.laz_chunks[c].point_count;
  }
  rewind();
}

// Chunks chunk_order_[begin ...] (one per thread, one at least) decoded into `batch`, in
// parallel (the file is read with pread, or lies in memory). The buffers are
// reused from batch to batch: no fresh pages to fault in and zero for every chunk.
void LasReader::decode_laz_batch(LazBatch& batch, std::size_t begin) const {
  const std::size_t threads = thread_count();
  batch.first = begin;
  batch.count = std::min(chunk_order_.size() - begin, threads);
  if (batch.records.size() < batch.count) batch.records.resize(batch.count);
  ParallelOptions options;
  options.threads = static_cast<unsigned>(threads);
  options.name = "las.decode_laz";
  parallel_for(
      batch.count,
      [&](const Chunk& chunk) {
        decode_laz_chunk(chunk_order_[begin + chunk.index], batch.records[chunk.index], coordinates_only_);
      },
      options);
}

// Waits for the batch being decoded ahead, if any; its error is dropped (a rewind or
// the end of the reader makes it moot).
void LasReader::settle_laz_prefetch() noexcept {
  if (!prefetch_.valid()) return;
  try {
    prefetch_.get();
  } catch (...) {
  }
}

// Records of the current batch's chunks in order; when they run out, the batch decoded
// ahead (on other threads, while the caller worked on these records) takes its place
// and the one after it starts decoding.
std::span<const std::uint8_t> LasReader::read_laz_records(std::size_t max_points) {
  const std::size_t length = header_.record_length;
  for (;;) {
    if (batch_chunk_ < current_.count) {
      const std::vector<std::uint8_t>& records = current_.records[batch_chunk_];
      const std::uint64_t points = records.size() / length;
      if (batch_point_ < points) {
        const auto n = static_cast<std::size_t>(std::min<std::uint64_t>(max_points, points - batch_point_));
        const std::span<const std::uint8_t> out(records.data() + batch_point_ * length, n * length);
        batch_point_ += n;
        next_ += n;
        return out;
      }
      ++batch_chunk_;
      batch_point_ = 0;
      continue;
    }
    const std::size_t begin = current_.first + current_.count;
    if (begin >= chunk_order_.size()) return {};
    if (prefetch_.valid()) {
      prefetch_.get();  // rethrows the ahead batch's error, in order
      std::swap(current_, ahead_);
    } else {
      decode_laz_batch(current_, begin);
    }
    batch_chunk_ = 0;
    batch_point_ = 0;
    const std::size_t after = current_.first + current_.count;
    if (after < chunk_order_.size())
      prefetch_ = std::async(std::launch::async, [this, after] { decode_laz_batch(ahead_, after); });
  }
}

}  // namespace vola::io
