#include "vola/slam/fusion.hpp"

#include <Eigen/Cholesky>
#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>
#include <limits>

#include "tsdf_reader.hpp"
#include "vola/error.hpp"
#include "vola/parallel.hpp"

namespace vola::slam {

void FusionParams::check() const {
  auto positive = [](double v) { return v > 0.0 && std::isfinite(v); };
  if (!positive(voxel_size)) throw InvalidArgument("voxel size must be positive");
  if (!(truncation >= voxel_size) || !std::isfinite(truncation))
    throw InvalidArgument("truncation must be at least the voxel size");
  if (!(max_weight >= 1.0f)) throw InvalidArgument("max weight must be at least 1");
  if (!(min_depth >= 0.0) || !(max_depth > min_depth) || !std::isfinite(max_depth))
    throw InvalidArgument("need 0 <= min depth < max depth");
  if (bilateral_radius < 0 || bilateral_radius > 16 || !positive(bilateral_sigma_space) ||
      !positive(bilateral_sigma_depth))
    throw InvalidArgument("bilateral filter: radius 0..16 and positive sigmas");
  for (int it : icp_iterations)
    if (it < 0 || it > 100) throw InvalidArgument("ICP iterations must be 0..100 per level");
  if (!positive(icp_max_distance) || !positive(icp_max_angle_degrees) || !positive(max_step_translation) ||
      !positive(max_step_rotation_degrees))
    throw InvalidArgument("ICP thresholds must be positive");
  if (!(motion_prior >= 0.0 && motion_prior < 1.0)) throw InvalidArgument("motion prior must be in [0, 1)");
  if (!(photometric_weight >= 0.0) || !std::isfinite(photometric_weight) || !positive(photometric_huber))
    throw InvalidArgument("photometric weight must be non-negative and its Huber threshold positive");
  if (!positive(keyframe_translation) || !positive(keyframe_rotation_degrees) || !positive(feature_icp_translation) ||
      !positive(feature_icp_rotation_degrees))
    throw InvalidArgument("feature tracking thresholds must be positive");
  if (!(min_overlap >= 0.0 && min_overlap <= 1.0)) throw InvalidArgument("minimum overlap must be in [0, 1]");
  if (relocalisation_min_inliers < 3) throw InvalidArgument("relocalisation needs at least 3 feature inliers");
  if (feature.max_features < 10 || feature.min_inliers < 3 || feature.ransac_iterations < 1 ||
      !(feature.ratio > 0.0 && feature.ratio <= 1.0) || feature.max_hamming < 0 || feature.max_hamming > 256 ||
      !(feature.ransac_confidence > 0.0 && feature.ransac_confidence <= 1.0))
    throw InvalidArgument("feature parameters out of range");
  if (refine_level < 0 || refine_level >= kPyramidLevels)
    throw InvalidArgument("keyframe refinement level must be 0 .. " + std::to_string(kPyramidLevels - 1));
  if (!(refine_min_move >= 0.0 && refine_min_move_degrees >= 0.0))
    throw InvalidArgument("keyframe refinement thresholds must not be negative");
}

namespace {

// Chunks of the parallel loops over pixels (rows) and bricks (512 voxels each): results
// are written per pixel and per brick, so the chunking does not change them.
constexpr std::size_t kRowsPerChunk = 4;
constexpr std::size_t kBricksPerChunk = 16;
constexpr std::size_t kTrackBands = 16;  // partial sums of the ICP and photometric terms
constexpr int kRecentBricksLog2 = 12;    // bricks_in_band's table of recently seen keys
constexpr std::size_t kRecentBricks = std::size_t{1} << kRecentBricksLog2;

using Vec6 = Eigen::Matrix<double, 6, 1>;
using Mat6 = Eigen::Matrix<double, 6, 6>;

struct RayHitSample {
  Eigen::Vector3d position, normal;
  const TsdfVoxel* voxel = nullptr;
};

// The zero crossing between t_a (positive nearest-voxel value fa) and t_b (negative
// fb): with trilinear values, a bracket grown by up to a voxel on each side (nearest
// values change sign up to half a voxel away from the interpolated ones) and up to three
// regula falsi steps, stopping early once the value at the estimate is within 10 um of
// the surface (values are distances / truncation); without trilinear values, the
// nearest values' linear interpolation. (At 0.1 mm the Kinect frames' ATE moved from
// 2.07 to 2.27 cm for no measurable speed.)
template <class Store, class GridAt>
double refine_crossing(TsdfReader<Store>& reader, const GridAt& grid_at, double t_a, double fa, double t_b, double fb,
                       double voxel, double truncation) {
  const double close_enough = 1e-5 / truncation;  // 10 um, far below the depth noise
  const double fallback = t_a + (t_b - t_a) * fa / (fa - fb);
  double ia = 0.0, ib = 0.0;
  if (!reader.trilinear(grid_at(t_a), ia) || !reader.trilinear(grid_at(t_b), ib)) return fallback;
  if (!(ia > 0.0)) {
    t_a -= voxel;
    if (!reader.trilinear(grid_at(t_a), ia) || !(ia > 0.0)) return fallback;
  }
  if (!(ib < 0.0)) {
    t_b += voxel;
    if (!reader.trilinear(grid_at(t_b), ib) || !(ib < 0.0)) return fallback;
  }
  for (int step = 0; step < 3; ++step) {
    const double t = t_a + (t_b - t_a) * ia / (ia - ib);
    double f = 0.0;
    if (!reader.trilinear(grid_at(t), f)) return t;
    if (std::abs(f) <= close_enough) return t;
    if (f > 0.0) {
      t_a = t;
      ia = f;
    } else {
      t_b = t;
      ib = f;
    }
  }
  return t_a + (t_b - t_a) * ia / (ia - ib);
}

// Marches one ray (world origin o, unit direction d) from t_near to t_far metres: big
// steps over unallocated bricks, steps of 0.8 of the stored distance (at least a voxel)
// inside them, and the first positive-to-negative crossing refined by interpolation.
// With_normal, the hit's normal is the TSDF's gradient (central differences of trilinear
// values a voxel either side: six more reads of eight voxels); without, it is left zero.
template <class Store>
std::optional<RayHitSample> march(TsdfReader<Store>& reader, const VolumeGeometry& geometry, const Eigen::Vector3d& o,
                                  const Eigen::Vector3d& d, double t_near, double t_far, double truncation,
                                  bool with_normal) {
  const double vs = geometry.voxel_size;
  // Grid coordinates along the ray, and the inverse direction for the brick exits: no
  // division per step.
  const Eigen::Vector3d go = (o - geometry.origin) / vs, dg = d / vs;
  const Eigen::Vector3d inverse_d(1.0 / d.x(), 1.0 / d.y(), 1.0 / d.z());
  auto grid_at = [&](double t) {  // component-wise: Eigen's expression did not inline here
    return Eigen::Vector3d(go.x() + dg.x() * t, go.y() + dg.y() * t, go.z() + dg.z() * t);
  };
  double t = t_near, t_prev = 0.0, f_prev = 0.0;
  bool prev_valid = false;
  // The brick of the last step, looked up again only when a step leaves it (most steps
  // stay: a brick is 8 voxels, a step 1 to 3).
  std::int64_t last_brick[3] = {-1, -1, -1};
  const TsdfVoxel* brick = nullptr;
  while (t < t_far) {
    const auto x = static_cast<std::int64_t>(std::floor(go.x() + dg.x() * t)),
               y = static_cast<std::int64_t>(std::floor(go.y() + dg.y() * t)),
               z = static_cast<std::int64_t>(std::floor(go.z() + dg.z() * t));
    if ((x >> 3) != last_brick[0] || (y >> 3) != last_brick[1] || (z >> 3) != last_brick[2]) {
      last_brick[0] = x >> 3;
      last_brick[1] = y >> 3;
      last_brick[2] = z >> 3;
      brick = reader.brick_at(x >> 3, y >> 3, z >> 3);
    }
    if (!brick) {
      // Leave the brick: the nearest exit plane over the three axes.
      double exit = std::numeric_limits<double>::infinity();
      const std::int64_t cell[3] = {x >> 3, y >> 3, z >> 3};
      for (int a = 0; a < 3; ++a) {
        if (d[a] == 0.0) continue;
        const double plane = static_cast<double>((d[a] > 0 ? cell[a] + 1 : cell[a]) * kBrickSide);
        exit = std::min(exit, (plane - go[a]) * inverse_d[a] * vs);
      }
      t = std::max(t + vs * 1e-3, exit + vs * 1e-3);
      prev_valid = false;
      continue;
    }
    const TsdfVoxel* v = brick + local_index(static_cast<std::uint32_t>(x), static_cast<std::uint32_t>(y),
                                             static_cast<std::uint32_t>(z));
    if (!(v->weight > 0.0f)) {
      prev_valid = false;
      t += vs;
      continue;
    }
    const double f = v->tsdf;
    if (f < 0.0) {
      if (!prev_valid || f_prev <= 0.0) return std::nullopt;  // entered from behind or from unknown space
      const double t_hit = refine_crossing(reader, grid_at, t_prev, f_prev, t, f, vs, truncation);
      // Without the normal (the tracking raycast), neither is the hit's own voxel needed.
      if (!with_normal) return RayHitSample{o + d * t_hit, Eigen::Vector3d::Zero(), v};
      const Eigen::Vector3d gh = grid_at(t_hit);
      const auto hx = static_cast<std::int64_t>(std::floor(gh.x())), hy = static_cast<std::int64_t>(std::floor(gh.y())),
                 hz = static_cast<std::int64_t>(std::floor(gh.z()));
      const TsdfVoxel* at = reader.voxel(hx, hy, hz);
      Eigen::Vector3d gradient;
      for (int a = 0; a < 3; ++a) {
        Eigen::Vector3d lo = gh, hi = gh;
        lo[a] -= 1.0;
        hi[a] += 1.0;
        double f_lo = 0.0, f_hi = 0.0;
        if (!reader.trilinear(lo, f_lo) || !reader.trilinear(hi, f_hi)) return std::nullopt;
        gradient[a] = f_hi - f_lo;
      }
      const double length = gradient.norm();
      if (!(length > 0.0)) return std::nullopt;
      return RayHitSample{o + d * t_hit, gradient / length, at ? at : v};
    }
    t_prev = t;
    f_prev = f;
    prev_valid = true;
    t += std::max(vs, 0.8 * f * truncation);
  }
  return std::nullopt;
}

Eigen::Vector3d pixel_direction(const Intrinsics& k, std::uint32_t u, std::uint32_t v) {
  return Eigen::Vector3d((u - k.cx) / k.fx, (v - k.cy) / k.fy, 1.0);
}

Intrinsics level_intrinsics(const Intrinsics& k, int level) {
  Intrinsics out = k;
  for (int l = 0; l < level; ++l) out = out.halved();
  return out;
}

// The camera depths (z) that allocated bricks span, per tile of kTile x kTile pixels:
// every brick is projected (its eight corners) and widens the range of the tiles its
// bounding rectangle covers. A ray of the tile meets no brick outside its range, so the
// march may start and end there instead of stepping brick by brick through the empty
// space between the camera and the first surface (InfiniTAM's range image). Bricks that
// reach behind the image plane cover every tile.
struct TileDepthRanges {
  static constexpr std::uint32_t kTile = 8;
  std::uint32_t tiles_x = 0;
  std::vector<float> near, far;  // +inf / -inf: no brick in the tile
  std::size_t tile_of(std::uint32_t x, std::size_t y) const { return (y / kTile) * tiles_x + x / kTile; }
};

template <class Store>
TileDepthRanges tile_depth_ranges(const Store& store, const Intrinsics& k, std::uint32_t width, std::uint32_t height,
                                  const Pose& pose, double min_depth) {
  TileDepthRanges ranges;
  ranges.tiles_x = (width + TileDepthRanges::kTile - 1) / TileDepthRanges::kTile;
  const std::uint32_t tiles_y = (height + TileDepthRanges::kTile - 1) / TileDepthRanges::kTile;
  ranges.near.assign(std::size_t{ranges.tiles_x} * tiles_y, std::numeric_limits<float>::infinity());
  ranges.far.assign(ranges.near.size(), -std::numeric_limits<float>::infinity());
  const VolumeGeometry& geometry = store.geometry();
  const double brick_metres = kBrickSide * geometry.voxel_size;
  const Pose to_camera = pose.inverse();
  const double last_x = width - 1.0, last_y = height - 1.0;
  store.for_each_brick([&](const BrickCoord& c, const TsdfVoxel*) {
    const Eigen::Vector3d low = geometry.origin + Eigen::Vector3d(c.x, c.y, c.z) * brick_metres;
    double z_min = std::numeric_limits<double>::infinity(), z_max = -z_min;
    double u_min = z_min, u_max = -z_min, v_min = z_min, v_max = -z_min;
    bool behind = false;
    for (int corner = 0; corner < 8; ++corner) {
      const Eigen::Vector3d p =
          to_camera * (low + Eigen::Vector3d(corner & 1, (corner >> 1) & 1, corner >> 2) * brick_metres);
      z_min = std::min(z_min, p.z());
      z_max = std::max(z_max, p.z());
      if (p.z() <= 1e-6) {
        behind = true;
        continue;
      }
      const double u = k.fx * p.x() / p.z() + k.cx, v = k.fy * p.y() / p.z() + k.cy;
      u_min = std::min(u_min, u);
      u_max = std::max(u_max, u);
      v_min = std::min(v_min, v);
      v_max = std::max(v_max, v);
    }
    if (z_max < min_depth) return;  // the march starts at min_depth
    if (behind) u_min = v_min = 0.0, u_max = last_x, v_max = last_y;
    // A pixel's ray passes through the brick only inside its projection; one pixel of
    // margin absorbs rounding.
    if (u_max < -1.0 || v_max < -1.0 || u_min > last_x + 1.0 || v_min > last_y + 1.0) return;
    const auto tile = [](double p, double last) {
      return static_cast<std::uint32_t>(std::clamp(p, 0.0, last)) / TileDepthRanges::kTile;
    };
    const std::uint32_t tx0 = tile(u_min - 1.0, last_x), tx1 = tile(u_max + 1.0, last_x);
    const std::uint32_t ty0 = tile(v_min - 1.0, last_y), ty1 = tile(v_max + 1.0, last_y);
    for (std::uint32_t ty = ty0; ty <= ty1; ++ty)
      for (std::uint32_t tx = tx0; tx <= tx1; ++tx) {
        const std::size_t i = std::size_t{ty} * ranges.tiles_x + tx;
        ranges.near[i] = std::min(ranges.near[i], static_cast<float>(z_min));
        ranges.far[i] = std::max(ranges.far[i], static_cast<float>(z_max));
      }
  });
  return ranges;
}

}  // namespace

// Marches the ray of every pixel through the TSDF from `pose` and calls
// on_hit(pixel index, hit, world ray direction) for each surface crossing found (with
// the TSDF's gradient as its normal when with_normal).
template <class Store, class OnHit>
void march_pixels(const Store& store, const Intrinsics& k, std::uint32_t width, std::uint32_t height, const Pose& pose,
                  const FusionParams& params, bool with_normal, const OnHit& on_hit) {
  const Eigen::Vector3d o = pose.translation();
  const Eigen::Matrix3d r = pose.linear();
  const TileDepthRanges ranges = tile_depth_ranges(store, k, width, height, pose, params.min_depth);
  const double voxel = store.geometry().voxel_size;
  ParallelOptions parallel;
  parallel.threads = params.threads;
  parallel.grain = kRowsPerChunk;
  parallel.name = "slam.raycast";
  const auto march_rows = [&](std::size_t begin, std::size_t end) {
    TsdfReader<Store> reader(store);
    for (std::size_t y = begin; y < end; ++y)
      for (std::uint32_t x = 0; x < width; ++x) {
        const std::size_t tile = ranges.tile_of(x, y);
        if (!(ranges.near[tile] <= ranges.far[tile])) continue;  // no brick on this ray
        const Eigen::Vector3d camera_dir = pixel_direction(k, x, static_cast<std::uint32_t>(y));
        const double scale = camera_dir.norm();  // metres along the ray per metre of depth
        const Eigen::Vector3d d = r * (camera_dir / scale);
        // A voxel of margin either side of the bricks' depths.
        const double t_near = std::max(params.min_depth, ranges.near[tile] - voxel) * scale;
        const double t_far =
            std::min(params.max_depth * scale + params.truncation, (ranges.far[tile] + voxel) * scale);
        const auto hit = march(reader, store.geometry(), o, d, t_near, t_far, params.truncation, with_normal);
        if (hit) on_hit(y * width + x, *hit, d);
      }
  };
  parallel_for(height, march_rows, parallel);
}

template <class Store>
VertexMap raycast(const Store& store, const Intrinsics& k, std::uint32_t width, std::uint32_t height, const Pose& pose,
                  const FusionParams& params) {
  const float nan = std::numeric_limits<float>::quiet_NaN();
  const std::size_t n = std::size_t{width} * height;
  VertexMap map{width, height, std::vector<Eigen::Vector3f>(n, Eigen::Vector3f::Constant(nan)),
                std::vector<Eigen::Vector3f>(n, Eigen::Vector3f::Constant(nan))};
  std::vector<Eigen::Vector3f> vertices(n, Eigen::Vector3f::Constant(nan));
  march_pixels(store, k, width, height, pose, params, false, [&](std::size_t i, const auto& hit, const Eigen::Vector3d&) {
    vertices[i] = hit.position.template cast<float>();
  });
  // Normals from the neighbouring hits, central differences across the pixel (as
  // InfiniTAM's raycast does): the TSDF's gradient at every hit cost six trilinear
  // reads, a quarter of the tracking loop's time. A pixel keeps its vertex only with
  // all four neighbours hit, so that every model vertex has a normal.
  const Eigen::Vector3f camera = pose.translation().template cast<float>();
  ParallelOptions parallel;
  parallel.threads = params.threads;
  parallel.grain = kRowsPerChunk;
  parallel.name = "slam.raycast_normals";
  parallel_for(
      height,
      [&](std::size_t begin, std::size_t end) {
        for (std::size_t y = std::max<std::size_t>(begin, 1); y < std::min<std::size_t>(end, height - 1); ++y)
          for (std::size_t x = 1; x + 1 < width; ++x) {
            const std::size_t i = y * width + x;
            const Eigen::Vector3f& v = vertices[i];
            const Eigen::Vector3f &left = vertices[i - 1], &right = vertices[i + 1];
            const Eigen::Vector3f &up = vertices[i - width], &down = vertices[i + width];
            if (!(v.x() == v.x() && left.x() == left.x() && right.x() == right.x() && up.x() == up.x() &&
                  down.x() == down.x()))
              continue;
            Eigen::Vector3f normal = (right - left).cross(down - up);
            const float length = normal.norm();
            if (!(length > 0.0f)) continue;
            normal /= length;
            if (normal.dot(v - camera) > 0.0f) normal = -normal;  // face the camera
            map.vertices[i] = v;
            map.normals[i] = normal;
          }
      },
      parallel);
  return map;
}

template <class Store>
RgbImage render_view(const Store& store, const Intrinsics& k, std::uint32_t width, std::uint32_t height,
                     const Pose& pose, const FusionParams& params, bool use_colour) {
  RgbImage image{width, height, std::vector<std::uint8_t>(std::size_t{width} * height * 3, 0)};
  const std::uint8_t grey[3] = {210, 210, 210};
  march_pixels(store, k, width, height, pose, params, true, [&](std::size_t i, const auto& hit, const Eigen::Vector3d& d) {
    const double light = 0.25 + 0.75 * std::max(0.0, -hit.normal.dot(d));
    const std::uint8_t* colour = (use_colour && hit.voxel) ? &hit.voxel->r : grey;
    for (int c = 0; c < 3; ++c)
      image.rgb[i * 3 + c] = static_cast<std::uint8_t>(std::lround(std::min(255.0, colour[c] * light)));
  });
  return image;
}

std::vector<BrickCoord> bricks_in_band(const DepthImage& depth, const Intrinsics& k, const Pose& pose,
                                       const VolumeGeometry& geometry, double truncation, unsigned threads) {
  const double brick_metres = kBrickSide * geometry.voxel_size;
  const double side = geometry.bricks_per_side;
  // Brick coordinates of the camera centre and of the rotation, so that a sample at depth
  // z along a pixel's ray is camera_in_bricks + (rotation_in_bricks * dir) z.
  const Eigen::Vector3d camera_in_bricks = (pose.translation() - geometry.origin) / brick_metres;
  const Eigen::Matrix3d rotation_in_bricks = pose.linear() / brick_metres;
  // Each band of rows collects its keys sorted and unique (neighbouring pixels share
  // most bricks, so the bands' lists are short), then the lists are merged: a set, the
  // same whatever the bands.
  ParallelOptions bands;
  bands.threads = threads;
  bands.chunks = std::max<std::size_t>(1, std::min<std::size_t>(depth.height, 16));
  bands.name = "slam.bricks_in_band";
  std::vector<std::vector<std::uint64_t>> band_keys(bands.chunks);
  parallel_for(
      depth.height,
      [&](const Chunk& chunk) {
        std::vector<std::uint64_t>& keys = band_keys[chunk.index];
        // The keys seen recently, direct-mapped: neighbouring pixels and rows name the
        // same few bricks, so most samples are dropped here instead of being pushed and
        // sorted (the band's list was a quarter of a million keys at 640 x 480).
        std::vector<std::uint64_t> recent(kRecentBricks, ~std::uint64_t{0});
        for (auto y = static_cast<std::uint32_t>(chunk.begin); y < chunk.end; ++y)
          for (std::uint32_t x = 0; x < depth.width; ++x) {
            const double d = depth.at(x, y);
            if (!(d > 0.0)) continue;
            const Eigen::Vector3d dir = pixel_direction(k, x, y);
            // Depth steps short enough that consecutive samples are at most half a brick apart.
            const double step = brick_metres / (2 * dir.norm());
            const int samples = static_cast<int>(std::ceil(2 * truncation / step));
            const Eigen::Vector3d along = rotation_in_bricks * dir;  // bricks per metre of depth
            for (int s = 0; s <= samples; ++s) {
              const double z = d - truncation + 2 * truncation * s / samples;
              if (z <= 0.0) continue;
              const Eigen::Vector3d g = camera_in_bricks + along * z;
              const double bx = std::floor(g.x()), by = std::floor(g.y()), bz = std::floor(g.z());
              if (!(bx >= 0 && by >= 0 && bz >= 0 && bx < side && by < side && bz < side)) continue;
              const std::uint64_t key = static_cast<std::uint64_t>(bz) << 42 | static_cast<std::uint64_t>(by) << 21 |
                                        static_cast<std::uint64_t>(bx);
              std::uint64_t& slot = recent[(key * 0x9E3779B97F4A7C15ull) >> (64 - kRecentBricksLog2)];
              if (slot == key) continue;
              slot = key;
              keys.push_back(key);
            }
          }
        std::sort(keys.begin(), keys.end());
        keys.erase(std::unique(keys.begin(), keys.end()), keys.end());
      },
      bands);
  std::vector<std::uint64_t> keys;
  for (const auto& band : band_keys) keys.insert(keys.end(), band.begin(), band.end());
  std::sort(keys.begin(), keys.end());
  keys.erase(std::unique(keys.begin(), keys.end()), keys.end());
  std::vector<BrickCoord> bricks;
  bricks.reserve(keys.size());
  const std::uint64_t mask = (std::uint64_t{1} << 21) - 1;
  for (const auto key : keys)
    bricks.push_back({static_cast<std::uint32_t>(key & mask), static_cast<std::uint32_t>((key >> 21) & mask),
                      static_cast<std::uint32_t>(key >> 42)});
  return bricks;
}

template <class Store>
Fusion<Store>::Fusion(Store& store, const Intrinsics& intrinsics, std::uint32_t width, std::uint32_t height,
                      const FusionParams& params)
    : store_(store), intrinsics_(intrinsics), width_(width), height_(height), params_(params) {
  params.check();
  intrinsics.check();
  if (std::abs(store.geometry().voxel_size - params.voxel_size) > 1e-12 * params.voxel_size)
    throw InvalidArgument("the store's voxel size differs from the fusion parameters'");
  if (width < (1u << kPyramidLevels) || height < (1u << kPyramidLevels))
    throw InvalidArgument("images must be at least 8 x 8 pixels");
  // The principal point lies on the image (a cx of 1e9 made the bricks' projection sweep a
  // billion columns per frame: minutes for two 160 x 120 frames, without a word).
  if (!(intrinsics.cx >= 0.0 && intrinsics.cx <= width && intrinsics.cy >= 0.0 && intrinsics.cy <= height))
    throw InvalidArgument("the principal point (cx " + std::to_string(intrinsics.cx) + ", cy " +
                          std::to_string(intrinsics.cy) + ") lies outside the " + std::to_string(width) + " x " +
                          std::to_string(height) + " image: check intrinsics.txt ('fx fy cx cy' in pixels)");
  // Focal lengths that no camera has: a field of view under 0.06 or over 177 degrees
  // (fx of 1e300 or 1e-300 ended in "no depth was measured", which blamed the depth).
  const auto plausible = [](double focal, std::uint32_t side) {
    return std::abs(focal) >= 0.01 * side && std::abs(focal) <= 1000.0 * side;
  };
  if (!plausible(intrinsics.fx, width) || !plausible(intrinsics.fy, height))
    throw InvalidArgument("the focal lengths (fx " + std::to_string(intrinsics.fx) + ", fy " +
                          std::to_string(intrinsics.fy) + " pixels) are implausible for a " + std::to_string(width) +
                          " x " + std::to_string(height) + " image (0.01 to 1000 times its side): check "
                          "intrinsics.txt ('fx fy cx cy' in pixels)");
}

namespace {

// The point-to-plane normal equations of one ICP iteration, summed over the frame's
// valid pixels: A (upper triangle) and b of A xi = b, and how many pixels took part.
struct IcpSums {
  Mat6 a = Mat6::Zero();
  Vec6 b = Vec6::Zero();
  int count = 0;
};

struct IcpFrame {
  const VertexMap& current;       // the frame's vertices and normals, camera frame
  const VertexMap& model;         // the model's, raycast from the previous pose
  Intrinsics k;                   // of this pyramid level
  Pose previous_inverse;          // world to the previous camera (projective association)
  double max_distance, cos_max;   // association limits: distance, normal angle
};

// Running sums of weight jac jac^T (its upper triangle) and -weight jac r in plain local
// arrays: summed into the band's IcpSums in the shared vector, every addition was a
// store the compiler could not keep in registers (it may alias the frame's data), and
// Eigen's rankUpdate is a call per point that does not inline.
class NormalEquations {
 public:
  void add(const Vec6& jac, double weight, double residual) {
    int k = 0;
    for (int col = 0; col < 6; ++col) {
      const double weighted = weight * jac[col];
      for (int row = 0; row <= col; ++row) a_[k++] += weighted * jac[row];
      b_[col] -= weighted * residual;
    }
    ++count_;
  }
  IcpSums sums() const {
    IcpSums out;
    int k = 0;
    for (int col = 0; col < 6; ++col) {
      for (int row = 0; row <= col; ++row) out.a(row, col) = a_[k++];
      out.b[col] = b_[col];
    }
    out.count = count_;
    return out;
  }

