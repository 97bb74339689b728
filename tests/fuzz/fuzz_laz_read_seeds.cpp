// Seeds for fuzz_laz_read: the small LAZ files of the shared data folder (beside
// golden/) and LAZ files written here with the codec's encoder (point formats 0-3 and
// 6-8, the wave-packet formats 4, 5, 9 and 10, extra bytes, several chunks, variable chunks, compressor 1, item versions 1 and 4).
// Linked into fuzz_laz_replay in place of fuzz_seeds.cpp.
#include <algorithm>
#include <cstring>
#include <fstream>
#include <iterator>
#include <random>
#include <string>

#include "fuzz_seeds.hpp"
#include "vola/io/laz.hpp"

namespace vola_fuzz {
namespace {

namespace laz = vola::io::laz;
using Bytes = std::vector<std::uint8_t>;

template <class T>
void put(Bytes& b, std::size_t at, T value) {
  std::memcpy(b.data() + at, &value, sizeof value);
}

// A LAS 1.2 file: a 227-byte header, the laszip VLR, the chunk table offset, chunks of
// `chunk_points` records, the chunk table.
Bytes laz_file(laz::LaszipInfo info, std::uint8_t format, const Bytes& records, std::uint32_t chunk_points) {
  const auto length = static_cast<std::uint16_t>(info.record_length());
  const std::uint64_t count = records.size() / length;
  if (info.chunk_size != laz::kVariableChunkSize) info.chunk_size = chunk_points;
  const Bytes vlr = laz::laszip_vlr_payload(info);
  Bytes f(227 + 54, 0);
  std::memcpy(f.data(), "LASF", 4);
  f[24] = 1, f[25] = 2;
  put<std::uint16_t>(f, 94, 227);
  put<std::uint32_t>(f, 96, static_cast<std::uint32_t>(227 + 54 + vlr.size()));
  put<std::uint32_t>(f, 100, 1);
  f[104] = static_cast<std::uint8_t>(format | 0x80);
  put<std::uint16_t>(f, 105, length);
  put<std::uint32_t>(f, 107, static_cast<std::uint32_t>(count));
  std::memcpy(f.data() + 227 + 2, "laszip encoded", 14);
  put<std::uint16_t>(f, 227 + 18, 22204);
  put<std::uint16_t>(f, 227 + 20, static_cast<std::uint16_t>(vlr.size()));
  f.resize(f.size() + vlr.size());
  std::memcpy(f.data() + 227 + 54, vlr.data(), vlr.size());
  if (info.compressor == 1) {
    laz::encode_chunk(info, records, length, f);
    return f;
  }
  const std::size_t points_at = f.size();
  f.resize(f.size() + 8);
  std::vector<laz::ChunkEntry> chunks;
  for (std::uint64_t first = 0; first < count; first += chunk_points) {
    const std::uint64_t n = std::min<std::uint64_t>(chunk_points, count - first);
    const std::size_t at = f.size();
    laz::encode_chunk(info, std::span(records).subspan(first * length, n * length), length, f);
    chunks.push_back({n, at, f.size() - at});
  }
  put<std::uint64_t>(f, points_at, f.size());
  const Bytes table = laz::chunk_table_bytes(info, chunks);
  f.insert(f.end(), table.begin(), table.end());
  return f;
}

Bytes records(std::uint16_t length, std::size_t count, std::uint64_t seed) {
  std::mt19937_64 rng(seed);
  Bytes r(count * length);
  for (std::size_t i = 0; i < r.size(); ++i) r[i] = static_cast<std::uint8_t>(i % length < 12 ? rng() % 8 : rng() % 3);
  return r;
}

}  // namespace

std::vector<Seed> synthetic_seeds() {
  std::vector<Seed> seeds;
  static constexpr std::uint16_t kBase[] = {20, 28, 26, 34, 57, 63, 30, 36, 38, 59, 67};
  for (const int format : {0, 1, 2, 3, 4, 5, 6, 7, 8, 9, 10}) {
    const auto length = static_cast<std::uint16_t>(kBase[format] + 3);
    const std::string name = "laz_format" + std::to_string(format);
    laz::LaszipInfo info = laz::laszip_info_for(static_cast<std::uint8_t>(format), length);
    seeds.push_back({name, laz_file(info, static_cast<std::uint8_t>(format), records(length, 40, static_cast<std::uint64_t>(format)), 16)});
    if (format >= 6) {
      for (auto& item : info.items) item.version = 4;
      info.chunk_size = laz::kVariableChunkSize;
      seeds.push_back({name + "_v4_variable", laz_file(info, static_cast<std::uint8_t>(format), records(length, 30, static_cast<std::uint64_t>(format) + 9), 7)});
    } else {
      info.compressor = 1;
      seeds.push_back({name + "_unchunked", laz_file(info, static_cast<std::uint8_t>(format), records(length, 20, static_cast<std::uint64_t>(format) + 9), 0)});
      for (auto& item : info.items) item.version = 1;  // LASzip 1.x
      seeds.push_back({name + "_v1_unchunked", laz_file(info, static_cast<std::uint8_t>(format), records(length, 20, static_cast<std::uint64_t>(format) + 17), 0)});
    }
  }
  return seeds;
}

std::vector<Seed> golden_seeds(const std::filesystem::path& golden) {
  std::vector<Seed> seeds;
  const auto folder = golden.parent_path() / "data" / "laz";
  if (!std::filesystem::is_directory(folder)) return seeds;
  for (const auto& entry : std::filesystem::directory_iterator(folder)) {
    if (!entry.is_regular_file() || entry.path().extension() != ".laz" || entry.file_size() > 64 * 1024) continue;
    std::ifstream in(entry.path(), std::ios::binary);
    seeds.push_back({"laz_" + entry.path().filename().string(), Bytes(std::istreambuf_iterator<char>(in), {})});
  }
  std::sort(seeds.begin(), seeds.end(), [](const Seed& a, const Seed& b) { return a.name < b.name; });
  return seeds;
}

}  // namespace vola_fuzz
