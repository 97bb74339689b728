#include "vola/setops.hpp"

#include <algorithm>
#include <cmath>
#include <iterator>
#include <optional>
#include <vector>

#include "emit.hpp"
#include "vola/error.hpp"

namespace vola {
VOLA_INLINE_NAMESPACE_BEGIN

namespace {

bool same_frame(const Frame& a, const Frame& b) {
  const double tolerance = 1e-9 * std::max(std::abs(a.voxel_size), std::abs(b.voxel_size));
  if (std::abs(a.voxel_size - b.voxel_size) > tolerance) return false;
  for (int i = 0; i < 3; ++i)
    if (std::abs(a.origin[i] - b.origin[i]) > tolerance) return false;
  return true;
}

// The keys of two trees on one lattice: grids of one voxel size whose origins differ by
// whole voxels (maps from separate `vola map` runs, whose origins follow their data; a
// map and its OctoMap round trip) hold the same places under different indices. Both
// sets of voxels are moved to the lower origin, on the smallest depth that holds them.
struct OneLattice {
  std::vector<Key> a, b;
  int depth = 0;
  Frame frame;
};

std::optional<OneLattice> on_one_lattice(const Tree& a, const Tree& b, const char* what) {
  const std::optional<Frame>& fa = a.stored_frame();
  const std::optional<Frame>& fb = b.stored_frame();
  if (!fa || !fb || fa->quantization != Quantization::grid || fb->quantization != Quantization::grid) return {};
  const double size = fa->voxel_size;
  if (!(size > 0.0) || std::abs(size - fb->voxel_size) > 1e-9 * size) return {};
  OneLattice out;
  out.frame = *fa;
  std::int64_t shift_a[3], shift_b[3];
  for (int i = 0; i < 3; ++i) {
    const double steps = (fb->origin[i] - fa->origin[i]) / size;  // b's origin in voxels of a's
    const double whole = std::round(steps);
    if (!(std::abs(steps - whole) <= 1e-6) || std::abs(whole) >= double(side_of(kMaxDepth))) return {};
    const auto k = static_cast<std::int64_t>(whole);
    shift_a[i] = k < 0 ? -k : 0;
    shift_b[i] = k < 0 ? 0 : k;
    out.frame.origin[i] = k < 0 ? fb->origin[i] : fa->origin[i];
  }
  std::uint64_t reach = 0;  // the largest moved coordinate
  const auto moved = [&](const Tree& t, const std::int64_t(&shift)[3], std::vector<Key>& keys) {
    keys = t.keys();
    for (Key& key : keys) {
      const Voxel v = decode(key);
      const std::uint64_t x = v.x + static_cast<std::uint64_t>(shift[0]),
                          y = v.y + static_cast<std::uint64_t>(shift[1]),
                          z = v.z + static_cast<std::uint64_t>(shift[2]);
      reach = std::max({reach, x, y, z});
      key = x < side_of(kMaxDepth) && y < side_of(kMaxDepth) && z < side_of(kMaxDepth)
                ? encode(static_cast<std::uint32_t>(x), static_cast<std::uint32_t>(y), static_cast<std::uint32_t>(z))
                : 0;
    }
  };
  moved(a, shift_a, out.a);
  moved(b, shift_b, out.b);
  out.depth = std::max(a.depth(), b.depth());
  while (out.depth <= kMaxDepth && reach >= side_of(out.depth)) ++out.depth;
  if (out.depth > kMaxDepth)
    VOLA_THROW(InvalidArgument(std::string(what) + ": the two grids are one lattice, but their voxels together span " +
                               std::to_string(reach + 1) + " voxels, more than depth 10 holds"));
  // Moving changes the keys' order (Morton order is not kept by a translation).
  std::sort(out.a.begin(), out.a.end());
  std::sort(out.b.begin(), out.b.end());
  return out;
}

// The result's georeferencing: the first tree's, or the second's CRS when only it states one.
void georeference_result(Tree& result, const Tree& a, const Tree& b) {
  result.georef() = a.georef();
  // A CRS only one side states is the result's (it was lost when the first had none).
  const Georef none{};
  if (a.georef().epsg == none.epsg && a.georef().crs_wkt.empty() &&
      (b.georef().epsg != none.epsg || !b.georef().crs_wkt.empty())) {
    result.georef().epsg = b.georef().epsg;
    result.georef().crs_wkt = b.georef().crs_wkt;
    result.georef().lat = b.georef().lat;
    result.georef().lon = b.georef().lon;
  }
}

template <class Merge>
Tree combine(const Tree& a, const Tree& b, FrameCheck check, const char* what, Merge merge) {
  if (check == FrameCheck::require_equal && (a.depth() != b.depth() || !same_frame(a.frame(), b.frame())))
    if (const std::optional<OneLattice> lattice = on_one_lattice(a, b, what)) {
      std::vector<Key> out;
      out.reserve(std::max(lattice->a.size(), lattice->b.size()));
      merge(lattice->a, lattice->b, std::back_inserter(out));
      Tree result = detail::emit_levels(out, lattice->depth, {}, false);
      georeference_result(result, a, b);
      result.set_frame(lattice->frame);
      return result;
    }
  if (a.depth() != b.depth())
    VOLA_THROW(InvalidArgument(std::string(what) + ": depths differ (" + std::to_string(a.depth()) + " and " +
                          std::to_string(b.depth()) + "); bring them to one depth with a level of detail"));
  if (check == FrameCheck::require_equal && !same_frame(a.frame(), b.frame()))
    VOLA_THROW(InvalidArgument(std::string(what) +
                          ": the trees' grids differ (origin or voxel size), so equal voxel indices are "
                          "different places; convert both with grid quantization and the same voxel size "
                          "and origin"));
  const auto ka = a.keys();
  const auto kb = b.keys();
  std::vector<Key> out;
  out.reserve(std::max(ka.size(), kb.size()));
  merge(ka, kb, std::back_inserter(out));
  Tree result = detail::emit_levels(out, a.depth(), {}, false);
  georeference_result(result, a, b);
  if (a.stored_frame()) result.set_frame(*a.stored_frame());
  return result;
}

}  // namespace

Tree unite(const Tree& a, const Tree& b, FrameCheck check) {
  return combine(a, b, check, "union", [](const auto& x, const auto& y, auto out) {
    std::set_union(x.begin(), x.end(), y.begin(), y.end(), out);
  });
}

Tree intersect(const Tree& a, const Tree& b, FrameCheck check) {
  return combine(a, b, check, "intersection", [](const auto& x, const auto& y, auto out) {
    std::set_intersection(x.begin(), x.end(), y.begin(), y.end(), out);
  });
}

Tree subtract(const Tree& a, const Tree& b, FrameCheck check) {
  return combine(a, b, check, "difference", [](const auto& x, const auto& y, auto out) {
    std::set_difference(x.begin(), x.end(), y.begin(), y.end(), out);
  });
}

VOLA_INLINE_NAMESPACE_END
}  // namespace vola
