#include "spill.hpp"

#include <fcntl.h>
#include <unistd.h>

#include <algorithm>
#include <bit>
#include <cmath>
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

std::uint64_t SpillFile::append(std::span<const Key> keys) { return append_bytes(std::as_bytes(keys)); }

std::uint64_t SpillFile::append_bytes(std::span<const std::byte> data) {
  const std::uint64_t start = end_;
  const auto* bytes = reinterpret_cast<const char*>(data.data());
  std::size_t left = data.size();
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

void SpillFile::read(std::uint64_t offset, std::span<Key> out) const { read_bytes(offset, std::as_writable_bytes(out)); }

void SpillFile::read_bytes(std::uint64_t offset, std::span<std::byte> out) const {
  auto* bytes = reinterpret_cast<char*>(out.data());
  std::size_t left = out.size();
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

namespace {

enum Packed : unsigned { kF64 = 0, kF32 = 1, kU16 = 2, kU8 = 3 };
constexpr std::size_t kPackedColumns = 32;  // 2 bits each in Run::packing; later columns stay f64

unsigned packed_kind(std::uint64_t packing, std::size_t a) {
  return a < kPackedColumns ? static_cast<unsigned>(packing >> (2 * a)) & 3u : kF64;
}
std::size_t packed_width(unsigned kind) { return kind == kF64 ? 8 : kind == kF32 ? 4 : kind == kU16 ? 2 : 1; }

// The narrowest kind that gives `bits` back exactly (the double's own bits: -0, NaN payloads).
unsigned narrowest(std::uint64_t bits) {
  const double v = std::bit_cast<double>(bits);
  if (v >= 0.0 && v <= 65535.0 && v == std::floor(v) && !std::signbit(v)) return v <= 255.0 ? kU8 : kU16;
  return std::bit_cast<std::uint64_t>(static_cast<double>(static_cast<float>(v))) == bits ? kF32 : kF64;
}
// Which kind holds both: the order f64 > f32 > u16 > u8 is by what they hold, except
// that f32 holds every u16 and u8 too.
unsigned wider(unsigned a, unsigned b) {
  if (a == b) return a;
  if (a == kF64 || b == kF64) return kF64;
  if (a == kF32 || b == kF32) return kF32;
  return kU16;  // u8 and u16
}

std::size_t record_bytes(std::uint64_t packing, std::size_t words) {
  std::size_t bytes = 16;
  for (std::size_t a = 0; a + 2 < words; ++a) bytes += packed_width(packed_kind(packing, a));
  return bytes;
}

// One packed record back into `words` words.
void unpack(const std::byte* in, std::uint64_t packing, std::size_t words, std::uint64_t* out) {
  std::memcpy(out, in, 16);
  in += 16;
  for (std::size_t a = 0; a + 2 < words; ++a) {
    const unsigned kind = packed_kind(packing, a);
    double v = 0.0;
    if (kind == kF64) {
      std::memcpy(&v, in, 8);
    } else if (kind == kF32) {
      float f;
      std::memcpy(&f, in, 4);
      v = f;
    } else if (kind == kU16) {
      std::uint16_t u;
      std::memcpy(&u, in, 2);
      v = u;
    } else {
      v = static_cast<std::uint8_t>(*in);
    }
    in += packed_width(kind);
    out[2 + a] = std::bit_cast<std::uint64_t>(v);
  }
}

}  // namespace

Run append_records(SpillFile& file, std::uint32_t file_id, std::span<const std::uint64_t> records, std::size_t words) {
  const std::size_t n = records.size() / words;
  std::uint64_t packing = 0;
  for (std::size_t a = 0; a + 2 < words && a < kPackedColumns; ++a) {
    unsigned kind = kU8;
    for (std::size_t r = 0; r < n && kind != kF64; ++r) kind = wider(kind, narrowest(records[r * words + 2 + a]));
    packing |= std::uint64_t{kind} << (2 * a);
  }
  const std::size_t bytes = record_bytes(packing, words);
  std::vector<std::byte> packed(n * bytes);
  std::byte* out = packed.data();
  for (std::size_t r = 0; r < n; ++r) {
    const std::uint64_t* record = records.data() + r * words;
    std::memcpy(out, record, 16);
    out += 16;
    for (std::size_t a = 0; a + 2 < words; ++a) {
      const unsigned kind = packed_kind(packing, a);
      const double v = std::bit_cast<double>(record[2 + a]);
      if (kind == kF64) {
        std::memcpy(out, &record[2 + a], 8);
      } else if (kind == kF32) {
        const float f = static_cast<float>(v);
        std::memcpy(out, &f, 4);
      } else if (kind == kU16) {
        const auto u = static_cast<std::uint16_t>(v);
        std::memcpy(out, &u, 2);
      } else {
        *out = static_cast<std::byte>(static_cast<std::uint8_t>(v));
      }
      out += packed_width(kind);
    }
  }
  return Run{file_id, file.append_bytes(packed), n, packing};
}

void merge_records(std::span<const Run> runs, std::span<const SpillFile* const> files, std::size_t words,
                   std::size_t buffer_records, const std::function<void(const std::uint64_t*, std::size_t)>& visit) {
  struct Cursor {
    const Run* run;
    std::uint64_t next_offset, left;  // records not yet loaded
    std::vector<std::byte> packed;
    std::vector<std::uint64_t> buffer;  // unpacked
    std::size_t at = 0, loaded = 0;     // records
  };
  const std::size_t per_buffer = std::max<std::size_t>(1, buffer_records);
  std::vector<Cursor> cursors;
  const auto refill = [&](Cursor& c) {
    if (c.left == 0) return false;
    const std::size_t bytes = record_bytes(c.run->packing, words);
    c.loaded = static_cast<std::size_t>(std::min<std::uint64_t>(c.left, per_buffer));
    c.packed.resize(c.loaded * bytes);
    files[c.run->file]->read_bytes(c.next_offset, c.packed);
    c.buffer.resize(c.loaded * words);
    for (std::size_t r = 0; r < c.loaded; ++r) unpack(c.packed.data() + r * bytes, c.run->packing, words, c.buffer.data() + r * words);
    c.next_offset += c.loaded * bytes;
    c.left -= c.loaded;
    c.at = 0;
    return true;
  };
  for (const Run& r : runs) {
    if (r.count == 0) continue;
    cursors.push_back(Cursor{&r, r.offset, r.count, {}, {}, 0, 0});
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
      std::size_t end = c.at + 1;
      while (end < c.loaded && c.buffer[end * words + 1] < others) ++end;
      visit(c.buffer.data() + c.at * words, end - c.at);
      c.at = end;
      more = c.at < c.loaded || refill(c);
    } while (more && c.buffer[c.at * words + 1] < others);
    if (more) heap.emplace(c.buffer[c.at * words + 1], i);
  }
}

}  // namespace vola::tile::detail
