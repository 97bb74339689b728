// The README's five-line example, built against the installed package.
#include <vola/vola.hpp>

#include <cstdio>

int main(int argc, char** argv) {
  const char* path = argc > 1 ? argv[1] : "points.vol";
  vola::PointCloud cloud;  cloud.xyz = {0.1, 0.2, 0.3,  5.0, 5.0, 5.0};
  vola::BuildOptions options;  options.quantization = vola::Quantization::grid;  options.voxel_size = 0.5;
  vola::write(vola::build(cloud, options), path);
  vola::Tree tree = vola::open_mapped(path);
  bool hit = tree.contains(0, 0, 0);  auto row = tree.rank({10, 10, 10});
  std::printf("voxels %llu, (0,0,0) %s, (10,10,10) rank %llu\n", static_cast<unsigned long long>(tree.voxel_count()),
              hit ? "occupied" : "empty", static_cast<unsigned long long>(row.value_or(~0ull)));
  return hit && row == 1 && tree.voxel_count() == 2 ? 0 : 1;
}
