#include <cmath>
#include <string>

#include "vola/error.hpp"
#include "vola/frame.hpp"

namespace vola {
VOLA_INLINE_NAMESPACE_BEGIN

namespace {
void check_depth(int depth) {
  if (depth < kMinDepth || depth > kMaxDepth)
    throw InvalidArgument("depth " + std::to_string(depth) + " is outside 1..10");
}
}  // namespace

Quantizer Quantizer::toolkit(const Box& bbox, int depth) {
  check_depth(depth);
  Quantizer q;
  q.mode_ = Quantization::toolkit;
  q.depth_ = depth;
  double longest = 0.0;
  for (int a = 0; a < 3; ++a) longest = std::max(longest, bbox.max[a] - bbox.min[a]);
  for (int a = 0; a < 3; ++a) {
    q.origin_[a] = bbox.min[a];
    // Written as the reference computes it: max' = min + Lmax, then max' - min, which
    // can differ from Lmax in the last bit.
    q.scale_[a] = (bbox.min[a] + longest) - bbox.min[a];
  }
  q.degenerate_ = !(longest > 0.0);
  return q;
}

Quantizer Quantizer::grid(const Point& origin, double voxel_size, int depth) {
  check_depth(depth);
  if (!(voxel_size > 0.0) || !std::isfinite(voxel_size))
    throw InvalidArgument("voxel size must be a positive number, got " + std::to_string(voxel_size));
  for (double o : origin)
    if (!std::isfinite(o)) throw InvalidArgument("grid origin must be finite");
  Quantizer q;
  q.mode_ = Quantization::grid;
  q.depth_ = depth;
  q.origin_ = origin;
  q.scale_ = {voxel_size, voxel_size, voxel_size};
  return q;
}

bool Quantizer::to_voxel(const Point& p, Voxel& out) const noexcept {
  const double side = static_cast<double>(side_of(depth_));
  std::uint32_t v[3];
  for (int a = 0; a < 3; ++a) {
    if (!std::isfinite(p[a])) return false;
    if (mode_ == Quantization::toolkit) {
      if (degenerate_) {
        v[a] = 0;
        continue;
      }
      double n = (p[a] - origin_[a]) / scale_[a];
      n = n < 0.0 ? 0.0 : (n > 1.0 ? 1.0 : n);
      // nearbyint rounds half to even in the default rounding mode, like numpy.round.
      v[a] = static_cast<std::uint32_t>(std::nearbyint((side - 1.0) * n));
    } else {
      const double c = std::floor((p[a] - origin_[a]) / scale_[a]);
      if (!(c >= 0.0 && c < side)) return false;
      v[a] = static_cast<std::uint32_t>(c);
    }
  }
  out = Voxel{v[0], v[1], v[2]};
  return true;
}

Point Quantizer::center(const Voxel& v) const noexcept {
  const std::uint32_t c[3] = {v.x, v.y, v.z};
  Point p{};
  const double steps = static_cast<double>(side_of(depth_) - 1);
  for (int a = 0; a < 3; ++a) {
    if (mode_ == Quantization::toolkit)
      p[a] = degenerate_ ? origin_[a] : origin_[a] + static_cast<double>(c[a]) * scale_[a] / steps;
    else
      p[a] = origin_[a] + (static_cast<double>(c[a]) + 0.5) * scale_[a];
  }
  return p;
}

Frame Quantizer::frame() const noexcept {
  Frame f;
  f.quantization = mode_;
  if (mode_ == Quantization::grid) {
    f.origin = origin_;
    f.voxel_size = scale_[0];
    return f;
  }
  const double steps = static_cast<double>(side_of(depth_) - 1);
  // Depth 1 has 3 steps; a zero-extent bbox has no scale at all: call the voxel 1 unit.
  f.voxel_size = degenerate_ ? 1.0 : scale_[0] / steps;
  for (int a = 0; a < 3; ++a) f.origin[a] = origin_[a] - f.voxel_size / 2;
  return f;
}

int depth_for_extent(double extent, double voxel_size) {
  if (!(voxel_size > 0.0)) throw InvalidArgument("voxel size must be positive");
  for (int depth = kMinDepth; depth <= kMaxDepth; ++depth)
    if (extent < static_cast<double>(side_of(depth)) * voxel_size) return depth;
  throw InvalidArgument("an extent of " + std::to_string(extent) + " at voxel size " +
                        std::to_string(voxel_size) + " needs more than 4^10 voxels per axis");
}

VOLA_INLINE_NAMESPACE_END
}  // namespace vola
