#include "vola/audio/patches.hpp"

#include <algorithm>
#include <array>
#include <bit>
#include <cmath>
#include <numbers>

#include "vola/error.hpp"

namespace vola::audio {

namespace {

constexpr int kFaceAxis[6] = {0, 0, 1, 1, 2, 2};
constexpr double kFaceSign[6] = {-1, 1, -1, 1, -1, 1};

std::uint64_t voxel_key(std::int64_t x, std::int64_t y, std::int64_t z) noexcept {
  return static_cast<std::uint64_t>(x) | static_cast<std::uint64_t>(y) << 20 | static_cast<std::uint64_t>(z) << 40;
}
bool in_grid(std::int64_t x, std::int64_t y, std::int64_t z, std::int64_t side) noexcept {
  return x >= 0 && y >= 0 && z >= 0 && x < side && y < side && z < side;
}

Point face_centre(const Voxel& v, int face) noexcept {
  Point c{v.x + 0.5, v.y + 0.5, v.z + 0.5};
  c[kFaceAxis[face]] += 0.5 * kFaceSign[face];
  return c;
}

// The eigenvector of the smallest eigenvalue of a symmetric 3x3 matrix and the two
// smallest eigenvalues (cyclic Jacobi rotations: exact enough in a few sweeps, and a
// diagonal matrix, a flat wall's, is left exactly as it is).
struct Eigen {
  Point vector{};
  double smallest = 0.0, middle = 0.0;
};
Eigen smallest_eigen(std::array<std::array<double, 3>, 3> a) {
  std::array<std::array<double, 3>, 3> v{{{1, 0, 0}, {0, 1, 0}, {0, 0, 1}}};
  for (int sweep = 0; sweep < 32; ++sweep) {
    const double off = a[0][1] * a[0][1] + a[0][2] * a[0][2] + a[1][2] * a[1][2];
    if (off < 1e-30) break;
    for (int p = 0; p < 2; ++p)
      for (int q = p + 1; q < 3; ++q) {
        if (a[p][q] == 0.0) continue;
        const double theta = (a[q][q] - a[p][p]) / (2.0 * a[p][q]);
        const double t = (theta >= 0 ? 1.0 : -1.0) / (std::abs(theta) + std::sqrt(theta * theta + 1.0));
        const double c = 1.0 / std::sqrt(t * t + 1.0), s = t * c;
        for (int k = 0; k < 3; ++k) {
          const double akp = a[k][p], akq = a[k][q];
          a[k][p] = c * akp - s * akq;
          a[k][q] = s * akp + c * akq;
        }
        for (int k = 0; k < 3; ++k) {
          const double apk = a[p][k], aqk = a[q][k];
          a[p][k] = c * apk - s * aqk;
          a[q][k] = s * apk + c * aqk;
        }
        for (int k = 0; k < 3; ++k) {
          const double vkp = v[k][p], vkq = v[k][q];
          v[k][p] = c * vkp - s * vkq;
          v[k][q] = s * vkp + c * vkq;
        }
      }
  }
  std::array<int, 3> order{0, 1, 2};
  std::sort(order.begin(), order.end(), [&](int i, int j) { return a[i][i] < a[j][j]; });
  Eigen e;
  e.vector = {v[0][order[0]], v[1][order[0]], v[2][order[0]]};
  e.smallest = a[order[0]][order[0]];
  e.middle = a[order[1]][order[1]];
  return e;
}

struct Raw {
  Voxel voxel;
  std::uint8_t face = 0;
  std::uint16_t slot = 0;
  Point normal{};
};

// A surface voxel's entry: exposed faces (bits 0-5), its first element (bits 8-39), the
// patch of that element (bits 40-63, kNoPatch when it does not fit).
constexpr std::uint64_t kNoPatch = 0xFFFFFF;
std::uint64_t first_of(std::uint64_t entry) noexcept { return (entry >> 8) & 0xFFFFFFFFull; }

}  // namespace

SurfacePatches::SurfacePatches(const Tree& tree, const VoxelMaterials& materials, const std::vector<LeafBlock>& blocks) {
  std::vector<Raw> raw;
  for_each_surface_voxel(tree, blocks, 0, blocks.size(), [&](const SurfaceVoxel& s) {
    const std::uint16_t slot = materials.slot(s.rank, s.leaf_block);
    for (int f = 0; f < 6; ++f)
      if (s.exposed & (1u << f)) raw.push_back(Raw{s.voxel, static_cast<std::uint8_t>(f), slot, {}});
  });
  // Key order, faces in order within a voxel: the element index of a voxel's faces is its
  // first plus the rank of the face among its exposed ones.
  std::sort(raw.begin(), raw.end(), [](const Raw& a, const Raw& b) {
    const std::uint64_t ka = voxel_key(a.voxel.x, a.voxel.y, a.voxel.z), kb = voxel_key(b.voxel.x, b.voxel.y, b.voxel.z);
    return ka != kb ? ka < kb : a.face < b.face;
  });
  // The surface voxels' blocks, then where each block's voxels start, then the voxels.
  std::size_t block_count = 0;
  {
    std::vector<std::uint64_t> keys;
    for (const Raw& r : raw) keys.push_back(voxel_key(r.voxel.x >> 2, r.voxel.y >> 2, r.voxel.z >> 2));
    std::sort(keys.begin(), keys.end());
    block_count = static_cast<std::size_t>(std::unique(keys.begin(), keys.end()) - keys.begin());
  }
  std::size_t capacity = 16;
  while (capacity < 2 * block_count) capacity *= 2;
  blocks_.assign(capacity, Block{});
  slot_mask_ = capacity - 1;
  slot_shift_ = 64 - std::countr_zero(capacity);
  auto bit_of = [](const Voxel& v) { return std::uint64_t{1} << ((v.x & 3) + 4 * (v.y & 3) + 16 * (v.z & 3)); };
  for (const Raw& r : raw) insert(voxel_key(r.voxel.x >> 2, r.voxel.y >> 2, r.voxel.z >> 2)).voxels |= bit_of(r.voxel);
  std::uint64_t surface_voxels = 0;
  for (Block& b : blocks_) {
    if (b.key == kNoKey) continue;
    b.offset = surface_voxels;
    surface_voxels += static_cast<std::uint64_t>(std::popcount(b.voxels));
  }
  voxel_faces_.assign(surface_voxels, 0);
  if (raw.size() >= (std::uint64_t{1} << 32)) throw InvalidArgument("the scene has 2^32 exposed voxel faces or more");
  for (std::size_t i = 0; i < raw.size(); ++i) {
    std::uint64_t& entry = const_cast<std::uint64_t&>(*find(raw[i].voxel.x, raw[i].voxel.y, raw[i].voxel.z));
    if ((entry & 0xFF) == 0) entry = static_cast<std::uint64_t>(i) << 8;
    entry |= std::uint64_t{1} << raw[i].face;
  }
  const auto side = static_cast<std::int64_t>(tree.side());
  auto element = [&](std::int64_t x, std::int64_t y, std::int64_t z, int face) -> std::int64_t {
    if (!in_grid(x, y, z, side)) return -1;
    const std::uint64_t* it = find(static_cast<std::uint64_t>(x), static_cast<std::uint64_t>(y), static_cast<std::uint64_t>(z));
    if (!it || !(*it & (1u << face))) return -1;
    return static_cast<std::int64_t>(first_of(*it) + std::popcount(static_cast<unsigned>(*it & ((1u << face) - 1))));
  };

  // Normals: a plane through the same-facing faces around each face.
  for (Raw& e : raw) {
    Point sum{0, 0, 0};
    std::array<std::array<double, 3>, 3> moment{};
    int n = 0;
    for (int dz = -kNormalRadius; dz <= kNormalRadius; ++dz)
      for (int dy = -kNormalRadius; dy <= kNormalRadius; ++dy)
        for (int dx = -kNormalRadius; dx <= kNormalRadius; ++dx) {
          const std::int64_t x = std::int64_t{e.voxel.x} + dx, y = std::int64_t{e.voxel.y} + dy, z = std::int64_t{e.voxel.z} + dz;
          if (element(x, y, z, e.face) < 0) continue;
          const Point c = face_centre(Voxel{static_cast<std::uint32_t>(x), static_cast<std::uint32_t>(y), static_cast<std::uint32_t>(z)}, e.face);
          // Relative to the element's own centre: small numbers, no cancellation.
          const Point r{c[0] - e.voxel.x, c[1] - e.voxel.y, c[2] - e.voxel.z};
          for (int i = 0; i < 3; ++i) {
            sum[i] += r[i];
            for (int j = 0; j < 3; ++j) moment[i][j] += r[i] * r[j];
          }
          ++n;
        }
    e.normal = {0, 0, 0};
    e.normal[kFaceAxis[e.face]] = kFaceSign[e.face];
    if (n < 4) continue;
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 3; ++j) moment[i][j] = moment[i][j] / n - sum[i] * sum[j] / (static_cast<double>(n) * n);
    const Eigen eig = smallest_eigen(moment);
    // Collinear centres (a one-voxel strip) fit no plane.
    if (!(eig.middle > 0.05)) continue;
    double along = eig.vector[kFaceAxis[e.face]] * kFaceSign[e.face];
    // Same-facing faces lie on one surface (a floor's top faces never mix with a wall's), so
    // a tilted fit is a slope: the riser of a staircase twice as long as high is 63 degrees
    // from its slope. Beyond 78 degrees the fit is more likely a thin ridge than a surface.
    if (std::abs(along) < 0.2) continue;
    const double sign = along < 0 ? -1.0 : 1.0;
    e.normal = {sign * eig.vector[0], sign * eig.vector[1], sign * eig.vector[2]};
  }