 private:
  double a_[21] = {}, b_[6] = {};
  int count_ = 0;
};

// One partial sum per band of rows, added in band order: the same sums on any number
// of threads.
// Updates rotate about the estimate's camera centre, then translate. About the world
// origin instead, a camera metres away couples every rotation with a large translation:
// the 6x6 system's conditioning (and the degeneracy test) then depended on where the
// world frame happens to be, and a run started at a ground-truth pose 3 m from the
// origin was refused as degenerate from frame 139 on.
IcpSums icp_sums(const IcpFrame& f, const Pose& estimate, const ParallelOptions& bands) {
  std::vector<IcpSums> sums(bands.chunks);
  const Eigen::Matrix3d rotation = estimate.linear();
  const Eigen::Vector3d centre = estimate.translation();
  const Pose to_previous = f.previous_inverse * estimate;  // this frame's camera to the model's
  const VertexMap& current = f.current;
  const VertexMap& model = f.model;
  const double fx = f.k.fx, fy = f.k.fy, cx = f.k.cx, cy = f.k.cy;
  const double max_squared = f.max_distance * f.max_distance, cos_max = f.cos_max;
  const double model_width = model.width, model_height = model.height;
  const auto sum_rows = [&](const Chunk& chunk) {
    NormalEquations equations;
    for (std::size_t y = chunk.begin; y < chunk.end; ++y)
      for (std::uint32_t x = 0; x < current.width; ++x) {
        const std::size_t i = y * current.width + x;
        if (!current.valid(i)) continue;
        const Eigen::Vector3d c = current.vertices[i].template cast<double>();
        const Eigen::Vector3d q = to_previous * c;
        if (q.z() <= 0.0) continue;
        const double inverse_z = 1.0 / q.z();
        const double u = std::floor(fx * q.x() * inverse_z + cx + 0.5), v = std::floor(fy * q.y() * inverse_z + cy + 0.5);
        if (!(u >= 0 && v >= 0 && u < model_width && v < model_height)) continue;
        const std::size_t j = static_cast<std::size_t>(v) * model.width + static_cast<std::size_t>(u);
        if (!model.valid(j)) continue;
        const Eigen::Vector3d p = estimate * c;
        const Eigen::Vector3d vm = model.vertices[j].template cast<double>(), nm = model.normals[j].template cast<double>();
        const Eigen::Vector3d diff = p - vm;
        if (diff.squaredNorm() > max_squared) continue;
        if ((rotation * current.normals[i].template cast<double>()).dot(nm) < cos_max) continue;
        Vec6 jac;
        jac << (p - centre).cross(nm), nm;
        equations.add(jac, 1.0, nm.dot(diff));
      }
    sums[chunk.index] = equations.sums();
  };
  parallel_for(current.height, sum_rows, bands);
  IcpSums total;
  for (const auto& s : sums) {  // in chunk order: reproducible
    total.a += s.a;
    total.b += s.b;
    total.count += s.count;
  }
  return total;
}

}  // namespace

IntensityPyramid intensity_pyramid(const RgbImage& rgb) {
  IntensityPyramid out;
  IntensityImage& base = out[0];
  base.width = rgb.width;
  base.height = rgb.height;
  base.values.resize(std::size_t{rgb.width} * rgb.height);
  for (std::size_t i = 0; i < base.values.size(); ++i) {
    const std::uint8_t* c = &rgb.rgb[i * 3];
    base.values[i] = (0.299f * c[0] + 0.587f * c[1] + 0.114f * c[2]) / 255.0f;
  }
  for (int l = 1; l < kPyramidLevels; ++l) {
    const IntensityImage& from = out[l - 1];
    IntensityImage& to = out[l];
    to.width = from.width / 2;
    to.height = from.height / 2;
    to.values.resize(std::size_t{to.width} * to.height);
    for (std::uint32_t y = 0; y < to.height; ++y)
      for (std::uint32_t x = 0; x < to.width; ++x) {
        const std::size_t a = std::size_t{2 * y} * from.width + 2 * x;
        to.values[std::size_t{y} * to.width + x] =
            0.25f * (from.values[a] + from.values[a + 1] + from.values[a + from.width] + from.values[a + from.width + 1]);
      }
  }
  return out;
}

namespace {

// Bilinear intensity at (u, v); false outside [0, width - 1) x [0, height - 1).
bool bilinear(const IntensityImage& image, double u, double v, double& value) {
  if (!(u >= 0.0 && v >= 0.0 && u < image.width - 1.0 && v < image.height - 1.0)) return false;
  const auto x = static_cast<std::size_t>(u), y = static_cast<std::size_t>(v);
  const double fx = u - static_cast<double>(x), fy = v - static_cast<double>(y);
  const float* row = image.values.data() + y * image.width + x;
  value = (1 - fy) * ((1 - fx) * row[0] + fx * row[1]) + fy * ((1 - fx) * row[image.width] + fx * row[image.width + 1]);
  return true;
}

struct PhotometricFrame {
  const VertexMap& reference;           // the previous frame's view: world vertices per pixel
  const IntensityImage& reference_intensity;
  const IntensityImage& current;        // this frame's intensity
  Intrinsics k;
  double weight, huber;
};

// The photometric residuals' normal equations (same parameters as icp_sums): the
// reference pixel's vertex v projected into the current camera at `estimate`, residual
// I_current(projection) - I_reference(pixel), its derivative through the image gradient
// and the projection. Flat reference pixels (no gradient) carry nothing and are skipped.
IcpSums photometric_sums(const PhotometricFrame& f, const Pose& estimate, const ParallelOptions& bands) {
  std::vector<IcpSums> sums(bands.chunks);
  const Pose world_to_camera = estimate.inverse();
  const Eigen::Matrix3d rotation = estimate.linear();
  const Eigen::Vector3d centre = estimate.translation();
  const IntensityImage& ref = f.reference_intensity;
  const auto sum_rows = [&](const Chunk& chunk) {
    NormalEquations equations;
    for (std::size_t y = std::max<std::size_t>(chunk.begin, 1); y < chunk.end && y + 1 < ref.height; ++y)
      for (std::uint32_t x = 1; x + 1 < ref.width; ++x) {
        const std::size_t i = y * ref.width + x;
        const Eigen::Vector3f& vf = f.reference.vertices[i];
        if (!(vf.x() == vf.x())) continue;
        const float gx_ref = ref.values[i + 1] - ref.values[i - 1], gy_ref = ref.values[i + ref.width] - ref.values[i - ref.width];
        if (gx_ref * gx_ref + gy_ref * gy_ref < 4e-4f) continue;  // under 0.01 per pixel
        const Eigen::Vector3d v = vf.template cast<double>();
        const Eigen::Vector3d q = world_to_camera * v;
        if (q.z() <= 0.0) continue;
        const double u = f.k.fx * q.x() / q.z() + f.k.cx, w = f.k.fy * q.y() / q.z() + f.k.cy;
        double i0 = 0.0, il = 0.0, ir = 0.0, iu = 0.0, id = 0.0;
        if (!bilinear(f.current, u, w, i0) || !bilinear(f.current, u - 1, w, il) || !bilinear(f.current, u + 1, w, ir) ||
            !bilinear(f.current, u, w - 1, iu) || !bilinear(f.current, u, w + 1, id))
          continue;
        const double gx = 0.5 * (ir - il), gy = 0.5 * (id - iu);
        const double iz = 1.0 / q.z();
        const Eigen::Vector3d g(gx * f.k.fx * iz, gy * f.k.fy * iz,
                                -(gx * f.k.fx * q.x() + gy * f.k.fy * q.y()) * iz * iz);
        const Eigen::Vector3d gw = rotation * g;
        Vec6 jac;
        jac << gw.cross(v - centre), -gw;
        const double r = i0 - ref.values[i];
        const double robust = std::abs(r) <= f.huber ? 1.0 : f.huber / std::abs(r);
        equations.add(jac, f.weight * robust, r);
      }
    sums[chunk.index] = equations.sums();
  };
  parallel_for(ref.height, sum_rows, bands);
  IcpSums total;
  for (const auto& s : sums) {
    total.a += s.a;
    total.b += s.b;
    total.count += s.count;
  }
  return total;
}

// The increment that solves the normal equations, applied to `estimate`; nothing when the
// geometry is degenerate. The motion prior: directions observed less than
// motion_prior * the best one are raised to that floor, pulling towards `prediction`
// (delta: the update that would reach it, in the same parameters as xi). No prediction:
// no prior.
struct IcpStep {
  Pose pose;                 // the estimate moved by the increment
  double twist_norm = 0.0;   // |xi|: the increment's size, for the stopping rule
};
std::optional<IcpStep> icp_step(const IcpSums& total, const Pose& estimate, const std::optional<Pose>& prediction,
                                double motion_prior) {
  const Mat6 a = total.a.template selfadjointView<Eigen::Upper>();
  const Eigen::SelfAdjointEigenSolver<Mat6> eigen(a);
  const Vec6& lambda = eigen.eigenvalues();  // ascending
  if (!(lambda(0) > 1e-6 * lambda(5))) return std::nullopt;  // degenerate geometry
  const Eigen::Vector3d centre = estimate.translation();
  Mat6 prior = Mat6::Zero();
  const double prior_floor = prediction ? motion_prior * lambda(5) : 0.0;
  for (int e = 0; e < 6 && lambda(e) < prior_floor; ++e)
    prior += (prior_floor - lambda(e)) * eigen.eigenvectors().col(e) * eigen.eigenvectors().col(e).transpose();
  Vec6 rhs = total.b;
  if (lambda(0) < prior_floor) {
    const Pose towards = *prediction * estimate.inverse();
    const Eigen::AngleAxisd turn(towards.linear());
    Vec6 delta;
    delta << turn.angle() * turn.axis(), towards.translation() - centre + towards.linear() * centre;
    rhs += prior * delta;
  }
  const Vec6 xi = (a + prior).ldlt().solve(rhs);
  if (!xi.allFinite()) return std::nullopt;
  const Eigen::Vector3d omega = xi.head<3>();
  Pose increment = Pose::Identity();
  const double angle = omega.norm();
  if (angle > 0.0) increment.linear() = Eigen::AngleAxisd(angle, omega / angle).toRotationMatrix();
  increment.translation() = centre + xi.tail<3>() - increment.linear() * centre;
  return IcpStep{increment * estimate, xi.norm()};
}

}  // namespace

template <class Store>
std::optional<Pose> Fusion<Store>::track(const std::array<VertexMap, kPyramidLevels>& frame, const Pose& start,
                                         const ModelView& model, const Pose& model_pose,
                                         const std::optional<Pose>& prediction, int* correspondences,
                                         const IntensityPyramid* intensity) const {
  // ICP starts at `start` (the previous pose, as KinectFusion's does, unless features
  // say the camera moved further); the constant-velocity prediction only enters through
  // the prior in the weakly observed directions, and only once a motion has been
  // tracked (not on the second frame, not after a loss).
  // (Starting at the prediction instead was unstable on room300: from frame 31 the
  // error grew 2.3 times per frame until tracking was lost at frame 39.)
  Pose estimate = start;
  // Sixteen bands whatever the thread count: the sums, added in band order, are then
  // the same on any number of threads, and the threads share the bands dynamically (one
  // band per thread left a thread idle while the other summed the half of the image
  // with more valid pixels).
  ParallelOptions bands;
  bands.threads = params_.threads;
  bands.chunks = kTrackBands;
  bands.name = "slam.track";
  int last_count = 0;
  for (int level = kPyramidLevels - 1; level >= 0; --level) {
    const IcpFrame icp{frame[level],
                       model.levels[level],
                       level_intrinsics(intrinsics_, level),
                       model_pose.inverse(),
                       params_.icp_max_distance,
                       std::cos(params_.icp_max_angle_degrees * M_PI / 180.0)};
    const bool photometric = intensity && reference_intensity_ && params_.photometric_weight > 0.0;
    for (int iteration = 0; iteration < params_.icp_iterations[level]; ++iteration) {
      IcpSums total = icp_sums(icp, estimate, bands);
      last_count = total.count;
      if (total.count < 6) return std::nullopt;
      if (photometric) {
        const PhotometricFrame pf{model_.levels[level], (*reference_intensity_)[level], (*intensity)[level],
                                  level_intrinsics(intrinsics_, level), params_.photometric_weight,
                                  params_.photometric_huber};
        const IcpSums p = photometric_sums(pf, estimate, bands);
        total.a += p.a;
        total.b += p.b;
      }
      const std::optional<IcpStep> step = icp_step(total, estimate, prediction, params_.motion_prior);
      if (!step) return std::nullopt;
      estimate = step->pose;
      if (step->twist_norm < 1e-5) break;
    }
  }
  *correspondences = last_count;
  const Pose step = start.inverse() * estimate;
  const double rotation_degrees = Eigen::AngleAxisd(step.linear()).angle() * 180.0 / M_PI;
  if (step.translation().norm() > params_.max_step_translation || rotation_degrees > params_.max_step_rotation_degrees)
    return std::nullopt;
  const std::size_t pixels = std::size_t{width_} * height_;
  if (static_cast<std::size_t>(last_count) * 100 < pixels) return std::nullopt;  // under 1% associated
  std::size_t valid = 0;
  for (std::size_t i = 0; i < frame[0].vertices.size(); ++i) valid += frame[0].valid(i) ? 1 : 0;
  // (Only from the previous pose: from a feature pose, the frame may see much that the
  // map has not, and the feature pose bounds where ICP may go.)
  if (&model == &model_ && static_cast<double>(last_count) < params_.min_overlap * static_cast<double>(valid))
    return std::nullopt;
  return estimate;
}

namespace {

bool within(const Pose& a, const Pose& b, double translation, double rotation_degrees) {
  const Pose d = a.inverse() * b;
  return d.translation().norm() <= translation &&
         Eigen::AngleAxisd(d.linear()).angle() * 180.0 / M_PI <= rotation_degrees;
}

}  // namespace

template <class Store>
ModelView Fusion<Store>::model_at(const Pose& pose) const {
  ModelView view;
  view.levels[0] = raycast(store_, intrinsics_, width_, height_, pose, params_);
  for (int l = 1; l < kPyramidLevels; ++l) view.levels[l] = halve_vertex_map(view.levels[l - 1], params_.threads);
  return view;
}

template <class Store>
std::optional<Pose> Fusion<Store>::refine_feature_pose(const std::array<VertexMap, kPyramidLevels>& frame,
                                                       const Pose& guess, int inliers, int* correspondences) const {
  const ModelView model = model_at(guess);
  // The feature pose is an independent measurement: it is the prior's prediction here.
  const auto icp = track(frame, guess, model, guess, guess, correspondences);
  const bool agrees = icp && within(guess, *icp, params_.feature_icp_translation, params_.feature_icp_rotation_degrees);
  if (inliers < params_.feature.min_inliers) {
    // A weak registration (relocalisation only) stands only when the geometry confirms
    // it: ICP converges near it with min_overlap of the frame associated.
    std::size_t valid = 0;
    for (std::size_t i = 0; i < frame[0].vertices.size(); ++i) valid += frame[0].valid(i) ? 1 : 0;
    if (agrees && static_cast<double>(*correspondences) >= params_.min_overlap * static_cast<double>(valid)) return icp;
    return std::nullopt;
  }
  if (agrees) return icp;
  if (inliers >= 2 * params_.feature.min_inliers) return guess;
  return std::nullopt;
}

template <class Store>
FeatureParams Fusion<Store>::weak_feature_params() const {
  FeatureParams weak = params_.feature;
  weak.min_inliers = std::min(weak.min_inliers, params_.relocalisation_min_inliers);
  return weak;
}

template <class Store>
void Fusion<Store>::retry_pending() {
  bool placed = false;
  for (auto it = pending_.begin(); it != pending_.end();) {
    const auto r = register_features(last_features_, it->features, weak_feature_params());
    std::optional<Pose> pose;
    int correspondences = 0;
    if (r) pose = refine_feature_pose(it->maps, pose_ * r->transform, r->inliers, &correspondences);
    if (!pose) {
      ++it;
      continue;
    }
    integrate(it->depth, it->rgb ? &*it->rgb : nullptr, *pose);
    keyframes_.push_back({std::move(it->features), *pose, it->frame, std::nullopt});
    recovered_.push_back({it->frame, *pose, r->inliers});
    placed = true;
    it = pending_.erase(it);
  }
  if (placed) model_ = model_at(pose_);
}

template <class Store>
std::vector<std::size_t> Fusion<Store>::nearest_keyframes(std::size_t count) const {
  std::vector<std::size_t> order(keyframes_.size());
  for (std::size_t i = 0; i < order.size(); ++i) order[i] = i;
  std::stable_sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) {
    return (keyframes_[a].pose.translation() - pose_.translation()).norm() <
           (keyframes_[b].pose.translation() - pose_.translation()).norm();
  });
  if (order.size() > count) order.resize(count);
  return order;
}

