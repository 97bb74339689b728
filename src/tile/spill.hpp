// Internal: runs of sorted unique keys spilled to one file per worker, and read back.
#pragma once

#include <cstdint>
#include <functional>
#include <span>
#include <string>
#include <vector>

#include "vola/key.hpp"

namespace vola::tile::detail {

struct Run {
  std::uint32_t file = 0;    // which spill file
  std::uint64_t offset = 0;  // byte offset of the first key (or record)
  std::uint64_t count = 0;   // keys (or records)
  // Attribute records: how each value is stored, 2 bits per column (see append_records);
  // 0: every value as its 8-byte double.
  std::uint64_t packing = 0;
};

// An append-only file of keys; positional reads may run on other threads at once.
class SpillFile {
 public:
  explicit SpillFile(std::string path);
  ~SpillFile();
  SpillFile(const SpillFile&) = delete;
  SpillFile& operator=(const SpillFile&) = delete;

  // Appends keys; returns the byte offset they start at. Throws IoError (file, offset) on failure.
  std::uint64_t append(std::span<const Key> keys);
  std::uint64_t append_bytes(std::span<const std::byte> bytes);
  void read(std::uint64_t offset, std::span<Key> out) const;
  void read_bytes(std::uint64_t offset, std::span<std::byte> out) const;
  std::uint64_t size() const noexcept { return end_; }
  const std::string& path() const noexcept { return path_; }

 private:
  std::string path_;
  int fd_ = -1;
  std::uint64_t end_ = 0;
};

// Attribute records (`words` words each, as below) appended as one run, each value column
// stored in the narrowest of u8, u16, f32 and f64 that gives every value of the run back
// bit for bit (LAS colours, intensity and classes take 1-2 bytes, not 8).
Run append_records(SpillFile& file, std::uint32_t file_id, std::span<const std::uint64_t> records, std::size_t words);

// Runs of attribute records: `words` words each (the voxel key in its tile, the point's
// sequence number, then one value per attribute as the bits of a double), each run
// sorted by sequence number. visit(records, n) sees every record of the runs in sequence
// order, n consecutive ones at a time (one k-way merge, each run read through a buffer of
// `buffer_records` records), so that the values reduce in the order the points came,
// whoever read them.
void merge_records(std::span<const Run> runs, std::span<const SpillFile* const> files, std::size_t words,
                   std::size_t buffer_records, const std::function<void(const std::uint64_t*, std::size_t)>& visit);

// Sorted unique keys of many sorted unique runs (one k-way merge), reading each run
// through a buffer of `buffer_keys` keys.
std::vector<Key> merge_runs(std::span<const Run> runs, std::span<const SpillFile* const> files,
                            std::size_t buffer_keys);

}  // namespace vola::tile::detail
