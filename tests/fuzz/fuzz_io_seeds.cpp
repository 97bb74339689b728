// Seeds for fuzz_io_read: the PLY, PCD, KITTI, binvox and (small) LAS files of the shared data folder
// (beside golden/) and small files of every variant written here, each prefixed with
// the byte that picks its reader (see fuzz_io_read.cpp). Linked into fuzz_io_replay in
// place of fuzz_seeds.cpp, so that replay_main.cpp serves both entry points.
#include <lzf.h>

#include <algorithm>
#include <cstring>
#include <fstream>
#include <iterator>
#include <stdexcept>
#include <string>

#include "fuzz_seeds.hpp"
#include "vola/io/binvox.hpp"
#include "vola/vola.hpp"

namespace vola_fuzz {

namespace {

enum Reader : std::uint8_t { kPly = 0, kPcd = 1, kKitti = 2, kNpy = 3, kBinvox = 4, kLas = 5, kText = 6 };
using Bytes = std::vector<std::uint8_t>;

Seed seed(const std::string& name, Reader reader, const Bytes& file) {
  Bytes bytes{reader};
  bytes.insert(bytes.end(), file.begin(), file.end());
  return {name, std::move(bytes)};
}

Bytes text(const std::string& s) { return Bytes(s.begin(), s.end()); }

template <class T>
void put(Bytes& out, T value, bool big_endian = false) {
  std::uint8_t raw[sizeof(T)];
  std::memcpy(raw, &value, sizeof(T));
  for (std::size_t i = 0; i < sizeof(T); ++i) out.push_back(raw[big_endian ? sizeof(T) - 1 - i : i]);
}

// Four coloured vertices and two faces (a quad and a triangle), plus a skipped list.
Bytes ply(const std::string& encoding) {
  const bool big = encoding == "binary_big_endian";
  Bytes b = text("ply\nformat " + encoding +
                 " 1.0\ncomment seed\nelement vertex 4\nproperty float x\nproperty double y\nproperty float z\n"
                 "property uchar red\nproperty uchar green\nproperty uchar blue\nelement face 2\n"
                 "property list uchar int vertex_indices\nproperty list ushort float texcoord\nend_header\n");
  if (encoding == "ascii") {
    const Bytes body = text("0 0 0 255 0 0\n1 0 0 0 255 0\n1 1 0 0 0 255\n0 1 1 9 9 9\n4 0 1 2 3 1 0.5\n3 3 2 1 0\n");
    b.insert(b.end(), body.begin(), body.end());
    return b;
  }
  for (int v = 0; v < 4; ++v) {
    put<float>(b, static_cast<float>(v & 1), big);
    put<double>(b, v >> 1, big);
    put<float>(b, v == 3 ? 1.0f : 0.0f, big);
    for (int c = 0; c < 3; ++c) b.push_back(static_cast<std::uint8_t>(60 * v + c));
  }
  b.push_back(4);
  for (int v : {0, 1, 2, 3}) put<std::int32_t>(b, v, big);
  put<std::uint16_t>(b, 1, big);
  put<float>(b, 0.5f, big);
  b.push_back(3);
  for (int v : {3, 2, 1}) put<std::int32_t>(b, v, big);
  put<std::uint16_t>(b, 0, big);
  return b;
}

// Four points with x y z, a packed rgb, a COUNT 2 field and intensity, one of them NaN.
Bytes pcd(const std::string& kind) {
  Bytes b = text("# .PCD v0.7\nVERSION 0.7\nFIELDS x y z rgb pair intensity\nSIZE 4 4 4 4 2 4\nTYPE F F F U I F\n"
                 "COUNT 1 1 1 1 2 1\nWIDTH 2\nHEIGHT 2\nVIEWPOINT 0 0 0 1 0 0 0\nPOINTS 4\nDATA " + kind + "\n");
  const float xyz[4][3] = {{0, 0, 0}, {1, 2, 3}, {__builtin_nanf(""), 0, 0}, {-1, 0.5f, 9}};
  if (kind == "ascii") {
    const Bytes body = text("0 0 0 16711680 1 2 0.5\n1 2 3 65280 -3 4 1\nnan 0 0 255 5 6 2\n-1 0.5 9 0 7 8 3\n");
    b.insert(b.end(), body.begin(), body.end());
    return b;
  }
  Bytes records;
  auto field = [&](int f, int i) {
    if (f < 3) put<float>(records, xyz[i][f]);
    else if (f == 3) put<std::uint32_t>(records, 0x00FF00FFu >> i);
    else if (f == 4) {
      put<std::int16_t>(records, static_cast<std::int16_t>(i));
      put<std::int16_t>(records, static_cast<std::int16_t>(-i));
    } else put<float>(records, 0.25f * static_cast<float>(i));
  };
  if (kind == "binary") {
    for (int i = 0; i < 4; ++i)
      for (int f = 0; f < 6; ++f) field(f, i);
    b.insert(b.end(), records.begin(), records.end());
    return b;
  }
  for (int f = 0; f < 6; ++f)
    for (int i = 0; i < 4; ++i) field(f, i);
  Bytes packed(2 * records.size() + 64);
  const unsigned n = lzf_compress(records.data(), static_cast<unsigned>(records.size()), packed.data(),
                                  static_cast<unsigned>(packed.size()));
  if (n == 0) throw std::runtime_error("lzf_compress failed on a seed");
  put<std::uint32_t>(b, n);
  put<std::uint32_t>(b, static_cast<std::uint32_t>(records.size()));
  b.insert(b.end(), packed.begin(), packed.begin() + n);
  return b;
}

Bytes kitti() {
  Bytes b;
  for (int i = 0; i < 8; ++i)
    for (float v : {static_cast<float>(i), -static_cast<float>(i) * 0.5f, 1.5f, 0.125f * static_cast<float>(i)}) put<float>(b, v);
  return b;
}

Bytes npy(const std::string& dtype, const std::string& shape, const Bytes& data, bool fortran = false) {
  // A structured dtype (a list of fields) goes in as it is, a plain one quoted.
  const std::string descr = dtype.starts_with("[") ? dtype : "'" + dtype + "'";
  std::string header = "{'descr': " + descr + ", 'fortran_order': " + (fortran ? "True" : "False") +
                       ", 'shape': " + shape + ", }";
  while ((11 + header.size()) % 64 != 0) header += ' ';
  header += '\n';
  Bytes b = {0x93, 'N', 'U', 'M', 'P', 'Y', 1, 0};
  put<std::uint16_t>(b, static_cast<std::uint16_t>(header.size()));
  const Bytes h = text(header);
  b.insert(b.end(), h.begin(), h.end());
  b.insert(b.end(), data.begin(), data.end());
  return b;
}

Bytes read_all(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw std::runtime_error("cannot open " + path.string());
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

}  // namespace

std::vector<Seed> synthetic_seeds() {
  std::vector<Seed> seeds;
  for (const std::string encoding : {"ascii", "binary_little_endian", "binary_big_endian"})
    seeds.push_back(seed("ply_" + encoding, kPly, ply(encoding)));
  for (const std::string kind : {"ascii", "binary", "binary_compressed"}) seeds.push_back(seed("pcd_" + kind, kPcd, pcd(kind)));
  seeds.push_back(seed("kitti", kKitti, kitti()));
  Bytes cells(4 * 4 * 4);
  for (std::size_t i = 0; i < cells.size(); ++i) cells[i] = i % 3 == 0;
  seeds.push_back(seed("npy_grid_u1", kNpy, npy("|u1", "(4, 4, 4)", cells)));
  Bytes floats;
  for (std::size_t i = 0; i < 2 * 3 * 4; ++i) put<float>(floats, i % 2 ? 0.0f : -1.5f, true);
  seeds.push_back(seed("npy_grid_f4_fortran", kNpy, npy(">f4", "(2, 3, 4)", floats, true)));
  Bytes points;
  for (int i = 0; i < 12; ++i) put<double>(points, 0.5 * i);
  seeds.push_back(seed("npy_points", kNpy, npy("<f8", "(3, 4)", points)));
  Bytes records;
  for (int i = 0; i < 4; ++i) {
    for (int a = 0; a < 3; ++a) put<double>(records, 1.5 * i + a);
    put<std::uint16_t>(records, static_cast<std::uint16_t>(100 * i));
    records.insert(records.end(), {1, 2, 3, 0});
  }
  seeds.push_back(seed("npy_records", kNpy,
                       npy("[('X', '<f8'), ('Y', '<f8'), ('Z', '<f8'), ('Intensity', '<u2'), ('rgb', '|u1', (3,)), ('', '|V1')]",
                           "(4,)", records)));
  std::vector<vola::Voxel> voxels;
  for (std::uint32_t i = 0; i < 20; ++i) voxels.push_back({i % 7, (i * 3) % 11, i % 5});
  vola::Tree tree = vola::build_from_voxels(voxels, 2);
  tree.set_frame({vola::Quantization::grid, {1, 2, 3}, 0.5});
  seeds.push_back(seed("binvox", kBinvox, vola::io::serialize_binvox(tree)));
  seeds.push_back(seed("text", kText, text("# x y z payload attribute\n1.5 2 3 7 0.25\n-4e3,5.5;6 255 1e-3\n"
                                           "\t7 8 9 0 -2\r\n// comment\n\n1 1 1 1 1")));
  return seeds;
}

// The shared data folder's PLY, PCD, KITTI and binvox files; `golden` is
// $VOLA_SHARED/golden, the data folder its sibling.
std::vector<Seed> golden_seeds(const std::filesystem::path& golden) {
  std::vector<Seed> seeds;
  const auto data = golden.parent_path() / "data";
  if (!std::filesystem::is_directory(data)) return seeds;
  const std::pair<std::string, Reader> kinds[] = {
      {"ply", kPly}, {"pcd", kPcd}, {"kitti", kKitti}, {"binvox", kBinvox}, {"las", kLas}};
  for (const auto& [folder, reader] : kinds) {
    if (!std::filesystem::is_directory(data / folder)) continue;
    for (const auto& entry : std::filesystem::recursive_directory_iterator(data / folder)) {
      const auto extension = entry.path().extension().string();
      // LAS seeds stay small so that each mutation parses quickly.
      const bool wanted = entry.is_regular_file() &&
                          (extension == "." + folder || (reader == kKitti && extension == ".bin")) &&
                          (reader != kLas || entry.file_size() <= 128 * 1024);
      if (wanted) seeds.push_back(seed(folder + "_" + entry.path().filename().string(), reader, read_all(entry.path())));
    }
  }
  std::sort(seeds.begin(), seeds.end(), [](const Seed& a, const Seed& b) { return a.name < b.name; });
  return seeds;
}

}  // namespace vola_fuzz
