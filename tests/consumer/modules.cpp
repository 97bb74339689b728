// vola::raycast and vola::analysis from the installed package, on a tree of two voxel
// groups: a ray finds the first, components count both.
#include <vola/analysis/components.hpp>
#include <vola/builder.hpp>
#include <vola/raycast/ray_caster.hpp>

#include <cstdio>
#include <vector>

int main() {
  const std::vector<vola::Voxel> voxels{{1, 1, 1}, {1, 1, 2}, {10, 10, 10}};
  const vola::Tree tree = vola::build_from_voxels(voxels, 2);
  const vola::raycast::RayCaster caster(tree);
  const auto hit = caster.cast(vola::raycast::Ray{{1.5, 1.5, -3.0}, {0, 0, 1}});
  const auto labels = vola::analysis::label_components(tree, vola::analysis::Connectivity::faces);
  std::printf("hit %s, components %zu\n", hit ? "yes" : "no", labels.components.size());
  return hit && hit->voxel == vola::Voxel{1, 1, 1} && labels.components.size() == 2 ? 0 : 1;
}
