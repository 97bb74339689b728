// Runs the mesh fuzz entry point without libFuzzer: hand-made seeds (a box, a sphere,
// triangles on cell faces, NaN and infinite vertices, huge triangles, in both number
// encodings) and N seeded random mutations of them. Used by ctest; a crash or an abort
// fails it.
//
//   fuzz_mesh_replay [--mutations N] [--seed S] [FILE...]
//   fuzz_mesh_replay --write-corpus DIR        (seeds for a libFuzzer run)
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <limits>
#include <random>
#include <string>
#include <vector>

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size);

namespace {

using Bytes = std::vector<std::uint8_t>;

void put_double(Bytes& b, double v) {
  std::uint8_t raw[8];
  std::memcpy(raw, &v, 8);
  b.insert(b.end(), raw, raw + 8);
}
void put_fixed(Bytes& b, double v) {
  const auto i = static_cast<std::int16_t>(std::lround(v * 64));
  b.push_back(static_cast<std::uint8_t>(i & 0xFF));
  b.push_back(static_cast<std::uint8_t>((i >> 8) & 0xFF));
}

// flags: bit 0 grid, bit 1 solid, bit 2 fixed point, bits 3.. depth - 1.
Bytes seed(bool grid, bool solid, bool fixed, int depth, const std::vector<double>& frame, double base,
           const std::vector<double>& coordinates) {
  Bytes b{static_cast<std::uint8_t>((grid ? 1 : 0) | (solid ? 2 : 0) | (fixed ? 4 : 0) | ((depth - 1) << 3))};
  const auto put = [&](double v) { fixed ? put_fixed(b, v) : put_double(b, v); };
  for (double v : frame) put(v);
  put(base);
  for (double v : coordinates) put(v);
  return b;
}

std::vector<double> box_triangles(double lo, double hi) {
  const auto c = [&](int i) { return std::vector<double>{i & 1 ? hi : lo, i & 2 ? hi : lo, i & 4 ? hi : lo}; };
  const int faces[6][4] = {{0, 2, 3, 1}, {4, 5, 7, 6}, {0, 1, 5, 4}, {2, 6, 7, 3}, {0, 4, 6, 2}, {1, 3, 7, 5}};
  std::vector<double> out;
  for (const auto& f : faces)
    for (int k : {f[0], f[1], f[2], f[0], f[2], f[3]})
      for (double v : c(k)) out.push_back(v);
  return out;
}

std::vector<Bytes> seeds() {
  const double nan = std::numeric_limits<double>::quiet_NaN(), inf = std::numeric_limits<double>::infinity();
  const std::vector<double> toolkit_frame{0, 0, 0, 4, 4, 4}, grid_frame{-1, -1, -1, 0.5};
  std::vector<Bytes> out;
  for (bool fixed : {false, true})
    for (int depth : {1, 2, 3}) {
      out.push_back(seed(false, true, fixed, depth, toolkit_frame, 0, box_triangles(0.5, 3.5)));
      out.push_back(seed(true, true, fixed, depth, grid_frame, -1, box_triangles(0, 2)));
      // On cell faces of the grid (faces at -1 + k/2), and exactly along a cell edge.
      out.push_back(seed(true, false, fixed, depth, grid_frame, 0,
                         {0, 0, 0.5, 1, 0, 0.5, 0, 1, 0.5, 0.5, 0.5, -3, 0.5, 0.5, 3, 2, 2, 0}));
      out.push_back(seed(false, false, fixed, depth, toolkit_frame, 9,
                         {-100, -50, 2, 300, 1, 2, 4, 500, 2.25, 1, 1, 1, 1, 1, 1, 3, 3, 3}));
    }
  out.push_back(seed(false, true, false, 2, toolkit_frame, nan,
                     {nan, 0, 0, 1, 1, 1, 0, 1, 0, inf, 1, 1, 2, 2, 2, 3, 3, -inf, 1e300, 1, 1, 2, 2, 2, 3, 3, 3}));
  out.push_back(seed(true, false, false, 3, {0, 0, 0, 1e-300}, 0, {0, 0, 0, 1e-300, 0, 0, 0, 1e-300, 0}));
  out.push_back(seed(false, false, false, 3, {5, 5, 5, 5, 5, 5}, 5, {1, 2, 3, 4, 5, 6, 7, 8, 9}));
  // Once findings: a NaN bbox minimum (face cache vs cell_box), a bbox of 1e-307
  // (products underflowing in the overlap test).
  out.push_back(seed(false, true, false, 2, {nan, 7e-323, 1.8e-322, 1.3e-231, 1.3e-231, 1.3e-231}, 3e-322,
                     {-2.7e154, -2.7e154, -2.7e154, -2.7e154, 7e-251, -2.7e154, 7e-251, 7e-251, -2.7e154}));
  out.push_back(seed(false, true, false, 2, {0, 0, 0, 0, 1.787e-307, 1.787e-307}, 0,
                     {1.77e-307, 1.77e-307, 1.77e-307, 1.77e-307, 0, 1.355e-312, 1.785e-307, 1.785e-307, 1.77e-307}));
  // A bbox near the largest double: cell faces once overflowed.
  out.push_back(seed(false, true, false, 2, {2e-314, 0, -2.4e307, 1.4e-309, 2.8e-306, 2.7e-312}, 0,
                     {6e-311, 0, 1.4e-312, 3.6e-313, 2e-314, 0, 0, 5.3e-315, 0}));
  return out;
}

void mutate(Bytes& b, std::mt19937_64& rng) {
  for (int n = 1 + static_cast<int>(rng() % 4); n > 0; --n) {
    if (b.empty()) b.push_back(0);
    const std::size_t at = rng() % b.size();
    switch (rng() % 6) {
      case 0: b[at] ^= static_cast<std::uint8_t>(1u << (rng() % 8)); break;
      case 1: b[at] = static_cast<std::uint8_t>(rng()); break;
      case 2: b.resize(at); break;
      case 3: b.insert(b.begin() + static_cast<std::ptrdiff_t>(at), static_cast<std::uint8_t>(rng())); break;
      case 4: b.erase(b.begin() + static_cast<std::ptrdiff_t>(at)); break;
      default: {  // copy a run of bytes elsewhere (a vertex onto another)
        const std::size_t from = rng() % b.size(), len = std::min<std::size_t>(1 + rng() % 16, b.size() - from);
        const Bytes run(b.begin() + static_cast<std::ptrdiff_t>(from), b.begin() + static_cast<std::ptrdiff_t>(from + len));
        for (std::size_t i = 0; i < run.size() && at + i < b.size(); ++i) b[at + i] = run[i];
      }
    }
  }
}

}  // namespace

