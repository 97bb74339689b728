#include "spill.hpp"

#include <fcntl.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstring>
#include <queue>

#include "vola/error.hpp"

namespace vola::tile::detail {

SpillFile::SpillFile(std::string path) : path_(std::move(path)) {
  fd_ = ::open(path_.c_str(), O_RDWR | O_CREAT | O_TRUNC | O_CLOEXEC, 0600);
  if (fd_ < 0) throw IoError(path_ + ": cannot create spill file (" + std::strerror(errno) + ")");
}

SpillFile::~SpillFile() {
  if (fd_ >= 0) {
    ::close(fd_);
    ::unlink(path_.c_str());
  }
}

std::uint64_t SpillFile::append(std::span<const Key> keys) {
  const std::uint64_t start = end_;
  const auto* bytes = reinterpret_cast<const char*>(keys.data());
  std::size_t left = keys.size_bytes();
  while (left > 0) {
    const ssize_t n = ::pwrite(fd_, bytes, left, static_cast<off_t>(end_));
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0)
      throw IoError(path_ + ": byte " + std::to_string(end_) + ": cannot write spill data (" +
                    std::strerror(n < 0 ? errno : ENOSPC) + ")");
    bytes += n;
    left -= static_cast<std::size_t>(n);
    end_ += static_cast<std::uint64_t>(n);
  }
  return start;
}

void SpillFile::read(std::uint64_t offset, std::span<Key> out) const {
  auto* bytes = reinterpret_cast<char*>(out.data());
  std::size_t left = out.size_bytes();
  while (left > 0) {
    const ssize_t n = ::pread(fd_, bytes, left, static_cast<off_t>(offset));
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0)
      throw IoError(path_ + ": byte " + std::to_string(offset) + ": cannot read spill data back (" +
                    (n < 0 ? std::strerror(errno) : "file shorter than written") + ")");
    bytes += n;
    left -= static_cast<std::size_t>(n);
    offset += static_cast<std::uint64_t>(n);
  }
}

namespace {

// One run read through a small buffer.
struct RunCursor {
  const SpillFile* file;
  std::uint64_t next_offset;
  std::uint64_t left;  // keys not yet loaded
  std::vector<Key> buffer;
  std::size_t at = 0;

  bool refill() {
    if (left == 0) return false;
    const std::size_t n = static_cast<std::size_t>(std::min<std::uint64_t>(left, buffer.capacity()));
    buffer.resize(n);
    file->read(next_offset, buffer);
    next_offset += n * sizeof(Key);
    left -= n;
    at = 0;
    return true;
  }
  Key key() const { return buffer[at]; }
  bool advance() { return ++at < buffer.size() || refill(); }
};

}  // namespace

std::vector<Key> merge_runs(std::span<const Run> runs, std::span<const SpillFile* const> files,
                            std::size_t buffer_keys) {
  std::vector<RunCursor> cursors;
  cursors.reserve(runs.size());
  for (const Run& r : runs) {
    if (r.count == 0) continue;
    RunCursor c{files[r.file], r.offset, r.count, {}, 0};
    c.buffer.reserve(std::max<std::size_t>(1, buffer_keys));
    c.refill();
    cursors.push_back(std::move(c));
  }
  using Entry = std::pair<Key, std::size_t>;  // key, cursor
  std::priority_queue<Entry, std::vector<Entry>, std::greater<>> heap;
  for (std::size_t i = 0; i < cursors.size(); ++i) heap.emplace(cursors[i].key(), i);
  std::vector<Key> out;
  while (!heap.empty()) {
    const auto [key, i] = heap.top();
    heap.pop();
    if (out.empty() || out.back() != key) out.push_back(key);
    if (cursors[i].advance()) heap.emplace(cursors[i].key(), i);
  }
  return out;
}

void merge_records(std::span<const Run> runs, std::span<const SpillFile* const> files, std::size_t words,
                   std::size_t buffer_records, const std::function<void(const std::uint64_t*)>& visit) {
  struct Cursor {
    const SpillFile* file;
    std::uint64_t next_offset, left;  // records not yet loaded
    std::vector<std::uint64_t> buffer;
    std::size_t at = 0, loaded = 0;  // records
  };
  const std::size_t per_buffer = std::max<std::size_t>(1, buffer_records);
  std::vector<Cursor> cursors;
  const auto refill = [&](Cursor& c) {
    if (c.left == 0) return false;
    c.loaded = static_cast<std::size_t>(std::min<std::uint64_t>(c.left, per_buffer));
    c.buffer.resize(c.loaded * words);
    c.file->read(c.next_offset, c.buffer);
    c.next_offset += c.loaded * words * sizeof(std::uint64_t);
    c.left -= c.loaded;
    c.at = 0;
    return true;
  };
  for (const Run& r : runs) {
    if (r.count == 0) continue;
    cursors.push_back(Cursor{files[r.file], r.offset, r.count, {}, 0, 0});
    refill(cursors.back());
  }
  using Entry = std::pair<std::uint64_t, std::size_t>;  // sequence number, cursor
  std::priority_queue<Entry, std::vector<Entry>, std::greater<>> heap;
  for (std::size_t i = 0; i < cursors.size(); ++i) heap.emplace(cursors[i].buffer[1], i);
  while (!heap.empty()) {
    const std::size_t i = heap.top().second;
    heap.pop();
    // Every record of this run below the other runs' next one goes out at once: runs
    // interleave by whole chunks, not by record, so the heap works once per stretch.
    const std::uint64_t others = heap.empty() ? ~std::uint64_t{0} : heap.top().first;
    Cursor& c = cursors[i];
    bool more = true;
    do {
      visit(c.buffer.data() + c.at * words);
      more = ++c.at < c.loaded || refill(c);
    } while (more && c.buffer[c.at * words + 1] < others);
    if (more) heap.emplace(c.buffer[c.at * words + 1], i);
  }
}

}  // namespace vola::tile::detail
