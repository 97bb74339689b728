#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <string>

#include "vola/error.hpp"
#include "vola/frame.hpp"

namespace vola {
VOLA_INLINE_NAMESPACE_BEGIN

namespace {
// A length as %g writes it: std::to_string prints a voxel size of 1e-9 as "0.000000".
std::string short_number(double v) {
  char text[32];
  std::snprintf(text, sizeof text, "%g", v);
  return text;
}

void check_depth(int depth) {
  if (depth < kMinDepth || depth > kMaxDepth)
    VOLA_THROW(InvalidArgument("depth " + std::to_string(depth) + " is outside 1..10"));
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
    VOLA_THROW(InvalidArgument("voxel size must be a positive number, got " + short_number(voxel_size)));
  for (double o : origin)
    if (!std::isfinite(o)) VOLA_THROW(InvalidArgument("grid origin must be finite"));
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
      // NaN (0/0: an axis whose (min + Lmax) - min rounds to 0) goes to voxel 0, as the
      // reference's 0/0 does; casting it would be undefined.
      n = n > 0.0 ? (n > 1.0 ? 1.0 : n) : 0.0;
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

namespace {

// Quantizer::to_keys for one mode; place(point, v) gives the voxel like to_voxel.
template <class Place>
std::uint64_t keys_of(std::span<const double> xyz, std::vector<Key>& keys, std::vector<std::uint32_t>* kept,
                      Place place) {
  const std::size_t n = xyz.size() / 3;
  keys.reserve(keys.size() + n);
  if (kept) kept->reserve(kept->size() + n);
  std::uint64_t dropped = 0;
  const double* p = xyz.data();
  for (std::size_t i = 0; i < n; ++i, p += 3) {
    std::uint32_t v[3];
    if (!(std::isfinite(p[0]) && std::isfinite(p[1]) && std::isfinite(p[2]) && place(p, v))) {
      ++dropped;
      continue;
    }
    keys.push_back(encode(v[0], v[1], v[2]));
    if (kept) kept->push_back(static_cast<std::uint32_t>(i));
  }
  return dropped;
}

}  // namespace

std::uint64_t Quantizer::to_keys(std::span<const double> xyz, std::vector<Key>& keys,
                                 std::vector<std::uint32_t>* kept) const {
  const double side = static_cast<double>(side_of(depth_));
  const Point origin = origin_, scale = scale_;
  if (mode_ == Quantization::toolkit && degenerate_)
    return keys_of(xyz, keys, kept, [](const double*, std::uint32_t* v) {
      v[0] = v[1] = v[2] = 0;
      return true;
    });
  if (mode_ == Quantization::toolkit)
    return keys_of(xyz, keys, kept, [&](const double* p, std::uint32_t* v) {
      for (int a = 0; a < 3; ++a) {
        double n = (p[a] - origin[a]) / scale[a];
        n = n > 0.0 ? (n > 1.0 ? 1.0 : n) : 0.0;  // NaN (0/0) to 0, as to_voxel
        v[a] = static_cast<std::uint32_t>(std::nearbyint((side - 1.0) * n));
      }
      return true;
    });
  return keys_of(xyz, keys, kept, [&](const double* p, std::uint32_t* v) {
    for (int a = 0; a < 3; ++a) {
      const double c = std::floor((p[a] - origin[a]) / scale[a]);
      if (!(c >= 0.0 && c < side)) return false;
      v[a] = static_cast<std::uint32_t>(c);
    }
    return true;
  });
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
  // So too when the x scale is not usable (0 when (min + Lmax) - min rounds away, NaN
  // from a header bbox holding NaN), and put the origin at 0 on an axis without one:
  // the frame is written in the extension and must read back.
  const double size = scale_[0] / steps;
  f.voxel_size = !degenerate_ && size > 0.0 && std::isfinite(size) ? size : 1.0;
  for (int a = 0; a < 3; ++a) {
    const double origin = origin_[a] - f.voxel_size / 2;
    f.origin[a] = std::isfinite(origin) ? origin : 0.0;
  }
  return f;
}

Box Quantizer::cell_box(const Voxel& v) const noexcept {
  const std::uint32_t c[3] = {v.x, v.y, v.z};
  const double inf = std::numeric_limits<double>::infinity();
  const std::uint32_t last = side_of(depth_) - 1;
  const double steps = static_cast<double>(last);
  Box box;
  for (int a = 0; a < 3; ++a) {
    if (mode_ == Quantization::grid) {
      box.min[a] = origin_[a] + static_cast<double>(c[a]) * scale_[a];
      box.max[a] = origin_[a] + static_cast<double>(c[a] + 1) * scale_[a];
    } else if (degenerate_) {
      box.min[a] = c[a] == 0 ? -inf : inf;
      box.max[a] = c[a] == 0 ? inf : -inf;
    } else {
      // Voxel k holds (S-1)(p - min)/scale in [k - 1/2, k + 1/2]: face k - 1/2 is
      // computed by the same expression for both voxels that share it (the step first,
      // so that no product overflows where the faces themselves are finite).
      const double k = static_cast<double>(c[a]), step = scale_[a] / steps;
      box.min[a] = c[a] == 0 ? -inf : origin_[a] + (k - 0.5) * step;
      box.max[a] = c[a] >= last ? inf : origin_[a] + ((k + 1.0) - 0.5) * step;
    }
  }
  return box;
}

bool Quantizer::voxel_range(const Box& box, Voxel& first, Voxel& last) const noexcept {
  const double side = static_cast<double>(side_of(depth_));
  std::uint32_t lo[3], hi[3];
  for (int a = 0; a < 3; ++a) {
    if (!(box.min[a] <= box.max[a])) return false;
    if (mode_ == Quantization::toolkit && degenerate_) {
      lo[a] = hi[a] = 0;
      continue;
    }
    // Position t in voxel units such that voxel k covers [k, k + 1]: voxels
    // ceil(t_min) - 1 .. floor(t_max) touch the box. Widened by what the rounding of this
    // arithmetic and of cell_box's faces can shift (a few ulps of the coordinates, which
    // exceed a voxel only when the voxel is below the coordinates' resolution). Where
    // the arithmetic fails (an overflowing or zero scale) the whole axis is the range:
    // a superset is always correct.
    const double shift = mode_ == Quantization::toolkit ? 0.5 : 0.0;
    const double per_unit = mode_ == Quantization::toolkit ? (side - 1.0) / scale_[a] : 1.0 / scale_[a];
    const double t_min = (box.min[a] - origin_[a]) * per_unit + shift;
    const double t_max = (box.max[a] - origin_[a]) * per_unit + shift;
    const double eps = 8 * std::numeric_limits<double>::epsilon();
    const double reach = std::max(std::abs(box.min[a]), std::abs(box.max[a])) * per_unit + std::abs(origin_[a]) * per_unit;
    const double rounding = eps * (reach + std::max(std::abs(t_min), std::abs(t_max)));
    double from = std::ceil(t_min - rounding) - 1.0;
    double to = std::floor(t_max + rounding);
    if (!std::isfinite(per_unit) || std::isnan(from) || std::isnan(to)) {
      from = 0.0;
      to = side - 1.0;
    }
    if (mode_ == Quantization::grid && (to < 0.0 || from > side - 1.0)) return false;
    // Toolkit clamps: everything below the bbox lands in voxel 0, above it in S-1.
    from = std::clamp(from, 0.0, side - 1.0);
    to = std::clamp(to, 0.0, side - 1.0);
    lo[a] = static_cast<std::uint32_t>(from);
    hi[a] = static_cast<std::uint32_t>(to);
  }
  first = Voxel{lo[0], lo[1], lo[2]};
  last = Voxel{hi[0], hi[1], hi[2]};
  return true;
}

int depth_for_extent(double extent, double voxel_size) {
  if (!(voxel_size > 0.0)) VOLA_THROW(InvalidArgument("voxel size must be positive"));
  for (int depth = kMinDepth; depth <= kMaxDepth; ++depth)
    if (extent < static_cast<double>(side_of(depth)) * voxel_size) return depth;
  VOLA_THROW(InvalidArgument("an extent of " + short_number(extent) + " at voxel size " + short_number(voxel_size) +
                             " needs " + short_number(std::ceil(extent / voxel_size)) +
                             " voxels per axis, more than the 4^10 = 1048576 of depth 10"));
}

VOLA_INLINE_NAMESPACE_END
}  // namespace vola