template <class Store>
const FeatureFrame& Fusion<Store>::sift_of(WideFeatures& wide) const {
  if (!wide.sift) wide.sift = extract_sift_features(wide.rgb, wide.depth, intrinsics_, params_.feature);
  return *wide.sift;
}

template <class Store>
std::optional<Pose> Fusion<Store>::relocalise_wide(WideFeatures& wide, const std::array<VertexMap, kPyramidLevels>& maps,
                                                   FrameResult& result, int* correspondences) {
  const FeatureFrame& current = sift_of(wide);
  if (current.size() < 3) return std::nullopt;
  std::optional<FeatureRegistration> best;
  std::size_t best_at = 0;
  for (const std::size_t i : nearest_keyframes(params_.wide_keyframes)) {
    if (!keyframes_[i].wide) continue;
    const auto r = register_features(sift_of(*keyframes_[i].wide), current, weak_feature_params());
    if (r && (!best || r->inliers > best->inliers)) {
      best = r;
      best_at = i;
    }
  }
  if (!best) return std::nullopt;
  result.feature_inliers = best->inliers;
  return refine_feature_pose(maps, keyframes_[best_at].pose * best->transform, best->inliers, correspondences);
}

// Keeps the colour and depth frames of the wide_frames_kept newest keyframes holding
// them; an older keyframe keeps its SIFT features if they were extracted.
template <class Store>
void Fusion<Store>::release_old_wide_frames() {
  std::size_t kept = 0;
  for (auto it = keyframes_.rbegin(); it != keyframes_.rend(); ++it) {
    if (!it->wide || it->wide->rgb.rgb.empty()) continue;
    if (++kept <= params_.wide_frames_kept) continue;
    if (!it->wide->sift) {
      it->wide.reset();
    } else {
      it->wide->rgb = RgbImage{};
      it->wide->depth = DepthImage{};
    }
  }
}

