#include "audio_test_support.hpp"

#include <cmath>

#include "vola/builder.hpp"

namespace vola_audio_test {

vola::Tree shoebox_tree(const Shoebox& box, double voxel_size) {
  std::vector<vola::Voxel> voxels;
  for (std::uint32_t z = box.lo[2]; z <= box.hi[2]; ++z)
    for (std::uint32_t y = box.lo[1]; y <= box.hi[1]; ++y)
      for (std::uint32_t x = box.lo[0]; x <= box.hi[0]; ++x) {
        const std::uint32_t c[3] = {x, y, z};
        bool wall = false;
        for (int a = 0; a < 3; ++a)
          wall = wall || (box.walls[2 * a] && c[a] == box.lo[a]) || (box.walls[2 * a + 1] && c[a] == box.hi[a]);
        if (wall) voxels.push_back({x, y, z});
      }
  vola::Tree tree = vola::build_from_voxels(voxels, 4);
  tree.set_frame(vola::Frame{vola::Quantization::grid, {0, 0, 0}, voxel_size});
  return tree;
}

vola_test::fs::path audio_dir() { return vola_test::golden_dir().parent_path() / "data" / "audio"; }

double t30(const std::vector<double>& ir, double rate) {
  std::vector<double> edc(ir.size() + 1, 0.0);
  for (std::size_t i = ir.size(); i-- > 0;) edc[i] = edc[i + 1] + ir[i] * ir[i];
  double n = 0, st = 0, sl = 0, stt = 0, stl = 0;
  for (std::size_t i = 0; i < ir.size(); ++i) {
    const double level = 10.0 * std::log10(edc[i] / edc[0]);
    if (level > -5.0 || level < -35.0) continue;
    const double t = static_cast<double>(i) / rate;
    n += 1, st += t, sl += level, stt += t * t, stl += t * level;
  }
  const double slope = (n * stl - st * sl) / (n * stt - st * st);  // dB per second
  return -60.0 / slope;
}

}  // namespace vola_audio_test
