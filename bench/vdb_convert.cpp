// The peer of `vola convert POINTS.npy OUT.vol --quantize toolkit --depth 5` as a whole
// process: reads the shared benchmark's (N, 3) int16 point array (voxel coordinates of a
// 1024^3 grid), builds an OpenVDB MaskGrid through a ValueAccessor (as bench/peers.cpp
// does in process) and writes it as .vdb with OpenVDB's default compression.
// usage: vola_vdb_convert POINTS.npy OUT.vdb   (bench/convert_whole_process.sh times both)
#include <openvdb/openvdb.h>

#include <cstdint>
#include <cstring>
#include <fstream>
#include <iostream>
#include <iterator>
#include <stdexcept>
#include <string>
#include <vector>

namespace {

// The int16 values of a little-endian (N, 3) .npy file, header checked.
std::vector<std::int16_t> read_points(const std::string& path) {
  std::ifstream in(path, std::ios::binary | std::ios::ate);
  if (!in) throw std::runtime_error(path + ": cannot open");
  std::vector<char> bytes(static_cast<std::size_t>(in.tellg()));
  in.seekg(0);
  in.read(bytes.data(), static_cast<std::streamsize>(bytes.size()));
  if (bytes.size() < 10 || std::memcmp(bytes.data(), "\x93NUMPY", 6) != 0) throw std::runtime_error(path + ": not .npy");
  const std::size_t header = 10 + static_cast<unsigned char>(bytes[8]) + (static_cast<unsigned char>(bytes[9]) << 8);
  const std::string dict(bytes.data() + 10, header - 10);
  if (dict.find("'<i2'") == std::string::npos || dict.find(", 3)") == std::string::npos)
    throw std::runtime_error(path + ": expected an (N, 3) <i2 array");
  std::vector<std::int16_t> xyz((bytes.size() - header) / 2);
  std::memcpy(xyz.data(), bytes.data() + header, xyz.size() * 2);
  return xyz;
}

}  // namespace

int main(int argc, char** argv) try {
  if (argc != 3) {
    std::cerr << "usage: vola_vdb_convert POINTS.npy OUT.vdb\n";
    return 2;
  }
  openvdb::initialize();
  const std::vector<std::int16_t> xyz = read_points(argv[1]);
  openvdb::MaskGrid::Ptr grid = openvdb::MaskGrid::create();
  auto accessor = grid->getAccessor();
  for (std::size_t i = 0; i + 2 < xyz.size(); i += 3) accessor.setValueOn(openvdb::Coord(xyz[i], xyz[i + 1], xyz[i + 2]));
  openvdb::io::File file(argv[2]);
  file.write(openvdb::GridCPtrVec{grid});
  file.close();
  return 0;
} catch (const std::exception& e) {
  std::cerr << "vola_vdb_convert: " << e.what() << "\n";
  return 1;
}
