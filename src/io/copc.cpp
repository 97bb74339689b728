// The COPC hierarchy: the info VLR and the pages of 32-byte entries (voxel key, offset,
// byte size, point count: -1 a child page, 0 an empty node, else a data chunk).
#include "vola/io/copc.hpp"

#include <algorithm>
#include <cmath>
#include <set>

#include "vola/error.hpp"
#include "vola/io/las.hpp"
#include "vola/little_endian.hpp"

namespace vola::io {

namespace {

constexpr std::size_t kEntryBytes = 32;
constexpr std::size_t kInfoBytes = 160;

CopcInfo parse_info(const LasVlr& vlr, const std::string& source) {
  if (vlr.data.size() < kInfoBytes)
    throw FormatError(source, vlr.offset, "the COPC info VLR has " + std::to_string(vlr.data.size()) +
                                              " bytes, not " + std::to_string(kInfoBytes));
  const std::uint8_t* d = vlr.data.data();
  CopcInfo info;
  for (int a = 0; a < 3; ++a) info.center[a] = load_le<double>(d + 8 * a);
  info.halfsize = load_le<double>(d + 24);
  info.spacing = load_le<double>(d + 32);
  info.root_page_offset = load_le<std::uint64_t>(d + 40);
  info.root_page_size = load_le<std::uint64_t>(d + 48);
  info.gps_time_min = load_le<double>(d + 56);
  info.gps_time_max = load_le<double>(d + 64);
  if (!(info.halfsize > 0.0) || !std::isfinite(info.halfsize) || !std::isfinite(info.center[0]) ||
      !std::isfinite(info.center[1]) || !std::isfinite(info.center[2]))
    throw FormatError(source, vlr.offset, "the COPC info VLR's octree cube is not a finite, positive size");
  return info;
}

// Walks the pages breadth first from the root, each once.
class PageWalk {
 public:
  PageWalk(CopcHierarchy& out, const LasHeader& hd, const laz::ReadAt& read_at, std::uint64_t file_size,
           const std::string& source)
      : out_(out), hd_(hd), read_at_(read_at), file_size_(file_size), source_(source) {}

  void run() {
    std::vector<std::pair<std::uint64_t, std::uint64_t>> pending{{out_.info.root_page_offset, out_.info.root_page_size}};
    std::uint64_t entries_seen = 0;
    while (!pending.empty()) {
      const auto [offset, size] = pending.back();
      pending.pop_back();
      check_page(offset, size);
      entries_seen += size / kEntryBytes;
      if (entries_seen > file_size_ / kEntryBytes)
        throw FormatError(source_, offset, "the COPC hierarchy has more entries than the file has room for");
      std::vector<std::uint8_t> page(static_cast<std::size_t>(size));
      read_at_(offset, size, page.data());
      ++out_.pages;
      for (std::size_t e = 0; e < page.size(); e += kEntryBytes) entry(page.data() + e, offset + e, pending);
    }
  }

 private:
  void check_page(std::uint64_t offset, std::uint64_t size) {
    if (offset > file_size_ || size > file_size_ - offset)
      throw FormatError(source_, offset, "a COPC hierarchy page of " + std::to_string(size) +
                                             " bytes lies outside the " + std::to_string(file_size_) + "-byte file");
    if (size % kEntryBytes != 0)
      throw FormatError(source_, offset, "a COPC hierarchy page of " + std::to_string(size) +
                                             " bytes is not a whole number of 32-byte entries");
    if (!visited_.insert(offset).second)
      throw FormatError(source_, offset, "the COPC hierarchy visits this page twice (a loop)");
  }

  void entry(const std::uint8_t* e, std::uint64_t at, std::vector<std::pair<std::uint64_t, std::uint64_t>>& pending) {
    CopcNode node;
    node.level = load_le<std::int32_t>(e);
    node.x = load_le<std::int32_t>(e + 4);
    node.y = load_le<std::int32_t>(e + 8);
    node.z = load_le<std::int32_t>(e + 12);
    const auto offset = load_le<std::uint64_t>(e + 16);
    const auto byte_size = load_le<std::int32_t>(e + 24);
    const auto point_count = load_le<std::int32_t>(e + 28);
    if (node.level < 0 || node.level > 30 || node.x < 0 || node.y < 0 || node.z < 0 ||
        std::max({node.x, node.y, node.z}) >= (std::int64_t{1} << node.level))
      throw FormatError(source_, at, "a COPC hierarchy entry has the impossible key " + std::to_string(node.level) +
                                         "-" + std::to_string(node.x) + "-" + std::to_string(node.y) + "-" +
                                         std::to_string(node.z));
    if (point_count == -1) {
      if (byte_size < 0) throw FormatError(source_, at + 24, "a COPC child page has a negative size");
      pending.emplace_back(offset, static_cast<std::uint64_t>(byte_size));
      return;
    }
    if (point_count < -1 || byte_size < 0)
      throw FormatError(source_, at + 24, "a COPC hierarchy entry has a negative size or point count");
    if (point_count == 0) return;
    node.offset = offset;
    node.byte_size = static_cast<std::uint64_t>(byte_size);
    node.point_count = static_cast<std::uint64_t>(point_count);
    if (node.offset < hd_.offset_to_points || node.offset > file_size_ || node.byte_size > file_size_ - node.offset)
      throw FormatError(source_, at + 16, "a COPC node's chunk lies outside the point data");
    out_.levels = std::max(out_.levels, node.level + 1);
    out_.nodes.push_back(node);
  }

  CopcHierarchy& out_;
  const LasHeader& hd_;
  const laz::ReadAt& read_at_;
  std::uint64_t file_size_;
  const std::string& source_;
  std::set<std::uint64_t> visited_;
};

}  // namespace

Box CopcHierarchy::bounds(const CopcNode& node) const noexcept {
  const double side = 2.0 * info.halfsize / std::ldexp(1.0, node.level);
  const std::int32_t key[3] = {node.x, node.y, node.z};
  Box box;
  for (int a = 0; a < 3; ++a) {
    box.min[a] = info.center[a] - info.halfsize + side * key[a];
    box.max[a] = box.min[a] + side;
  }
  return box;
}

std::optional<CopcHierarchy> read_copc_hierarchy(const LasHeader& header, const laz::ReadAt& read_at,
                                                 std::uint64_t file_size, const std::string& source) {
  const auto info = std::find_if(header.vlrs.begin(), header.vlrs.end(),
                                 [](const LasVlr& v) { return !v.extended && v.user_id == "copc" && v.record_id == 1; });
  if (info == header.vlrs.end()) return std::nullopt;
  CopcHierarchy out;
  out.info = parse_info(*info, source);
  PageWalk(out, header, read_at, file_size, source).run();
  return out;
}

}  // namespace vola::io