  // Region growing over touching voxels (26-neighbourhood, every face).
  const double min_cos = std::cos(kMaxNormalAngle * std::numbers::pi / 180.0);
  constexpr std::uint32_t kUnset = UINT32_MAX;
  std::vector<std::uint32_t> patch_of_element(raw.size(), kUnset);
  std::vector<std::size_t> queue;  // breadth first: a vector read from its head
  for (std::size_t seed = 0; seed < raw.size(); ++seed) {
    if (patch_of_element[seed] != kUnset) continue;
    const auto id = static_cast<std::uint32_t>(patches_.size());
    const Raw& s = raw[seed];
    const Point seed_centre = face_centre(s.voxel, s.face);
    SurfacePatch patch;
    patch.slot = s.slot;
    patch.lo = patch.hi = seed_centre;
    Point normal_sum{0, 0, 0}, centre_sum{0, 0, 0};
    double weight = 0.0;
    // Candidates are judged against the plane of the faces joined so far (breadth first:
    // the nearest first), so a long slope is not cut where it drifts from its seed's plane.
    Point plane_normal = s.normal, plane_point = seed_centre;
    queue.assign(1, seed);
    patch_of_element[seed] = id;
    for (std::size_t head = 0; head < queue.size(); ++head) {
      const std::size_t i = queue[head];
      const Raw& e = raw[i];
      const Point c = face_centre(e.voxel, e.face);
      // The face's area projected on its surface's plane.
      const double w = std::abs(e.normal[kFaceAxis[e.face]]);
      for (int k = 0; k < 3; ++k) {
        normal_sum[k] += w * e.normal[k];
        centre_sum[k] += w * c[k];
        patch.lo[k] = std::min(patch.lo[k], c[k]);
        patch.hi[k] = std::max(patch.hi[k], c[k]);
      }
      weight += w;
      patch.area += w;
      ++patch.faces;
      const double norm = std::sqrt(normal_sum[0] * normal_sum[0] + normal_sum[1] * normal_sum[1] + normal_sum[2] * normal_sum[2]);
      for (int k = 0; k < 3; ++k) {
        plane_normal[k] = normal_sum[k] / norm;
        plane_point[k] = centre_sum[k] / weight;
      }
      for (int dz = -1; dz <= 1; ++dz)
        for (int dy = -1; dy <= 1; ++dy)
          for (int dx = -1; dx <= 1; ++dx) {
            const std::int64_t x = std::int64_t{e.voxel.x} + dx, y = std::int64_t{e.voxel.y} + dy, z = std::int64_t{e.voxel.z} + dz;
            if (!in_grid(x, y, z, side)) continue;
            const std::uint64_t* it = find(static_cast<std::uint64_t>(x), static_cast<std::uint64_t>(y), static_cast<std::uint64_t>(z));
            if (!it) continue;
            auto j = static_cast<std::uint32_t>(first_of(*it));
            for (unsigned mask = static_cast<unsigned>(*it & 0xFF); mask; mask &= mask - 1, ++j) {
              if (patch_of_element[j] != kUnset) continue;
              const Raw& o = raw[j];
              if (o.slot != s.slot) continue;
              if (o.normal[0] * plane_normal[0] + o.normal[1] * plane_normal[1] + o.normal[2] * plane_normal[2] < min_cos)
                continue;
              const Point oc = face_centre(o.voxel, o.face);
              const double off = (oc[0] - plane_point[0]) * plane_normal[0] + (oc[1] - plane_point[1]) * plane_normal[1] +
                                 (oc[2] - plane_point[2]) * plane_normal[2];
              if (std::abs(off) > kMaxPlaneDistance) continue;
              patch_of_element[j] = id;
              queue.push_back(j);
            }
          }
    }
    const double norm = std::sqrt(normal_sum[0] * normal_sum[0] + normal_sum[1] * normal_sum[1] + normal_sum[2] * normal_sum[2]);
    for (int k = 0; k < 3; ++k) {
      patch.normal[k] = normal_sum[k] / norm;
      patch.centroid[k] = centre_sum[k] / weight;
    }
    patches_.push_back(patch);
  }
  elements_.resize(raw.size());
  for (std::size_t i = 0; i < raw.size(); ++i) elements_[i] = Element{patch_of_element[i], raw[i].face};
  // The first element's patch in the voxel's entry: a wall voxel has one exposed face, so
  // the tracer finds its patch without a further load.
  for (std::uint64_t& entry : voxel_faces_) {
    const std::uint64_t patch = elements_[first_of(entry)].patch;
    entry |= (patch < kNoPatch ? patch : kNoPatch) << 40;
  }
}

