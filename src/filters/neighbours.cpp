#include "vola/filters/neighbours.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <unordered_map>

#include "vola/error.hpp"
#include "vola/filters/dimensions.hpp"
#include "vola/filters/kd_tree.hpp"
#include "vola/parallel.hpp"

namespace vola::filters {

namespace {

// Whether point i of an x y z array has a place: every coordinate finite.
bool finite_point(std::span<const double> xyz, std::size_t i) {
  return std::isfinite(xyz[3 * i]) && std::isfinite(xyz[3 * i + 1]) && std::isfinite(xyz[3 * i + 2]);
}

}  // namespace

std::vector<double> height_above_ground(const PointCloud& cloud) {
  const auto cls = find_dimension(cloud, "classification");
  if (!cls || cls->axis >= 0)
    throw InvalidArgument("hag: the points have no classification (run smrf first to find the ground)");
  // Ground points without a place (a coordinate not finite) cannot be nearest to anything:
  // left in, they misled the k-d tree's search for every point near them.
  std::vector<std::uint32_t> ground;
  for (std::size_t i = 0; i < cloud.size(); ++i)
    if (value_of(cloud, *cls, i) == 2 && finite_point(cloud.xyz, i)) ground.push_back(static_cast<std::uint32_t>(i));
  if (ground.empty())
    throw InvalidArgument("hag: no point is classified ground (2); run smrf first to find the ground");
  const KdTree<2> tree(cloud.xyz, 3, std::move(ground));
  std::vector<double> hag(cloud.size());
  parallel_for(cloud.size(), [&](std::size_t begin, std::size_t end) {
    for (std::size_t i = begin; i < end; ++i) {
      if (!finite_point(cloud.xyz, i)) {
        hag[i] = std::numeric_limits<double>::quiet_NaN();  // no place, no height
        continue;
      }
      const auto near = tree.nearest({cloud.xyz[3 * i], cloud.xyz[3 * i + 1]}, 1);
      hag[i] = cloud.xyz[3 * i + 2] - cloud.xyz[3 * std::size_t{near[0].second} + 2];
    }
  }, {.grain = 4096});
  return hag;
}

void add_height_above_ground(PointCloud& cloud) {
  std::vector<double> hag = height_above_ground(cloud);
  const std::size_t c = ensure_column(cloud, "height_above_ground", ValueType::f64, Reduction::mean);
  cloud.attributes[c].values = std::move(hag);
}

void OutlierOptions::check() const {
  if (neighbours < 1 || neighbours > kMaxNeighbours)
    throw OptionError("neighbours", "must be 1 to " + std::to_string(kMaxNeighbours));
  if (!(multiplier >= 0.0) || !std::isfinite(multiplier)) throw OptionError("multiplier", "must be 0 or more");
}

std::vector<bool> statistical_outliers(std::span<const double> xyz, const OutlierOptions& options) {
  options.check();
  // A point without a place (a coordinate not finite) has no neighbours and is never kept,
  // as in the decimations; left in, its NaN distance made the limit NaN and kept every
  // outlier of the file.
  std::vector<std::uint32_t> placed;
  for (std::size_t i = 0; i < xyz.size() / 3; ++i)
    if (finite_point(xyz, i)) placed.push_back(static_cast<std::uint32_t>(i));
  std::vector<bool> outlier(xyz.size() / 3, true);
  for (const std::uint32_t i : placed) outlier[i] = false;
  const std::size_t n = placed.size();
  if (n < 2) return outlier;
  const KdTree<3> tree(xyz, 3, placed);
  const auto k = static_cast<std::size_t>(options.neighbours);
  std::vector<double> mean(n);
  parallel_for(n,
               [&](std::size_t begin, std::size_t end) {
                 for (std::size_t p = begin; p < end; ++p) {
                   const std::size_t i = placed[p];
                   // k + 1: the point itself is its own nearest (and is skipped).
                   const auto near = tree.nearest({xyz[3 * i], xyz[3 * i + 1], xyz[3 * i + 2]}, k + 1);
                   double sum = 0.0;
                   std::size_t used = 0;
                   for (const auto& [d2, j] : near)
                     if (j != i && used < k) sum += std::sqrt(d2), ++used;
                   mean[p] = used ? sum / static_cast<double>(used) : 0.0;
                 }
               },
               {.grain = 4096});
  double total = 0.0;
  for (const double m : mean) total += m;
  const double average = total / static_cast<double>(n);
  double squares = 0.0;
  for (const double m : mean) squares += (m - average) * (m - average);
  // As PDAL's filters.outlier: the sample standard deviation (n - 1), and a point at the
  // limit is an outlier.
  // With no spread at all (duplicates, two points) every point lies at the limit: PDAL
  // would mark them all as noise, which dropped the whole file; none stands out, so none is.
  if (squares == 0.0) return outlier;
  const double limit = average + options.multiplier * std::sqrt(squares / static_cast<double>(n - 1));
  for (std::size_t p = 0; p < n; ++p) outlier[placed[p]] = mean[p] >= limit;
  return outlier;
}

namespace {

// Integer cell coordinates of a point in cubes of side `size` from `origin`, packed.
struct CellKey {
  std::int64_t x, y, z;
  bool operator==(const CellKey&) const = default;
};
struct CellHash {
  std::size_t operator()(const CellKey& k) const noexcept {
    return static_cast<std::size_t>((static_cast<std::uint64_t>(k.x) * 0x9E3779B97F4A7C15ull) ^
                                    (static_cast<std::uint64_t>(k.y) * 0xC2B2AE3D27D4EB4Full) ^
                                    (static_cast<std::uint64_t>(k.z) * 0x165667B19E3779F9ull));
  }
};

void check_size(const char* option, double size) {
  if (!(size > 0.0) || !std::isfinite(size)) throw OptionError(option, "must be a positive length, not " + std::to_string(size));
}

// Cell indices are int64: refuse a size so small that |coordinate| / size passes 2^52.
void check_cells(const char* option, std::span<const double> xyz, double size) {
  double reach = 0.0;
  for (const double v : xyz)
    if (std::isfinite(v)) reach = std::max(reach, std::abs(v));
  if (reach / size > 4.5e15) {
    char what[96];
    std::snprintf(what, sizeof what, "%g is too small for coordinates reaching %g", size, reach);
    throw OptionError(option, what);
  }
}

}  // namespace

std::vector<bool> voxel_decimation(std::span<const double> xyz, double size) {
  check_size("voxel", size);
  check_cells("voxel", xyz, size);
  const std::size_t n = xyz.size() / 3;
  // Points with a NaN or infinite coordinate are in no cell: never kept.
  const auto finite = [&](std::size_t i) {
    return std::isfinite(xyz[3 * i]) && std::isfinite(xyz[3 * i + 1]) && std::isfinite(xyz[3 * i + 2]);
  };
  double lo[3] = {INFINITY, INFINITY, INFINITY};
  for (std::size_t i = 0; i < n; ++i)
    if (finite(i))
      for (int a = 0; a < 3; ++a) lo[a] = std::min(lo[a], xyz[3 * i + a]);
  std::unordered_map<CellKey, std::pair<double, std::size_t>, CellHash> best;  // cell -> (distance^2, point)
  for (std::size_t i = 0; i < n; ++i) {
    if (!finite(i)) continue;
    std::int64_t c[3];
    double d2 = 0.0;
    for (int a = 0; a < 3; ++a) {
      const double u = (xyz[3 * i + a] - lo[a]) / size;
      c[a] = static_cast<std::int64_t>(std::floor(u));
      const double d = (u - static_cast<double>(c[a]) - 0.5) * size;
      d2 += d * d;
    }
    const auto [it, added] = best.try_emplace(CellKey{c[0], c[1], c[2]}, d2, i);
    if (!added && d2 < it->second.first) it->second = {d2, i};
  }
  std::vector<bool> keep(n, false);
  for (const auto& [cell, chosen] : best) keep[chosen.second] = true;
  return keep;
}

std::vector<bool> poisson_decimation(std::span<const double> xyz, double radius) {
  check_size("poisson", radius);
  check_cells("poisson", xyz, radius);
  const std::size_t n = xyz.size() / 3;
  std::unordered_map<CellKey, std::vector<std::size_t>, CellHash> kept_in;  // cells of side radius
  std::vector<bool> keep(n, false);
  const double r2 = radius * radius;
  for (std::size_t i = 0; i < n; ++i) {
    const double* p = &xyz[3 * i];
    if (!std::isfinite(p[0]) || !std::isfinite(p[1]) || !std::isfinite(p[2])) continue;  // in no cell: dropped
    const CellKey c{static_cast<std::int64_t>(std::floor(p[0] / radius)), static_cast<std::int64_t>(std::floor(p[1] / radius)),
                    static_cast<std::int64_t>(std::floor(p[2] / radius))};
    bool near = false;
    for (std::int64_t dz = -1; dz <= 1 && !near; ++dz)
      for (std::int64_t dy = -1; dy <= 1 && !near; ++dy)
        for (std::int64_t dx = -1; dx <= 1 && !near; ++dx) {
          const auto it = kept_in.find({c.x + dx, c.y + dy, c.z + dz});
          if (it == kept_in.end()) continue;
          for (const std::size_t j : it->second) {
            const double a = xyz[3 * j] - p[0], b = xyz[3 * j + 1] - p[1], d = xyz[3 * j + 2] - p[2];
            if (a * a + b * b + d * d < r2) {
              near = true;
              break;
            }
          }
        }
    if (near) continue;
    keep[i] = true;
    kept_in[c].push_back(i);
  }
  return keep;
}

}  // namespace vola::filters
