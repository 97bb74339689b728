#include "reference_map.hpp"

#include <algorithm>
#include <set>

namespace vola_map_test {

namespace {

using vola::map::VoxelIndex;

std::int64_t floor_div(std::int64_t a, std::int64_t b) { return a / b - ((a % b != 0) && ((a < 0) != (b < 0))); }

// n / d with d > 0.
struct Fraction {
  std::int64_t n, d;
};
bool less(const Fraction& a, const Fraction& b) { return a.n * b.d < b.n * a.d; }

// Whether the open parameter interval (0, 1) of the segment o + t (e - o) meets the
// cell's interior for a positive length (a constant axis must lie in [lo, hi)).
bool spends_length_in(const Units& o, const Units& e, const Units& cell) {
  Fraction lower{0, 1}, upper{1, 1};
  for (int a = 0; a < 3; ++a) {
    const std::int64_t lo = cell[a] * kVoxelUnits, hi = lo + kVoxelUnits, d = e[a] - o[a];
    if (d == 0) {
      if (!(lo <= o[a] && o[a] < hi)) return false;
      continue;
    }
    const Fraction enter = d > 0 ? Fraction{lo - o[a], d} : Fraction{o[a] - hi, -d};
    const Fraction leave = d > 0 ? Fraction{hi - o[a], d} : Fraction{o[a] - lo, -d};
    if (less(lower, enter)) lower = enter;
    if (less(leave, upper)) upper = leave;
  }
  return less(lower, upper);
}

Units cell_of(const Units& p) {
  return {floor_div(p[0], kVoxelUnits), floor_div(p[1], kVoxelUnits), floor_div(p[2], kVoxelUnits)};
}

VoxelIndex index_of(const Units& c) {
  return {static_cast<std::int32_t>(c[0]), static_cast<std::int32_t>(c[1]), static_cast<std::int32_t>(c[2])};
}

}  // namespace

std::vector<VoxelIndex> ReferenceMap::passed(const Units& origin, const Units& end) {
  const Units first = cell_of(origin), last = cell_of(end);
  std::vector<VoxelIndex> out;
  if (first == last) return out;
  out.push_back(index_of(first));
  Units c{};
  for (c[0] = std::min(first[0], last[0]); c[0] <= std::max(first[0], last[0]); ++c[0])
    for (c[1] = std::min(first[1], last[1]); c[1] <= std::max(first[1], last[1]); ++c[1])
      for (c[2] = std::min(first[2], last[2]); c[2] <= std::max(first[2], last[2]); ++c[2])
        if (c != first && c != last && spends_length_in(origin, end, c)) out.push_back(index_of(c));
  return out;
}

void ReferenceMap::insert(const UnitScan& scan) {
  std::set<VoxelIndex> hit, free;
  for (const Units& p : scan.points) {
    for (const VoxelIndex& v : passed(scan.origin, p)) free.insert(v);
    hit.insert(index_of(cell_of(p)));
  }
  for (const VoxelIndex& v : hit) free.erase(v);
  const auto update = [&](const VoxelIndex& v, float change) {
    float& value = cells_.try_emplace(v, 0.0f).first->second;
    value += change;
    if (value < model_.clamp_min) value = model_.clamp_min;
    if (value > model_.clamp_max) value = model_.clamp_max;
  };
  for (const VoxelIndex& v : free) update(v, model_.miss);
  for (const VoxelIndex& v : hit) update(v, model_.hit);
}

std::vector<double> metres(const std::vector<Units>& points) {
  std::vector<double> xyz;
  for (const Units& p : points)
    for (const std::int64_t u : p) xyz.push_back(static_cast<double>(u) / kUnitsPerMetre);
  return xyz;
}

vola::Point metres(const Units& p) {
  return {static_cast<double>(p[0]) / kUnitsPerMetre, static_cast<double>(p[1]) / kUnitsPerMetre,
          static_cast<double>(p[2]) / kUnitsPerMetre};
}

}  // namespace vola_map_test
