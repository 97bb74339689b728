// LasReader: opening a LAS file (pread on regular files, a stream otherwise, or bytes in
// memory) and decoding its point records in chunks. The header is parsed in las_header.cpp.
#include "vola/io/las.hpp"

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <memory>
#include <string>

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include "las_format.hpp"
#include "vola/error.hpp"

namespace vola::io {

bool LasHeader::has_rgb() const noexcept {
  return point_format == 2 || point_format == 3 || point_format == 5 || point_format == 7 || point_format == 8 ||
         point_format == 10;
}

bool LasHeader::has_gps_time() const noexcept { return point_format != 0 && point_format != 2; }

int LasHeader::coordinate_decimals(int axis) const noexcept {
  const auto a = static_cast<std::size_t>(axis);
  const auto whole_at = [](double v, int decimals) {
    // Within the rounding of a double and of the product (0.00025 * 1e5 is 25.000000000000004).
    const double scaled = std::abs(v) * std::pow(10.0, decimals);
    return std::abs(scaled - std::round(scaled)) <= 4e-16 * scaled + 1e-9;
  };
  int decimals = 0;
  while (decimals < 12 && !(whole_at(scale[a], decimals) && whole_at(offset[a], decimals))) ++decimals;
  double magnitude = 0;
  for (const double v : {min[a], max[a], offset[a]})
    if (std::isfinite(v)) magnitude = std::max(magnitude, std::abs(v));
  const int integer_digits = magnitude >= 1 ? static_cast<int>(std::floor(std::log10(magnitude))) + 1 : 1;
  return std::clamp(decimals, 0, std::max(0, 15 - integer_digits));
}

int LasHeader::coordinate_decimals() const noexcept {
  return std::max({coordinate_decimals(0), coordinate_decimals(1), coordinate_decimals(2)});
}

void LasChunk::clear() {
  xyz.clear();
  intensity.clear();
  return_number.clear();
  number_of_returns.clear();
  classification.clear();
  user_data.clear();
  point_source_id.clear();
  gps_time.clear();
  red.clear();
  green.clear();
  blue.clear();
  for (auto& e : extra) e.clear();
}

LasReader::LasReader(const std::string& path) : path_(path) {
  // O_NONBLOCK: a FIFO opens at once instead of waiting for a writer, and is refused
  // below (its reader would block until someone writes: forever, most often).
  const int fd = ::open(path.c_str(), O_RDONLY | O_CLOEXEC | O_NONBLOCK);
  if (fd < 0) throw IoError(path + ": cannot open");
  struct stat st {};
  if (::fstat(fd, &st) == 0 && S_ISREG(st.st_mode)) {
    fd_ = std::shared_ptr<const int>(new int(fd), [](const int* f) {
      ::close(*f);
      delete f;
    });
    file_size_ = static_cast<std::uint64_t>(st.st_size);
#ifdef POSIX_FADV_SEQUENTIAL
    ::posix_fadvise(fd, 0, 0, POSIX_FADV_SEQUENTIAL);
#endif
  } else {
    ::close(fd);
    throw IoError(path + ": not a regular file (a FIFO, device or directory): inputs are files");
  }
  read_header();
}

LasReader::LasReader(std::span<const std::uint8_t> bytes, const std::string& name)
    : path_(name), owned_(bytes.begin(), bytes.end()) {
  bytes_ = owned_;
  file_size_ = bytes_.size();
  read_header();
}

// size bytes at offset (checked by the caller to lie inside the file).
void LasReader::fetch(std::uint64_t offset, std::uint64_t size, std::uint8_t* out) const {
  bytes_read_ += size;
  if (fd_) {
    std::uint64_t done = 0;
    while (done < size) {
      const ::ssize_t got = ::pread(*fd_, out + done, static_cast<std::size_t>(size - done),
                                    static_cast<off_t>(offset + done));
      if (got < 0 && errno == EINTR) continue;
      if (got <= 0) throw FormatError(path_, offset + done, "cannot read");
      done += static_cast<std::uint64_t>(got);
    }
    return;
  }
  if (size) std::memcpy(out, bytes_.data() + offset, size);
}


std::span<const std::uint8_t> LasReader::read_records(std::size_t max_points) {
  const LasHeader& hd = header_;
  const std::size_t n = static_cast<std::size_t>(std::min<std::uint64_t>(max_points, points_total_ - next_));
  if (n == 0) return {};
  if (hd.compressed()) {
    if (kept_complete_) return read_kept_records(n);
    const std::uint64_t first = next_;
    const std::span<const std::uint8_t> records = read_laz_records(n);
    if (kept_fd_) keep(records, first);
    return records;
  }
  const std::size_t length = hd.record_length;
  const std::uint64_t at = hd.offset_to_points + next_ * length;
  if (!fd_) {  // in memory; the header check guarantees the records lie inside
    next_ += n;
    return bytes_.subspan(static_cast<std::size_t>(at), n * length);
  }
  // resize() only grows the buffer after the first chunk: no zeroing per chunk.
  if (buffer_.size() < n * length) buffer_.resize(n * length);
  try {
    fetch(at, n * length, buffer_.data());
  } catch (const FormatError&) {
    throw FormatError(path_, at, "cannot read the point records (truncated file)");
  }
  next_ += n;
  return {buffer_.data(), n * length};
}

std::size_t LasReader::read(LasChunk& chunk, std::size_t max_points, bool xyz_only) {
  chunk.clear();
  const LasHeader& hd = header_;
  chunk.extra.resize(hd.extra_fields.size());
  const std::size_t length = hd.record_length;
  const std::size_t n = static_cast<std::size_t>(std::min<std::uint64_t>(max_points, points_total_ - next_));
  if (n == 0) return 0;
  // The records come in batches that stay in cache while their fields are spread out.
  const std::size_t batch = std::max<std::size_t>(1, kLasRecordBatchBytes / length);
  if (xyz_only) {
    chunk.xyz.resize(3 * n);
    double* out = chunk.xyz.data();
    for (std::size_t done = 0; done < n;) {
      const std::span<const std::uint8_t> records = read_records(std::min(batch, n - done));
      const std::size_t m = records.size() / length;
      for (std::size_t i = 0; i < m; ++i, out += 3) {
        const std::uint8_t* r = records.data() + i * length;
        for (int a = 0; a < 3; ++a) out[a] = static_cast<double>(load_le<std::int32_t>(r + 4 * a)) * hd.scale[a] + hd.offset[a];
      }
      done += m;
    }
    return n;
  }
  for (std::size_t done = 0; done < n;) {
    const std::span<const std::uint8_t> records = read_records(std::min(batch, n - done));
    const std::size_t m = records.size() / length;
    decode_las_records(hd, records, chunk);
    done += m;
  }
  return n;
}


LasReader::~LasReader() { settle_laz_prefetch(); }

void LasReader::set_coordinates_only(bool on) {
  on = on && !(kept_fd_ && !kept_complete_);  // records being kept are decoded whole
  if (on == coordinates_only_) return;
  settle_laz_prefetch();  // a batch decoded ahead was decoded the other way
  coordinates_only_ = on;
  rewind();
}

bool LasReader::keep_decoded_records() {
  rewind();
  if (!header_.compressed()) return false;
  if (!kept_fd_) {
    const char* dir = std::getenv("TMPDIR");
    const std::string folder = dir && *dir ? dir : "/tmp";
    int fd = ::open(folder.c_str(), O_TMPFILE | O_RDWR | O_CLOEXEC, 0600);
    if (fd < 0) {  // a file system without O_TMPFILE: a named file, unlinked at once
      std::string name = folder + "/vola-records-XXXXXX";
      fd = ::mkostemp(name.data(), O_CLOEXEC);
      if (fd >= 0) ::unlink(name.c_str());
    }
    if (fd < 0) return false;
    kept_fd_ = std::shared_ptr<const int>(new int(fd), [](const int* f) {
      ::close(*f);
      delete f;
    });
  }
  kept_points_ = 0;
  kept_complete_ = false;
  set_coordinates_only(false);
  return true;
}

// Records [first, first + n) as decoded, appended when they are the next ones to keep.
void LasReader::keep(std::span<const std::uint8_t> records, std::uint64_t first) {
  const std::size_t length = header_.record_length;
  if (first != kept_points_ || records.empty()) return;
  std::uint64_t done = 0;
  while (done < records.size()) {
    const ::ssize_t put =
        ::pwrite(*kept_fd_, records.data() + done, records.size() - done, static_cast<off_t>(first * length + done));
    if (put < 0 && errno == EINTR) continue;
    if (put <= 0) {  // no room: decode on every pass, as without a file
      kept_fd_.reset();
      kept_points_ = 0;
      return;
    }
    done += static_cast<std::uint64_t>(put);
  }
  kept_points_ += records.size() / length;
  kept_complete_ = kept_points_ == points_total_;
}

std::span<const std::uint8_t> LasReader::read_kept_records(std::size_t n) {
  const std::size_t length = header_.record_length;
  if (buffer_.size() < n * length) buffer_.resize(n * length);
  std::uint64_t done = 0;
  const std::uint64_t at = next_ * length;
  while (done < n * length) {
    const ::ssize_t got = ::pread(*kept_fd_, buffer_.data() + done, n * length - done, static_cast<off_t>(at + done));
    if (got < 0 && errno == EINTR) continue;
    if (got <= 0) throw IoError(path_ + ": cannot read back the decoded records kept in a temporary file");
    done += static_cast<std::uint64_t>(got);
  }
  next_ += n;
  return {buffer_.data(), n * length};
}

void LasReader::rewind() {
  next_ = 0;
  settle_laz_prefetch();
  current_.first = current_.count = 0;
  batch_chunk_ = 0;
  batch_point_ = 0;
}


}  // namespace vola::io
