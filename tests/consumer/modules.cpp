// vola::raycast, vola::analysis and vola::map from the installed package, on a tree of
// two voxel groups: a ray finds the first, components count both; and one scan into an
// occupancy map, frozen to a state map whose occupied tree is its hit voxel.
#include <vola/analysis/components.hpp>
#include <vola/builder.hpp>
#include <vola/map/occupancy_map.hpp>
#include <vola/map/state_map.hpp>
#include <vola/raycast/ray_caster.hpp>

#include <cstdio>
#include <vector>

int main() {
  const std::vector<vola::Voxel> voxels{{1, 1, 1}, {1, 1, 2}, {10, 10, 10}};
  const vola::Tree tree = vola::build_from_voxels(voxels, 2);
  const vola::raycast::RayCaster caster(tree);
  const auto hit = caster.cast(vola::raycast::Ray{{1.5, 1.5, -3.0}, {0, 0, 1}});
  const auto labels = vola::analysis::label_components(tree, vola::analysis::Connectivity::faces);
  vola::map::OccupancyMap map(0.5);
  const std::vector<double> scan{2.25, 0.25, 0.25};
  map.insert_scan(scan, vola::Point{0.25, 0.25, 0.25});
  const vola::Tree occupied = vola::map::occupied_tree(vola::map::freeze(map));
  std::printf("hit %s, components %zu, map voxels %zu (%llu occupied)\n", hit ? "yes" : "no", labels.components.size(),
              map.size(), static_cast<unsigned long long>(occupied.voxel_count()));
  return hit && hit->voxel == vola::Voxel{1, 1, 1} && labels.components.size() == 2 && map.size() == 5 &&
                 occupied.voxel_count() == 1
             ? 0
             : 1;
}
