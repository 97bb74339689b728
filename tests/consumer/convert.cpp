// vola::convert from the installed package: a text file of points to a .vol, as
// `vola convert points.xyz points.vol --voxel-size 0.5` writes it.
#include <vola/convert.hpp>
#include <vola/file.hpp>

#include <cstdio>
#include <fstream>
#include <string>

int main(int argc, char** argv) {
  const std::string dir = argc > 1 ? argv[1] : ".";
  std::ofstream(dir + "/points.xyz") << "0.1 0.2 0.3\n5.0 5.0 5.0\n5.1 5.1 5.1\n";
  vola::ConvertOptions options;
  options.voxel_size = 0.5;
  vola::ConvertReport report;
  vola::convert_file(dir + "/points.xyz", dir + "/converted.vol", options, {}, &report);
  const vola::Tree tree = vola::read(dir + "/converted.vol");
  std::printf("points %llu, voxels %llu\n", static_cast<unsigned long long>(report.build.points_in),
              static_cast<unsigned long long>(tree.voxel_count()));
  return report.build.points_in == 3 && tree.voxel_count() == 2 ? 0 : 1;
}
