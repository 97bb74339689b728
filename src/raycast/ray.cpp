#include "vola/raycast/ray.hpp"

#include "vola/error.hpp"

namespace vola::raycast {

void check_ray(const Ray& ray) {
  bool moves = false;
  for (int a = 0; a < 3; ++a) {
    if (!std::isfinite(ray.origin[a]) || std::abs(ray.origin[a]) > kMaxOriginMagnitude)
      throw InvalidArgument("ray origin must be finite and within 1e12 voxels of the grid");
    if (!std::isfinite(ray.direction[a])) throw InvalidArgument("ray direction must be finite");
    if (std::isfinite(1.0 / ray.direction[a])) moves = true;
  }
  if (!moves) throw InvalidArgument("ray direction must not be zero");
  if (!(ray.t_max >= 0.0)) throw InvalidArgument("ray t_max must be >= 0");
}

}  // namespace vola::raycast