template <class Store>
void Fusion<Store>::remember_features(FeatureFrame&& features, std::optional<WideFeatures>&& wide) {
  if (features.size() == 0) return;
  if (keyframes_.empty() || !within(keyframes_.back().pose, pose_, params_.keyframe_translation,
                                    params_.keyframe_rotation_degrees)) {
    if (params_.loop_closure) detect_loop(features);
    keyframes_.push_back({features, pose_, frames_ - 1, std::move(wide)});
    release_old_wide_frames();
  }
  last_features_ = std::move(features);
}

// The keyframe about to be added (at pose_) against the older ones within the loop gate
// (drift is bounded; a place that merely looks alike elsewhere is not a loop), nearest
// in position and viewing direction first.
template <class Store>
void Fusion<Store>::detect_loop(const FeatureFrame& features) {
  if (keyframes_.size() <= params_.loop_skip_keyframes) return;
  const std::size_t older = keyframes_.size() - params_.loop_skip_keyframes;
  const auto apart = [&](std::size_t i) {
    const Pose d = keyframes_[i].pose.inverse() * pose_;
    return d.translation().norm() / params_.loop_gate_translation +
           Eigen::AngleAxisd(d.linear()).angle() * 180.0 / M_PI / params_.loop_gate_rotation_degrees;
  };
  std::vector<std::size_t> candidates;
  for (std::size_t i = 0; i < older; ++i)
    if (within(keyframes_[i].pose, pose_, params_.loop_gate_translation, params_.loop_gate_rotation_degrees))
      candidates.push_back(i);
  std::stable_sort(candidates.begin(), candidates.end(), [&](std::size_t a, std::size_t b) { return apart(a) < apart(b); });
  candidates.resize(std::min<std::size_t>(candidates.size(), 3));
  std::optional<LoopEdge> best;
  for (const std::size_t i : candidates) {
    const auto r = register_features(keyframes_[i].features, features, params_.feature);
    if (!r || r->inliers < params_.loop_min_inliers || (best && r->inliers <= best->inliers)) continue;
    if (!within(keyframes_[i].pose * r->transform, pose_, params_.loop_gate_translation,
                params_.loop_gate_rotation_degrees))
      continue;
    best = LoopEdge{i, keyframes_.size(), r->transform, r->inliers};
  }
  if (best) loops_.push_back(*best);
}

