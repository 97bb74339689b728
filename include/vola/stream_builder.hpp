// Building a tree from points that arrive in chunks, in memory bounded by the number
// of distinct voxels rather than the number of points: each chunk is sorted and
// reduced to one record per voxel at once, and the reduced runs are merged like a
// binary counter (a run merges with the previous one when it has grown as large), so
// every voxel record is merged O(log chunks) times.
//
// The result equals vola::build over all the points at once with the same quantizer:
// the same voxels, the same attribute values for every reduction (majorities from
// exact counts; means from sums and counts, equal up to the order of floating-point
// summation), and the same payloads (the last point of a voxel in input order wins, as
// the reference's dict does).
#pragma once

#include <cstdint>
#include <memory>
#include <span>
#include <vector>

#include "vola/attributes.hpp"
#include "vola/builder.hpp"
#include "vola/frame.hpp"
#include "vola/tree.hpp"
#include "vola/version.hpp"

namespace vola {
VOLA_INLINE_NAMESPACE_BEGIN

struct AttributeSpec {
  std::string name;
  ValueType type = ValueType::f32;
  Reduction reduction = Reduction::mean;
};

class StreamBuilder {
 public:
  StreamBuilder(const Quantizer& quantizer, std::vector<AttributeSpec> attributes, bool payload);
  ~StreamBuilder();
  StreamBuilder(StreamBuilder&&) noexcept;
  StreamBuilder& operator=(StreamBuilder&&) noexcept;

  // One chunk: xyz holds 3 values per point; values[a] one value per point for
  // attribute a (in the order given to the constructor); payloads one word per point
  // when building payloads (else empty).
  void add(std::span<const double> xyz, std::span<const std::span<const double>> values,
           std::span<const std::uint64_t> payloads);
  // Occupancy only (no attributes, no payloads): one chunk as voxel keys already
  // quantized (any order, duplicates allowed, each below 2^(6 depth)); `outside` counts
  // the chunk's points that fell outside the grid. The keys are sorted in place (their
  // order afterwards is unspecified). Cheaper than add(): no coordinates, one sort of
  // only the key bits that vary within the chunk, no allocation per chunk but the run.
  void add_keys(std::span<Key> keys, std::uint64_t outside = 0);
  // A buffer of n keys owned by the builder, reused from chunk to chunk (valid until the
  // next call), to fill and hand to add_keys.
  std::span<Key> key_scratch(std::size_t n);
  // A hint (a LAS header's point count, say): about `points` points will be added. With
  // attributes or payloads the first run then reserves room for that many voxels in
  // each column (address space only: pages are touched as written), so the merges into
  // it never move its columns to fresh memory (up to 2^27 voxels; larger runs grow as
  // they go). Any count is safe; 0 is no hint.
  void expect_points(std::uint64_t points) noexcept;
  // All chunks added: the tree (frame set from the quantizer; georef left to the caller).
  Tree finish();

  std::uint64_t points_in() const noexcept;
  std::uint64_t points_outside() const noexcept;
  // Bytes held by the reduced runs now (the memory bound: ~ voxels, not points).
  std::size_t memory_bytes() const noexcept;

 private:
  struct State;
  std::unique_ptr<State> state_;
};

VOLA_INLINE_NAMESPACE_END
}  // namespace vola