const std::uint64_t* SurfacePatches::find(std::uint64_t x, std::uint64_t y, std::uint64_t z) const noexcept {
  if (blocks_.empty()) return nullptr;
  const std::uint64_t key = voxel_key(static_cast<std::int64_t>(x >> 2), static_cast<std::int64_t>(y >> 2), static_cast<std::int64_t>(z >> 2));
  const std::uint64_t bit = std::uint64_t{1} << ((x & 3) + 4 * (y & 3) + 16 * (z & 3));
  for (std::uint64_t i = (key * 0x9E3779B97F4A7C15ull) >> slot_shift_;; i = (i + 1) & slot_mask_) {
    const Block& b = blocks_[i];
    if (b.key == key) {
      if (!(b.voxels & bit)) return nullptr;
      return &voxel_faces_[b.offset + static_cast<std::uint64_t>(std::popcount(b.voxels & (bit - 1)))];
    }
    if (b.key == kNoKey) return nullptr;
  }
}

SurfacePatches::Block& SurfacePatches::insert(std::uint64_t key) {
  for (std::uint64_t i = (key * 0x9E3779B97F4A7C15ull) >> slot_shift_;; i = (i + 1) & slot_mask_) {
    Block& b = blocks_[i];
    if (b.key == key) return b;
    if (b.key == kNoKey) {
      b.key = key;
      return b;
    }
  }
}

