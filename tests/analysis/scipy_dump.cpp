// Writes grids and our component labels for tests/analysis/compare_scipy.py:
//   NAME.npy            the dense 0/1 grid (vola::io::write_npy_grid, indexed [x, y, z])
//   NAME.cC.npy         int64 (n, 4) rows x, y, z, label of every voxel, C = 6, 18, 26
// Grids: random ones at depths 1..3 over several fill ratios, then each .vol given on
// the command line (depth <= 4).
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <random>
#include <string>
#include <vector>

#include "vola/analysis/components.hpp"
#include "vola/builder.hpp"
#include "vola/file.hpp"
#include "vola/io/export.hpp"

namespace {

void write_rows(const vola::Tree& tree, const vola::analysis::ComponentLabels& labels, const std::string& path) {
  std::vector<std::int64_t> rows;
  std::size_t rank = 0;
  tree.for_each_voxel([&](const vola::Voxel& v) {
    rows.insert(rows.end(), {std::int64_t{v.x}, std::int64_t{v.y}, std::int64_t{v.z}, std::int64_t{labels.label[rank++]}});
  });
  // NPY 1.0: magic, version, header length, a Python dict padded to 64 bytes.
  std::string header = "{'descr': '<i8', 'fortran_order': False, 'shape': (" + std::to_string(rows.size() / 4) + ", 4), }";
  while ((10 + header.size() + 1) % 64) header += ' ';
  header += '\n';
  std::ofstream out(path, std::ios::binary);
  out.write("\x93NUMPY\x01\x00", 8);
  const unsigned char len[2] = {static_cast<unsigned char>(header.size() & 255), static_cast<unsigned char>(header.size() >> 8)};
  out.write(reinterpret_cast<const char*>(len), 2);
  out << header;
  out.write(reinterpret_cast<const char*>(rows.data()), static_cast<std::streamsize>(rows.size() * sizeof(std::int64_t)));
  if (!out) throw std::runtime_error("cannot write " + path);
}

void dump(const vola::Tree& tree, const std::filesystem::path& dir, const std::string& name) {
  vola::io::write_npy_grid(tree, (dir / (name + ".npy")).string());
  for (int c : {6, 18, 26})
    write_rows(tree, vola::analysis::label_components(tree, vola::analysis::parse_connectivity(c)),
               (dir / (name + ".c" + std::to_string(c) + ".npy")).string());
}

}  // namespace

int main(int argc, char** argv) {
  if (argc < 2) {
    std::fprintf(stderr, "usage: %s OUTDIR [FILE.vol...]\n", argv[0]);
    return 2;
  }
  const std::filesystem::path dir(argv[1]);
  std::filesystem::create_directories(dir);
  std::mt19937_64 rng(20261121);
  for (int depth = 1; depth <= 3; ++depth)
    for (double p : {0.1, 0.25, 0.3116, 0.5, 0.8}) {  // 0.3116: the 3D site percolation threshold
      std::bernoulli_distribution keep(p);
      std::vector<vola::Key> keys;
      const std::uint32_t s = vola::side_of(depth);
      for (std::uint32_t z = 0; z < s; ++z)
        for (std::uint32_t y = 0; y < s; ++y)
          for (std::uint32_t x = 0; x < s; ++x)
            if (keep(rng)) keys.push_back(vola::encode(x, y, z));
      dump(vola::build_from_keys(std::move(keys), depth), dir,
           "random_d" + std::to_string(depth) + "_p" + std::to_string(static_cast<int>(p * 10000)));
    }
  for (int i = 2; i < argc; ++i)
    dump(vola::read(argv[i]), dir, std::filesystem::path(argv[i]).stem().string());
  return 0;
}
