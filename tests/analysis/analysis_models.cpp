#include "analysis_models.hpp"

#include <algorithm>
#include <deque>

namespace vola_analysis_test {

XyzSet bernoulli(std::mt19937_64& rng, int depth, double p) {
  XyzSet out;
  const std::uint32_t s = vola::side_of(depth);
  std::bernoulli_distribution keep(p);
  for (std::uint32_t z = 0; z < s; ++z)
    for (std::uint32_t y = 0; y < s; ++y)
      for (std::uint32_t x = 0; x < s; ++x)
        if (keep(rng)) out.insert({x, y, z});
  return out;
}

std::vector<Grid> random_grids(std::uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::vector<Grid> grids;
  for (int depth = 1; depth <= 3; ++depth)
    for (double p : {0.05, 0.2, 0.35, 0.6, 0.9})
      grids.push_back({depth, bernoulli(rng, depth, p), "dense d" + std::to_string(depth) + " p" + std::to_string(p)});
  for (int depth : {4, 6, 7, 8})
    for (auto shape : {vola_test::Shape::clustered, vola_test::Shape::uniform, vola_test::Shape::slab}) {
      const auto v = vola_test::random_voxels(rng, depth, shape, 1500);
      grids.push_back({depth, XyzSet(v.begin(), v.end()),
                       "sparse d" + std::to_string(depth) + " " + vola_test::shape_name(shape)});
    }
  return grids;
}

vola::Tree tree_of(const XyzSet& voxels, int depth) {
  std::vector<vola::Voxel> v;
  for (const Xyz& x : voxels) v.push_back(vola_test::to_voxel(x));
  return vola::build_from_voxels(v, depth);
}

namespace {

// Membership of a voxel set: a flat array of cells where the grid is small enough (up to
// 256^3: the dense random grids), the set itself otherwise. Only a faster lookup; the
// models below stay the brute force they were.
class Occupancy {
 public:
  static constexpr std::uint64_t kDenseSide = 256;
  explicit Occupancy(std::uint64_t side) : side_(side) {
    if (side_ <= kDenseSide) cells_.assign(side_ * side_ * side_, 0);
  }
  Occupancy(const XyzSet& voxels, std::uint64_t side) : Occupancy(side) {
    for (const Xyz& v : voxels) insert(v);
  }
  bool dense() const { return !cells_.empty(); }
  bool contains(const Xyz& v) const {
    if (!dense()) return set_.count(v) != 0;
    return v[0] < side_ && v[1] < side_ && v[2] < side_ && cells_[index(v)] != 0;
  }
  void insert(const Xyz& v) {
    if (dense())
      cells_[index(v)] = 1;
    else
      set_.insert(v);
  }
  // The members of a dense occupancy in XyzSet order (x, then y, then z).
  XyzSet dense_to_set() const {
    XyzSet out;
    for (std::uint32_t x = 0; x < side_; ++x)
      for (std::uint32_t y = 0; y < side_; ++y)
        for (std::uint32_t z = 0; z < side_; ++z)
          if (cells_[index({x, y, z})]) out.insert(out.end(), {x, y, z});
    return out;
  }

