#include "vola/learn/npz.hpp"

#include <zip.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <memory>

#include "vola/error.hpp"

namespace vola::learn {

namespace {

// Deflate's best case: 258 bytes out of about 2 bits in, so about 1032:1.
constexpr std::uint64_t kMaxDeflateRatio = 1032;
constexpr std::string_view kNpySuffix = ".npy";

struct ZipCloser {
  void operator()(zip_t* archive) const noexcept { zip_discard(archive); }
};
struct ZipFileCloser {
  void operator()(zip_file_t* file) const noexcept { zip_fclose(file); }
};
using Archive = std::unique_ptr<zip_t, ZipCloser>;

Archive open_archive(const std::string& path) {
  int code = 0;
  zip_t* archive = zip_open(path.c_str(), ZIP_RDONLY, &code);
  if (!archive) {
    zip_error_t error;
    zip_error_init_with_code(&error, code);
    const std::string message = zip_error_strerror(&error);
    zip_error_fini(&error);
    if (code == ZIP_ER_OPEN || code == ZIP_ER_NOENT || code == ZIP_ER_READ)
      throw IoError("cannot open " + path + ": " + message);
    throw FormatError(path, std::nullopt, "not a readable .npz (zip) archive: " + message);
  }
  return Archive(archive);
}

std::string archive_error(zip_t* archive) { return zip_strerror(archive); }

}  // namespace

std::vector<std::string> npz_array_names(const std::string& path) {
  Archive archive = open_archive(path);
  const zip_int64_t count = zip_get_num_entries(archive.get(), 0);
  std::vector<std::string> names;
  for (zip_int64_t i = 0; i < count; ++i) {
    const char* name = zip_get_name(archive.get(), static_cast<zip_uint64_t>(i), 0);
    if (!name) throw FormatError(path, std::nullopt, "zip entry " + std::to_string(i) + ": " + archive_error(archive.get()));
    std::string member = name;
    if (member.size() > kNpySuffix.size() && member.ends_with(kNpySuffix))
      names.push_back(member.substr(0, member.size() - kNpySuffix.size()));
  }
  return names;
}

namespace {

// The sizes the zip directory states for `member`, checked against the archive's own
// length: the directory is bytes of the file like any other (a ZIP64 entry can claim
// 8 GiB of stored data in a 2.5 KB file), so a member is believed to hold no more than
// the archive holds, times deflate's best ratio.
zip_stat_t checked_stat(zip_t* archive, zip_int64_t index, const std::string& path, const std::string& member) {
  zip_stat_t stat;
  zip_stat_init(&stat);
  if (zip_stat_index(archive, static_cast<zip_uint64_t>(index), 0, &stat) != 0 || !(stat.valid & ZIP_STAT_SIZE) ||
      !(stat.valid & ZIP_STAT_COMP_SIZE))
    throw FormatError(path, std::nullopt, member + ": no sizes in the zip directory: " + archive_error(archive));
  std::error_code error;
  const std::uint64_t archive_bytes = std::filesystem::file_size(path, error);
  if (error) throw IoError("cannot read the size of " + path + ": " + error.message());
  if (stat.comp_size > archive_bytes)
    throw FormatError(path, std::nullopt,
                      member + ": the zip directory states " + std::to_string(stat.comp_size) +
                          " compressed bytes, more than the archive's " + std::to_string(archive_bytes));
  const bool stored = stat.comp_method == ZIP_CM_STORE;
  const std::uint64_t limit = stored ? stat.comp_size : stat.comp_size * kMaxDeflateRatio + 1024;
  if (stat.size > limit)
    throw FormatError(path, std::nullopt,
                      member + ": states " + std::to_string(stat.size) + " bytes, more than its " +
                          std::to_string(stat.comp_size) + " compressed bytes can hold");
  return stat;
}

// Reads exactly `size` bytes of the member, growing the buffer as the bytes arrive
// rather than trusting `size` up front.
std::vector<std::uint8_t> read_member(zip_file_t* file, std::uint64_t size, const std::string& path,
                                      const std::string& member) {
  constexpr std::uint64_t kChunk = std::uint64_t{1} << 20;
  std::vector<std::uint8_t> bytes;
  while (bytes.size() < size) {
    const std::size_t done = bytes.size();
    bytes.resize(done + std::min(kChunk, size - done));
    const zip_int64_t got = zip_fread(file, bytes.data() + done, bytes.size() - done);
    if (got < 0) throw FormatError(path, std::nullopt, member + ": cannot inflate: " + zip_file_strerror(file));
    bytes.resize(done + static_cast<std::size_t>(got));
    if (got == 0) break;
  }
  if (bytes.size() != size)
    throw FormatError(path, std::nullopt,
                      member + ": ends after " + std::to_string(bytes.size()) + " of " + std::to_string(size) + " bytes");
  std::uint8_t extra = 0;
  if (zip_fread(file, &extra, 1) > 0)
    throw FormatError(path, std::nullopt, member + ": inflates past its stated " + std::to_string(size) + " bytes");
  return bytes;
}

// A label as the file holds it: integers without a fraction (they were printed as
// "99.000000", and 2^40 as "1099511627776.000000").
std::string label_text(double label) {
  char text[32];
  std::snprintf(text, sizeof text, "%.17g", label);
  return text;
}

}  // namespace

io::NpyArray read_npz_array(const std::string& path, const std::string& name) {
  Archive archive = open_archive(path);
  const std::string member = name + std::string(kNpySuffix);
  const zip_int64_t index = zip_name_locate(archive.get(), member.c_str(), 0);
  if (index < 0) throw FormatError(path, std::nullopt, "no array '" + name + "' (member " + member + ") in the archive");
  const zip_stat_t stat = checked_stat(archive.get(), index, path, member);
  std::unique_ptr<zip_file_t, ZipFileCloser> file(zip_fopen_index(archive.get(), static_cast<zip_uint64_t>(index), 0));
  if (!file) throw FormatError(path, std::nullopt, member + ": cannot open: " + archive_error(archive.get()));
  return io::parse_npy(read_member(file.get(), stat.size, path, member), path + ":" + member);
}

LabelledGrids read_labelled_grids(const std::string& path, const std::string& split_wanted) {
  std::string split = split_wanted;
  if (split.empty()) {
    std::vector<std::string> candidates;
    for (const auto& name : npz_array_names(path))
      if (name.starts_with("X_")) candidates.push_back(name.substr(2));
    if (candidates.size() != 1)
      throw FormatError(path, std::nullopt,
                        candidates.empty() ? "no X_<split> array (expected X_<split> grids and y_<split> labels)"
                                           : "several X_<split> arrays: name the split");
    split = candidates.front();
  }
  const std::string x_name = "X_" + split, y_name = "y_" + split;
  const io::NpyArray x = read_npz_array(path, x_name);
  const io::NpyArray y = read_npz_array(path, y_name);
  const std::string x_where = path + ":" + x_name;
  const std::string y_where = path + ":" + y_name;

  if (x.shape.size() != 4 || x.shape[1] != x.shape[2] || x.shape[2] != x.shape[3] || x.shape[1] < 4 || x.shape[1] > 256) {
    std::string shape;
    for (auto s : x.shape) {
      if (!shape.empty()) shape += ',';
      shape += std::to_string(s);
    }
    throw FormatError(x_where, std::nullopt, "shape (" + shape + "): expected (N, S, S, S) grids with 4 <= S <= 256");
  }
  if (x.kind != 'u' && x.kind != 'i' && x.kind != 'b' && x.kind != 'f')
    throw FormatError(x_where, std::nullopt, "dtype " + x.dtype() + ": expected integer, bool or float 0/1 cells");
  if (y.shape.size() != 1 || y.shape[0] != x.shape[0])
    throw FormatError(y_where, std::nullopt,
                      "expected one label per grid (" + std::to_string(x.shape[0]) + "), shape has " +
                          std::to_string(y.shape.size()) + " dimensions" +
                          (y.shape.empty() ? "" : " and " + std::to_string(y.shape[0]) + " entries"));
  if (y.kind != 'u' && y.kind != 'i') throw FormatError(y_where, std::nullopt, "dtype " + y.dtype() + ": expected integer labels");

  LabelledGrids grids;
  grids.split = split;
  grids.side = static_cast<int>(x.shape[1]);
  grids.labels.resize(y.shape[0]);
  for (std::uint64_t i = 0; i < y.shape[0]; ++i) {
    const double label = y.value(i);
    if (!(label >= 0 && label <= 9))
      throw FormatError(y_where, std::nullopt,
                        "grid " + std::to_string(i) + "'s label is " + label_text(label) + ", not 0..9");
    grids.labels[i] = static_cast<int>(label);
  }
  grids.cells.resize(x.size());
  for (std::uint64_t i = 0; i < grids.cells.size(); ++i) {
    const double v = x.value(i);
    if (v != 0 && v != 1)
      throw FormatError(x_where, std::nullopt,
                        "grid " + std::to_string(i / grids.cells_per_grid()) + " holds " + std::to_string(v) +
                            ": expected 0/1 occupancy");
    grids.cells[i] = static_cast<std::uint8_t>(v);
  }
  return grids;
}

}  // namespace vola::learn
