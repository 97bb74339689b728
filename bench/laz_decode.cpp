// LAZ decode (and encode) speed of vola's codec on one core: every chunk of a LAZ file
// decoded `repeats` times; prints the best and median points per second (for layered
// chunks also of decoding the coordinates alone).
//
//   vola_laz_bench [file.laz] [repeats]
//
// The file defaults to $VOLA_SHARED/data/laz/pdal_autzen_trim.laz (point format 3:
// POINT10 + GPSTIME11 + RGB12, 110000 points in 3 chunks).
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <iterator>
#include <string>
#include <vector>

#include "vola/error.hpp"
#include "vola/io/laz.hpp"

namespace {

namespace laz = vola::io::laz;
using Bytes = std::vector<std::uint8_t>;
using Clock = std::chrono::steady_clock;

template <class T>
T get(const Bytes& b, std::size_t at) {
  T v{};
  if (at + sizeof v <= b.size()) std::memcpy(&v, b.data() + at, sizeof v);
  return v;
}

struct LazFile {
  Bytes bytes;
  laz::LaszipInfo info;
  std::uint32_t offset_to_points = 0;
  std::uint16_t record_length = 0;
  std::uint64_t points = 0;
};

LazFile open_laz(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw vola::IoError("cannot open " + path);
  LazFile f;
  f.bytes.assign(std::istreambuf_iterator<char>(in), {});
  f.offset_to_points = get<std::uint32_t>(f.bytes, 96);
  f.record_length = get<std::uint16_t>(f.bytes, 105);
  f.points = get<std::uint32_t>(f.bytes, 107);
  if (f.points == 0 && get<std::uint8_t>(f.bytes, 25) >= 4) f.points = get<std::uint64_t>(f.bytes, 247);
  std::size_t at = get<std::uint16_t>(f.bytes, 94);
  for (std::uint32_t i = 0, n = get<std::uint32_t>(f.bytes, 100); i < n && at + 54 <= f.bytes.size(); ++i) {
    const auto length = get<std::uint16_t>(f.bytes, at + 20);
    if (get<std::uint16_t>(f.bytes, at + 18) == 22204 && at + 54 + length <= f.bytes.size())
      f.info = laz::parse_laszip_vlr(std::span(f.bytes).subspan(at + 54, length), path, at + 54);
    at += 54 + std::size_t{length};
  }
  return f;
}

double median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  return v[v.size() / 2];
}

}  // namespace

int main(int argc, char** argv) try {
  const char* shared = std::getenv("VOLA_SHARED");
  const std::string path = argc > 1 ? argv[1] : std::string(shared ? shared : "../shared") + "/data/laz/pdal_autzen_trim.laz";
  const int repeats = argc > 2 ? std::atoi(argv[2]) : 20;
  const LazFile f = open_laz(path);
  const auto read_at = [&f](std::uint64_t offset, std::uint64_t n, std::uint8_t* out) {
    if (offset > f.bytes.size() || n > f.bytes.size() - offset) throw vola::IoError("read past the end");
    std::memcpy(out, f.bytes.data() + offset, n);
  };
  const auto chunks = laz::read_chunk_table(f.info, read_at, f.bytes.size(), f.offset_to_points, f.points, path);
  Bytes records(f.points * f.record_length);
  std::vector<double> decode_seconds, coordinates_seconds, encode_seconds;
  Bytes encoded;
  const auto decode_all = [&](bool coordinates_only) {
    const auto start = Clock::now();
    std::uint64_t done = 0;
    for (std::size_t i = 0; i < chunks.size(); ++i) {
      const auto& c = chunks[i];
      laz::decode_chunk(f.info, std::span(f.bytes).subspan(c.byte_offset, c.byte_size), c.point_count,
                        records.data() + done * f.record_length, f.record_length, i, c.byte_offset, path,
                        coordinates_only);
      done += c.point_count;
    }
    return std::chrono::duration<double>(Clock::now() - start).count();
  };
  // Layered chunks (point formats 6-10) can decode their coordinate layers alone, as the
  // occupancy conversion does; the two are measured alternately.
  const bool layered = f.info.compressor == 3;
  for (int r = 0; r < repeats; ++r) {
    decode_seconds.push_back(decode_all(false));
    if (layered) coordinates_seconds.push_back(decode_all(true));
  }
  if (layered) decode_all(false);  // whole records again for the encoder
  for (int r = 0; r < std::max(1, repeats / 4); ++r) {
    encoded.clear();
    const auto start = Clock::now();
    std::uint64_t done = 0;
    for (const auto& c : chunks) {
      laz::encode_chunk(f.info, std::span(records).subspan(done * f.record_length, c.point_count * f.record_length),
                        f.record_length, encoded);
      done += c.point_count;
    }
    encode_seconds.push_back(std::chrono::duration<double>(Clock::now() - start).count());
  }
  const double best = *std::min_element(decode_seconds.begin(), decode_seconds.end());
  std::printf("%s: %llu points of %u bytes, %zu chunks, %zu compressed bytes\n", path.c_str(),
              static_cast<unsigned long long>(f.points), unsigned{f.record_length}, chunks.size(),
              f.bytes.size() - f.offset_to_points);
  const auto points = static_cast<double>(f.points);
  std::printf("decode: best %.2f M points/s, median %.2f M points/s (%d runs)\n", points / best / 1e6,
              points / median(decode_seconds) / 1e6, repeats);
  if (layered)
    std::printf("decode of X, Y, Z alone: best %.2f M points/s, median %.2f M points/s (%d runs)\n",
                points / *std::min_element(coordinates_seconds.begin(), coordinates_seconds.end()) / 1e6,
                points / median(coordinates_seconds) / 1e6, repeats);
  std::printf("encode: median %.2f M points/s, %zu bytes (%d runs)\n", points / median(encode_seconds) / 1e6,
              encoded.size(), static_cast<int>(encode_seconds.size()));
  return 0;
} catch (const vola::Error& e) {
  std::fprintf(stderr, "vola_laz_bench: %s\n", e.what());
  return 1;
}