int main(int argc, char** argv) {
  long mutations = 20000;
  std::uint64_t seed_value = 1;
  std::vector<std::string> files;
  std::string corpus;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    if (a == "--mutations" && i + 1 < argc) mutations = std::stol(argv[++i]);
    else if (a == "--seed" && i + 1 < argc) seed_value = std::stoull(argv[++i]);
    else if (a == "--write-corpus" && i + 1 < argc) corpus = argv[++i];
    else files.push_back(a);
  }
  if (!corpus.empty()) {
    std::filesystem::create_directories(corpus);
    int n = 0;
    for (const Bytes& b : seeds())
      std::ofstream(std::filesystem::path(corpus) / ("seed" + std::to_string(n++)), std::ios::binary)
          .write(reinterpret_cast<const char*>(b.data()), static_cast<std::streamsize>(b.size()));
    std::printf("%d seeds written to %s\n", n, corpus.c_str());
    return 0;
  }
  if (!files.empty()) {
    for (const std::string& f : files) {
      std::ifstream in(f, std::ios::binary);
      const Bytes b{std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
      LLVMFuzzerTestOneInput(b.data(), b.size());
    }
    std::printf("%zu files replayed\n", files.size());
    return 0;
  }
  const std::vector<Bytes> base = seeds();
  for (const Bytes& b : base) LLVMFuzzerTestOneInput(b.data(), b.size());
  std::mt19937_64 rng(seed_value);
  for (long i = 0; i < mutations; ++i) {
    Bytes b = base[static_cast<std::size_t>(rng() % base.size())];
    mutate(b, rng);
    LLVMFuzzerTestOneInput(b.data(), b.size());
  }
  std::printf("%zu seeds and %ld mutations: no finding\n", base.size(), mutations);
  return 0;
}
