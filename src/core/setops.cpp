#include "vola/setops.hpp"

#include <algorithm>
#include <cmath>
#include <iterator>

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

template <class Merge>
Tree combine(const Tree& a, const Tree& b, FrameCheck check, const char* what, Merge merge) {
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
