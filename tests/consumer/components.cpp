// One small program per component of the installed package (find_package(vola
// COMPONENTS ...)), each linking that module alone: the component's targets, its
// third-party dependencies and the modules it uses must all resolve from the install.
#include <vola/builder.hpp>

#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

[[maybe_unused]] const std::vector<vola::Voxel> two_corners{{0, 0, 0}, {15, 15, 15}};

#if defined(VOLA_CONSUMER_TILE)
#include <vola/tile/communicator.hpp>
#include <vola/tile/point_source.hpp>
#include <vola/tile/tile_set.hpp>
#include <vola/tile/tiler.hpp>
// A generated survey tiled into a folder, then one of its points found again.
int main(int argc, char** argv) {
  if (argc < 2) return 2;
  vola::tile::SurveyOptions survey;
  survey.points = 20000;
  const auto source = vola::tile::generated_survey(survey);
  vola::tile::TileOptions options;
  options.grid.origin = survey.origin;
  options.grid.tile_size = 256.0;
  options.grid.depth = 6;
  options.output_dir = std::string(argv[1]) + "/tiles";
  options.overviews = false;
  const auto summary = vola::tile::make_tiles({source.get()}, options, *vola::tile::single_process());
  const vola::tile::TileSet set(summary.index_path);
  std::printf("tile: %llu tiles, %llu voxels\n", static_cast<unsigned long long>(summary.tiles),
              static_cast<unsigned long long>(summary.voxels));
  return summary.tiles > 0 && summary.voxels > 0 && set.index().tiles.size() == summary.tiles ? 0 : 1;
}
#elif defined(VOLA_CONSUMER_VIEWER)
#include <vola/viewer/cell_index.hpp>
// The viewer's level-of-detail cell index over a two-voxel tree.
int main() {
  const vola::Tree tree = vola::build_from_voxels(two_corners, 2);
  const vola::viewer::CellIndex cells(tree);
  std::printf("viewer: %llu cells at the finest level\n", static_cast<unsigned long long>(cells.cell_count(cells.depth() - 1)));
  return cells.cell_count(cells.depth() - 1) == 2 ? 0 : 1;
}
#elif defined(VOLA_CONSUMER_SLAM)
#include <vola/slam/trajectory_error.hpp>
// The absolute trajectory error of an estimate that is the ground truth moved rigidly: 0.
int main() {
  std::vector<vola::slam::StampedPose> truth, estimate;
  for (int i = 0; i < 5; ++i) {
    vola::slam::StampedPose p;
    p.timestamp = i;
    p.pose.translation() = Eigen::Vector3d(i, i * i * 0.1, 0.5 * i);
    truth.push_back(p);
    p.pose.translation() += Eigen::Vector3d(2, -1, 3);
    estimate.push_back(p);
  }
  const auto error = vola::slam::absolute_trajectory_error(truth, estimate);
  std::printf("slam: ATE %.2e m over %zu poses\n", error.rmse, error.pairs);
  return error.pairs == 5 && error.rmse < 1e-9 ? 0 : 1;
}
#elif defined(VOLA_CONSUMER_AUDIO)
#include <vola/audio/surface.hpp>
// The surface voxels of a solid 4x4x4 cube: all but its 2x2x2 core.
int main() {
  std::vector<vola::Voxel> cube;
  for (std::uint32_t x = 0; x < 4; ++x)
    for (std::uint32_t y = 0; y < 4; ++y)
      for (std::uint32_t z = 0; z < 4; ++z) cube.push_back({x, y, z});
  const auto surface = vola::audio::surface_voxels(vola::build_from_voxels(cube, 2));
  std::printf("audio: %zu surface voxels\n", surface.size());
  return surface.size() == 56 ? 0 : 1;
}
#elif defined(VOLA_CONSUMER_LEARN)
#include <vola/learn/occupancy.hpp>
// A tree's voxels into the network's dense input grid.
int main() {
  const vola::Tree tree = vola::build_from_voxels(two_corners, 2);
  std::vector<float> grid(8 * 8 * 8);
  vola::learn::fill_occupancy(tree, 8, 0.0, grid);
  double sum = 0;
  for (const float v : grid) sum += v;
  std::printf("learn: %g occupied cells\n", sum);
  return sum == 2 ? 0 : 1;
}
#endif