 private:
  std::size_t index(const Xyz& v) const { return static_cast<std::size_t>((v[2] * side_ + v[1]) * side_ + v[0]); }
  std::uint64_t side_;
  std::vector<char> cells_;
  XyzSet set_;
};

std::uint64_t side_around(const XyzSet& voxels) {
  std::uint64_t top = 0;
  for (const Xyz& v : voxels) top = std::max<std::uint64_t>({top, v[0], v[1], v[2]});
  return top + 1;
}

}  // namespace

std::map<Xyz, int> model_components(const XyzSet& voxels, int connectivity) {
  const Occupancy occupied(voxels, side_around(voxels));
  Occupancy labelled(side_around(voxels));
  std::map<Xyz, int> label;
  int next = 0;
  const int limit = connectivity == 6 ? 1 : connectivity == 18 ? 2 : 3;
  for (const Xyz& start : voxels) {
    if (labelled.contains(start)) continue;
    std::deque<Xyz> queue{start};
    label[start] = next;
    labelled.insert(start);
    while (!queue.empty()) {
      const Xyz v = queue.front();
      queue.pop_front();
      for (int dz = -1; dz <= 1; ++dz)
        for (int dy = -1; dy <= 1; ++dy)
          for (int dx = -1; dx <= 1; ++dx) {
            const int nonzero = (dx != 0) + (dy != 0) + (dz != 0);
            if (nonzero == 0 || nonzero > limit) continue;
            const Xyz n{v[0] + dx, v[1] + dy, v[2] + dz};  // wraps below 0: never a voxel
            if (occupied.contains(n) && !labelled.contains(n)) {
              label[n] = next;
              labelled.insert(n);
              queue.push_back(n);
            }
          }
    }
    ++next;
  }
  return label;
}

std::vector<std::array<int, 3>> element_offsets(int r, vola::analysis::Element element) {
  std::vector<std::array<int, 3>> out;
  for (int dz = -r; dz <= r; ++dz)
    for (int dy = -r; dy <= r; ++dy)
      for (int dx = -r; dx <= r; ++dx)
        if (element == vola::analysis::Element::cube || dx * dx + dy * dy + dz * dz <= r * r) out.push_back({dx, dy, dz});
  return out;
}

namespace {
bool shifted(const Xyz& v, const std::array<int, 3>& o, int depth, Xyz& out) {
  const std::int64_t s = vola::side_of(depth);
  for (int a = 0; a < 3; ++a) {
    const std::int64_t c = std::int64_t{v[a]} + o[a];
    if (c < 0 || c >= s) return false;
    out[a] = static_cast<std::uint32_t>(c);
  }
  return true;
}
}  // namespace

XyzSet model_dilate(const XyzSet& voxels, int depth, int radius, vola::analysis::Element element) {
  const auto offsets = element_offsets(radius, element);
  const std::uint64_t side = vola::side_of(depth);
  if (side <= Occupancy::kDenseSide) {
    Occupancy out(side);
    for (const Xyz& v : voxels)
      for (const auto& o : offsets) {
        Xyz n;
        if (shifted(v, o, depth, n)) out.insert(n);
      }
    return out.dense_to_set();
  }
  // Sparse sets in large grids: every shifted voxel, then sorted once.
  std::vector<Xyz> out;
  for (const Xyz& v : voxels)
    for (const auto& o : offsets) {
      Xyz n;
      if (shifted(v, o, depth, n)) out.push_back(n);
    }
  std::sort(out.begin(), out.end());
  out.erase(std::unique(out.begin(), out.end()), out.end());
  return XyzSet(out.begin(), out.end());
}

XyzSet model_erode(const XyzSet& voxels, int depth, int radius, vola::analysis::Element element) {
  const Occupancy occupied(voxels, vola::side_of(depth));
  XyzSet out;
  const auto offsets = element_offsets(radius, element);
  for (const Xyz& v : voxels) {
    bool all = true;
    for (const auto& o : offsets) {
      Xyz n;
      if (!shifted(v, o, depth, n) || !occupied.contains(n)) {
        all = false;
        break;
      }
    }
    if (all) out.insert(out.end(), v);
  }
  return out;
}

XyzSet model_fill(const XyzSet& voxels) {
  if (voxels.empty()) return {};
  std::int64_t lo[3] = {INT64_MAX, INT64_MAX, INT64_MAX}, hi[3] = {INT64_MIN, INT64_MIN, INT64_MIN};
  for (const Xyz& v : voxels)
    for (int a = 0; a < 3; ++a) {
      lo[a] = std::min<std::int64_t>(lo[a], v[a]);
      hi[a] = std::max<std::int64_t>(hi[a], v[a]);
    }
  // Dense box from lo-1 to hi+1 per axis.
  const std::int64_t n[3] = {hi[0] - lo[0] + 3, hi[1] - lo[1] + 3, hi[2] - lo[2] + 3};
  auto at = [&](std::int64_t x, std::int64_t y, std::int64_t z) { return static_cast<std::size_t>((z * n[1] + y) * n[0] + x); };
  std::vector<char> solid(static_cast<std::size_t>(n[0] * n[1] * n[2]), 0), out(solid.size(), 0);
  for (const Xyz& v : voxels) solid[at(v[0] - lo[0] + 1, v[1] - lo[1] + 1, v[2] - lo[2] + 1)] = 1;
  std::deque<std::array<std::int64_t, 3>> queue{{0, 0, 0}};
  out[0] = 1;
  while (!queue.empty()) {
    const auto c = queue.front();
    queue.pop_front();
    const int d[6][3] = {{1, 0, 0}, {-1, 0, 0}, {0, 1, 0}, {0, -1, 0}, {0, 0, 1}, {0, 0, -1}};
    for (const auto& o : d) {
      const std::int64_t x = c[0] + o[0], y = c[1] + o[1], z = c[2] + o[2];
      if (x < 0 || y < 0 || z < 0 || x >= n[0] || y >= n[1] || z >= n[2]) continue;
      const std::size_t i = at(x, y, z);
      if (solid[i] || out[i]) continue;
      out[i] = 1;
      queue.push_back({x, y, z});
    }
  }
  XyzSet filled;
  for (std::int64_t z = 1; z + 1 < n[2]; ++z)
    for (std::int64_t y = 1; y + 1 < n[1]; ++y)
      for (std::int64_t x = 1; x + 1 < n[0]; ++x)
        if (!out[at(x, y, z)])
          filled.insert({static_cast<std::uint32_t>(x - 1 + lo[0]), static_cast<std::uint32_t>(y - 1 + lo[1]),
                         static_cast<std::uint32_t>(z - 1 + lo[2])});
  return filled;
}

}  // namespace vola_analysis_test