std::int64_t SurfacePatches::element_of(const Voxel& v, int face) const noexcept {
  const std::uint64_t* it = find(v.x, v.y, v.z);
  if (!it || !(*it & (1u << face))) return -1;
  return static_cast<std::int64_t>(first_of(*it) + std::popcount(static_cast<unsigned>(*it & ((1u << face) - 1))));
}

std::int64_t SurfacePatches::element_of(const Voxel& v, int face, std::uint32_t& patch) const noexcept {
  const std::uint64_t* it = find(v.x, v.y, v.z);
  if (!it || !(*it & (1u << face))) return -1;
  const auto below = static_cast<unsigned>(*it & ((1u << face) - 1));
  const std::uint64_t e = first_of(*it) + static_cast<std::uint64_t>(std::popcount(below));
  const std::uint64_t stored = *it >> 40;
  patch = below == 0 && stored != kNoPatch ? static_cast<std::uint32_t>(stored) : elements_[e].patch;
  return static_cast<std::int64_t>(e);
}

std::int64_t SurfacePatches::patch_of(const Voxel& v, int face) const noexcept {
  const std::int64_t e = element_of(v, face);
  return e < 0 ? std::int64_t{-1} : std::int64_t{elements_[static_cast<std::size_t>(e)].patch};
}

bool SurfacePatches::voxel_in_patch(const Voxel& v, std::uint32_t p) const noexcept {
  const std::uint64_t* it = find(v.x, v.y, v.z);
  if (!it) return false;
  const auto n = static_cast<std::uint32_t>(std::popcount(static_cast<unsigned>(*it & 0xFF)));
  const std::uint64_t first = first_of(*it);
  for (std::uint32_t i = 0; i < n; ++i)
    if (elements_[first + i].patch == p) return true;
  return false;
}

}  // namespace vola::audio