template <class Store>
std::vector<KeyframePose> Fusion<Store>::keyframe_poses() const {
  std::vector<KeyframePose> out;
  out.reserve(keyframes_.size());
  for (const Keyframe& k : keyframes_) out.push_back({k.frame, k.pose});
  return out;
}

template <class Store>
void Fusion<Store>::integrate_at_pose(const DepthImage& raw, const RgbImage* rgb, const Pose& pose) {
  integrate(filtered(clipped(raw, rgb)), rgb, pose);
  pose_ = pose;
  ++frames_;
}

template <class Store>
void Fusion<Store>::integrate(const DepthImage& depth, const RgbImage* rgb, const Pose& pose) {
  const VolumeGeometry& geometry = store_.geometry();
  const std::vector<BrickCoord> bricks =
      bricks_in_band(depth, intrinsics_, pose, geometry, params_.truncation, params_.threads);
  // Bricks not yet in the store are integrated into scratch space first and only stored
  // when at least one voxel was observed: the band test is per pixel ray, so a brick it
  // names can still have every voxel behind the surface or projecting outside the
  // image, and such all-unobserved bricks would hold memory without any surface.
  std::vector<TsdfVoxel*> data(bricks.size());
  std::vector<std::size_t> fresh;  // indices into `bricks` of the ones not yet stored
  for (std::size_t i = 0; i < bricks.size(); ++i) {
    data[i] = store_.brick(bricks[i]);
    if (!data[i]) fresh.push_back(i);
  }
  std::vector<TsdfVoxel> scratch(fresh.size() * kBrickVoxels);
  for (std::size_t f = 0; f < fresh.size(); ++f) data[fresh[f]] = scratch.data() + f * kBrickVoxels;
  const Pose world_to_camera = pose.inverse();
  const Eigen::Matrix3d r = world_to_camera.linear();
  const Eigen::Vector3d t = world_to_camera.translation();
  const Intrinsics k = intrinsics_;
  const double vs = geometry.voxel_size, truncation = params_.truncation;
  const float max_weight = params_.max_weight;
  ParallelOptions parallel;
  parallel.threads = params_.threads;
  parallel.grain = kBricksPerChunk;
  parallel.name = "slam.integrate";
  // A voxel's camera position is the brick corner's plus whole steps along the three
  // axes (r's columns times the voxel size), added up rather than a matrix product per
  // voxel.
  const Eigen::Vector3d step_x = r.col(0) * vs, step_y = r.col(1) * vs, step_z = r.col(2) * vs;
  const auto colour_mean = [](std::uint8_t old, std::uint8_t sample, float w) {
    return static_cast<std::uint8_t>((old * w + sample) / (w + 1.0f) + 0.5f);  // both non-negative: rounds half up
  };
  const auto integrate_bricks = [&](std::size_t begin, std::size_t end) {
    for (std::size_t b = begin; b < end; ++b) {
      const BrickCoord c = bricks[b];
      const Eigen::Vector3d corner =
          r * (geometry.origin + vs * Eigen::Vector3d(c.x * 8.0 + 0.5, c.y * 8.0 + 0.5, c.z * 8.0 + 0.5)) + t;
      TsdfVoxel* brick = data[b];
      for (int lz = 0; lz < kBrickSide; ++lz)
        for (int ly = 0; ly < kBrickSide; ++ly) {
          const Eigen::Vector3d row = corner + step_y * ly + step_z * lz;
          for (int lx = 0; lx < kBrickSide; ++lx) {
            const Eigen::Vector3d p = row + step_x * lx;
            if (p.z() <= 0.0) continue;
            const double inverse_z = 1.0 / p.z();
            const double u = std::floor(k.fx * p.x() * inverse_z + k.cx + 0.5),
                         v = std::floor(k.fy * p.y() * inverse_z + k.cy + 0.5);
            if (!(u >= 0 && v >= 0 && u < depth.width && v < depth.height)) continue;
            const std::size_t pixel = static_cast<std::size_t>(v) * depth.width + static_cast<std::size_t>(u);
            const double d = depth.metres[pixel];
            if (!(d > 0.0)) continue;
            const double sdf = d - p.z();
            if (sdf < -truncation) continue;
            const float f = static_cast<float>(std::min(1.0, sdf / truncation));
            TsdfVoxel& voxel = brick[(lz * kBrickSide + ly) * kBrickSide + lx];
            const float w = voxel.weight;
            voxel.tsdf = (voxel.tsdf * w + f) / (w + 1.0f);
            if (rgb && std::abs(sdf) < truncation * 0.5) {
              const std::uint8_t* c3 = &rgb->rgb[pixel * 3];
              voxel.r = colour_mean(voxel.r, c3[0], w);
              voxel.g = colour_mean(voxel.g, c3[1], w);
              voxel.b = colour_mean(voxel.b, c3[2], w);
            }
            voxel.weight = std::min(w + 1.0f, max_weight);
          }
        }
    }
  };
  parallel_for(bricks.size(), integrate_bricks, parallel);
  for (std::size_t f = 0; f < fresh.size(); ++f) {
    const TsdfVoxel* brick = scratch.data() + f * kBrickVoxels;
    if (std::any_of(brick, brick + kBrickVoxels, [](const TsdfVoxel& v) { return v.weight > 0.0f; }))
      std::copy(brick, brick + kBrickVoxels, store_.allocate(bricks[fresh[f]]));
  }
}

