// Internal: a read-only memory map of a whole file (POSIX), kept alive by shared_ptr
// from the trees that view it.
//
// A map reads the file as it is now, not as it was opened: when another process cuts
// the file (truncate, or an editor rewriting it in place), a read of a page past the
// new end raises SIGBUS, which by default ends the process. Every mapping is therefore
// listed in a fixed, lock-free table, and a SIGBUS handler (installed by the first
// open, chained to whatever handler was there before) that finds the faulting address
// in one of them replaces that whole mapping with zero pages and marks it lost: the
// read that faulted is restarted and reads 0, and every later read too. lost() then
// says so, and check_mapped() (vola/file.hpp) turns it into an IoError naming the file.
// A fault outside our mappings goes to the previous handler (or the default action).
// When the table is full the file is read into memory instead: no mapping, nothing
// to lose.
//
// A file rewritten in place with as many bytes or more (`cp other.vol mapped.vol`
// truncates it, then writes) raises no SIGBUS unless a read falls in the moment it is
// short: the mapping then shows the other file's bytes under this file's decoded
// structure. rewritten_at() looks for that by the file's size and modification time
// (each time, or at most once a millisecond per mapping for callers that run once per
// point) and treats a rewritten mapping as a cut one: zero pages, lost.
#pragma once

#include <cstdint>
#include <memory>
#include <span>
#include <string>
#include <vector>

#include "vola/version.hpp"

namespace vola {
VOLA_INLINE_NAMESPACE_BEGIN
namespace detail {

class MappedFile {
 public:
  // Throws IoError naming the path when the file cannot be opened or mapped.
  static std::shared_ptr<const MappedFile> open(const std::string& path);
  // Reads the whole file into memory (pread): for callers that copy what they read
  // anyway, so that a file cut meanwhile is a short read, never a lost page.
  static std::shared_ptr<const MappedFile> load(const std::string& path);
  // The mapping holding `address` if the file was cut under it (its pages are zeros
  // now), else null (also for addresses in no mapping).
  static const MappedFile* lost_at(const void* address) noexcept;
  // The mapping holding `address` if its file now has another size or modification time
  // than when it was mapped (under the same path and inode: a file renamed over the path
  // leaves this mapping's file whole); that mapping is then lost, as a cut one. Null
  // otherwise; with `at_most_every_millisecond`, also when the last such look at this
  // mapping is less than a millisecond old.
  static const MappedFile* rewritten_at(const void* address, bool at_most_every_millisecond) noexcept;
  ~MappedFile();
  MappedFile(const MappedFile&) = delete;
  MappedFile& operator=(const MappedFile&) = delete;

  std::span<const std::uint8_t> bytes() const noexcept { return {data_, size_}; }
  const std::string& path() const noexcept { return path_; }
  // False when the bytes are a copy: load(), or open() past the table of live mappings.
  bool is_mapping() const noexcept { return slot_ >= 0; }

 private:
  MappedFile() = default;
  const std::uint8_t* data_ = nullptr;
  std::size_t size_ = 0;
  int slot_ = -1;                   // in the table of live mappings, or -1 (not mapped)
  // The file as it was mapped, to tell a rewrite in place (rewritten_at).
  std::uint64_t device_ = 0, inode_ = 0;
  std::int64_t file_size_ = 0, modified_ns_ = 0;
  std::vector<std::uint8_t> copy_;  // the bytes, when not mapped
  std::string path_;
};

}  // namespace detail
VOLA_INLINE_NAMESPACE_END
}  // namespace vola
