#include "vola/io/npz.hpp"

#include <zip.h>

#include <algorithm>
#include <cctype>
#include <filesystem>
#include <memory>
#include <string_view>

#include "vola/error.hpp"

namespace vola::io {

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
    if (!name)
      throw FormatError(path, std::nullopt, "zip entry " + std::to_string(i) + ": " + archive_error(archive.get()));
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
    throw FormatError(
        path, std::nullopt,
        member + ": ends after " + std::to_string(bytes.size()) + " of " + std::to_string(size) + " bytes");
  std::uint8_t extra = 0;
  if (zip_fread(file, &extra, 1) > 0)
    throw FormatError(path, std::nullopt, member + ": inflates past its stated " + std::to_string(size) + " bytes");
  return bytes;
}

}  // namespace

NpyArray read_npz_array(const std::string& path, const std::string& name) {
  Archive archive = open_archive(path);
  const std::string member = name + std::string(kNpySuffix);
  const zip_int64_t index = zip_name_locate(archive.get(), member.c_str(), 0);
  if (index < 0)
    throw FormatError(path, std::nullopt, "no array '" + name + "' (member " + member + ") in the archive");
  const zip_stat_t stat = checked_stat(archive.get(), index, path, member);
  std::unique_ptr<zip_file_t, ZipFileCloser> file(zip_fopen_index(archive.get(), static_cast<zip_uint64_t>(index), 0));
  if (!file) throw FormatError(path, std::nullopt, member + ": cannot open: " + archive_error(archive.get()));
  NpyArray array = parse_npy(read_member(file.get(), stat.size, path, member), path + ":" + member);
  if (stat.comp_method != ZIP_CM_STORE) array.compressed_bytes = stat.comp_size;
  return array;
}

std::string npz_points_member(const std::string& path, const std::string& wanted) {
  const std::vector<std::string> names = npz_array_names(path);
  std::string listed;
  for (const auto& n : names) listed += (listed.empty() ? "" : ", ") + n;
  if (names.empty()) throw FormatError(path, std::nullopt, "the archive holds no .npy array");
  if (!wanted.empty()) {
    if (std::find(names.begin(), names.end(), wanted) == names.end())
      throw FormatError(path, std::nullopt, "no array '" + wanted + "' in the archive (it holds " + listed + ")");
    return wanted;
  }
  if (names.size() == 1) return names.front();
  // pyntcloud saves "points" (beside "mesh"); datasets often "xyz" beside "rgb" and "label".
  static const std::vector<std::string_view> kPointNames = {"points",      "xyz", "positions", "pos",
                                                            "point_cloud", "pc",  "cloud"};
  std::vector<std::string> named;
  for (const auto& n : names) {
    std::string lower = n;
    std::transform(lower.begin(), lower.end(), lower.begin(),
                   [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
    if (std::find(kPointNames.begin(), kPointNames.end(), lower) != kPointNames.end()) named.push_back(n);
  }
  if (named.size() == 1) return named.front();
  throw FormatError(path, std::nullopt,
                    "which array holds the points? The archive holds " + listed +
                        (named.empty() ? ", none named points or xyz" : ", several named as points are") +
                        ": give one with --grid NAME (Python: grid=NAME; C: vola_convert_options.grid)");
}

}  // namespace vola::io