template <class Store>
DepthImage Fusion<Store>::clipped(const DepthImage& raw, const RgbImage* rgb) const {
  if (raw.width != width_ || raw.height != height_)
    throw InvalidArgument("depth frame is " + std::to_string(raw.width) + " x " + std::to_string(raw.height) +
                          ", the sequence's first was " + std::to_string(width_) + " x " + std::to_string(height_));
  if (rgb && (rgb->width != width_ || rgb->height != height_))
    throw InvalidArgument("colour frame size differs from the depth frame's");
  DepthImage depth = raw;
  for (float& d : depth.metres)
    if (!(d >= params_.min_depth && d <= params_.max_depth)) d = 0.0f;
  return depth;
}

// The map integrates the bilateral-filtered depth, not the raw one: while a region has
// been seen only once, the model raycast from it carries that frame's noise in its
// normals, and on large planes those noisy normals add false stiffness in the weakly
// observed directions (sliding along a wall), which dragged ICP several centimetres off
// (the generated room's first step: 57 mm error from raw, under 1 mm from filtered).
template <class Store>
DepthImage Fusion<Store>::filtered(const DepthImage& depth) const {
  return bilateral_filter(depth, params_.bilateral_radius, params_.bilateral_sigma_space, params_.bilateral_sigma_depth,
                          params_.threads);
}

// The frame's vertex and normal maps at every pyramid level (depth halved level by level).
template <class Store>
std::array<VertexMap, kPyramidLevels> Fusion<Store>::frame_maps(const DepthImage& depth) const {
  std::array<VertexMap, kPyramidLevels> maps;
  DepthImage level = depth;
  for (int l = 0; l < kPyramidLevels; ++l) {
    if (l > 0) level = halve_depth(level, params_.bilateral_sigma_depth, params_.threads);
    maps[l] = vertex_normal_map(level, level_intrinsics(intrinsics_, l), params_.threads);
  }
  return maps;
}

template <class Store>
void Fusion<Store>::integrate_and_predict(const DepthImage& depth, const RgbImage* rgb) {
  integrate(depth, rgb, pose_);
  model_.levels[0] = raycast(store_, intrinsics_, width_, height_, pose_, params_);
  for (int l = 1; l < kPyramidLevels; ++l) model_.levels[l] = halve_vertex_map(model_.levels[l - 1], params_.threads);
}

template <class Store>
FrameResult Fusion<Store>::process(const DepthImage& raw, const RgbImage* rgb, const Pose& initial_pose) {
  const DepthImage clipped_depth = clipped(raw, rgb);
  const DepthImage depth = filtered(clipped_depth);
  FeatureFrame features;
  std::optional<WideFeatures> wide;
  if (params_.features && rgb && features_available()) {
    // Features keep the far measurements that fusion drops (beyond max_depth): matched
    // by reprojection, their depth noise matters little, and a view of a far wall may
    // have little else.
    DepthImage near_clipped = raw;
    for (float& d : near_clipped.metres)
      if (!(d >= params_.min_depth)) d = 0.0f;
    features = extract_features(*rgb, near_clipped, intrinsics_, params_.feature);
    if (params_.wide_features) wide = WideFeatures{*rgb, std::move(near_clipped), std::nullopt};
  }
  std::optional<IntensityPyramid> intensity;
  if (rgb && params_.photometric_weight > 0.0) intensity = intensity_pyramid(*rgb);
  FrameResult result;
  if (frames_ == 0) {
    pose_ = initial_pose;
  } else {
    const std::array<VertexMap, kPyramidLevels> maps = frame_maps(depth);
    int correspondences = 0;
    // The motion since the last tracked frame from colour features, when they agree;
    // when few agree, the nearest keyframes may share more of the view.
    std::optional<Pose> feature_pose;
    if (features.size() && last_features_.size()) {
      std::optional<FeatureRegistration> best = register_features(last_features_, features, params_.feature);
      if (best) feature_pose = pose_ * best->transform;
      if (!best || best->inliers < 4 * params_.feature.min_inliers)
        for (const std::size_t i : nearest_keyframes(kNearbyKeyframes)) {
          const auto r = register_features(keyframes_[i].features, features, params_.feature);
          if (r && (!best || r->inliers > best->inliers)) {
            best = r;
            feature_pose = keyframes_[i].pose * r->transform;
          }
        }
      if (best) result.feature_inliers = best->inliers;
    }
    // ICP from the previous pose first (cheap, and the most precise for small motions);
    // its answer is vetoed when a well-supported feature pose disagrees with it (a jump it
    // could not follow, converged to a wrong place), and ICP then starts from the
    // feature pose instead.
    const std::optional<Pose> prediction = motion_ ? std::optional<Pose>(pose_ * *motion_) : std::nullopt;
    std::optional<Pose> tracked =
        track(maps, pose_, model_, pose_, prediction, &correspondences, intensity ? &*intensity : nullptr);
    if (tracked && feature_pose && result.feature_inliers >= 2 * params_.feature.min_inliers &&
        !within(*tracked, *feature_pose, params_.feature_icp_translation, params_.feature_icp_rotation_degrees)) {
      // The two disagree: ICP from the feature pose too, and the answer that more of the
      // frame associates with wins. (Taking the feature pose whenever they disagreed put
      // one frame of the generated room 12 cm off, its repeating floor tiles matched one
      // tile over, and the room's ATE went from 0.40 to 1.84 cm.)
      int count = 0;
      const ModelView model = model_at(*feature_pose);
      const auto from_features = track(maps, *feature_pose, model, *feature_pose, *feature_pose, &count);
      if (from_features &&
          within(*feature_pose, *from_features, params_.feature_icp_translation, params_.feature_icp_rotation_degrees) &&
          count > correspondences) {
        tracked = from_features;
        correspondences = count;
        result.wide_baseline = true;
      }
    }
    if (!tracked && feature_pose) {
      tracked = refine_feature_pose(maps, *feature_pose, result.feature_inliers, &correspondences);
      result.wide_baseline = tracked.has_value();
    }
    if (!tracked && features.size()) {
      // Relocalisation: the keyframe with the most feature inliers, nearest first on ties.
      std::optional<FeatureRegistration> best;
      std::size_t best_at = 0;
      for (const std::size_t i : nearest_keyframes(keyframes_.size())) {
        const auto r = register_features(keyframes_[i].features, features, weak_feature_params());
        if (r && (!best || r->inliers > best->inliers)) {
          best = r;
          best_at = i;
        }
      }
      if (best) {
        result.feature_inliers = best->inliers;
        tracked = refine_feature_pose(maps, keyframes_[best_at].pose * best->transform, best->inliers, &correspondences);
        result.relocalised = tracked.has_value();
      }
    }
    if (!tracked && wide) {
      tracked = relocalise_wide(*wide, maps, result, &correspondences);
      result.relocalised = tracked.has_value();
    }
    result.correspondences = correspondences;
    result.tracked = tracked.has_value();
    if (tracked && previous_lost_) result.relocalised = true;
    previous_lost_ = !tracked;
    // The constant-velocity model: the last motion, forgotten when a frame is lost.
    motion_.reset();
    if (tracked) motion_ = Pose(pose_.inverse() * *tracked);
    if (tracked) pose_ = *tracked;
  }
  result.pose = pose_;
  ++frames_;
  if (result.tracked) {
    integrate_and_predict(depth, rgb);
    remember_features(std::move(features), std::move(wide));
    reference_intensity_ = std::move(intensity);
    retry_pending();
  } else if (frames_ > 1 && features.size() && params_.max_pending > 0) {
    if (pending_.size() >= params_.max_pending) pending_.erase(pending_.begin());
    pending_.push_back({frames_ - 1, std::move(features), frame_maps(depth), depth,
                        rgb ? std::optional<RgbImage>(*rgb) : std::nullopt});
  }
  return result;
}

template <class Store>
FrameResult Fusion<Store>::process_at_pose(const DepthImage& raw, const RgbImage* rgb, const Pose& pose) {
  const DepthImage depth = filtered(clipped(raw, rgb));
  motion_.reset();
  if (frames_) motion_ = Pose(pose_.inverse() * pose);
  pose_ = pose;
  ++frames_;
  integrate_and_predict(depth, rgb);
  reference_intensity_.reset();
  if (rgb && params_.photometric_weight > 0.0) reference_intensity_ = intensity_pyramid(*rgb);
  FrameResult result;
  result.pose = pose_;
  return result;
}

template class Fusion<SparseTsdfStore>;
template class Fusion<DenseTsdfStore>;
template VertexMap raycast(const SparseTsdfStore&, const Intrinsics&, std::uint32_t, std::uint32_t, const Pose&,
                           const FusionParams&);
template VertexMap raycast(const DenseTsdfStore&, const Intrinsics&, std::uint32_t, std::uint32_t, const Pose&,
                           const FusionParams&);
template RgbImage render_view(const SparseTsdfStore&, const Intrinsics&, std::uint32_t, std::uint32_t, const Pose&,
                              const FusionParams&, bool);
template RgbImage render_view(const DenseTsdfStore&, const Intrinsics&, std::uint32_t, std::uint32_t, const Pose&,
                              const FusionParams&, bool);

}  // namespace vola::slam
