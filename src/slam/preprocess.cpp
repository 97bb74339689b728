#include "vola/slam/preprocess.hpp"

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstdint>
#include <limits>

#include "vola/parallel.hpp"

namespace vola::slam {

namespace {
constexpr std::size_t kImageRowsPerChunk = 4;  // every pixel is written on its own: any chunking gives the same image

// The parallel loop over rows that every per-pixel step here uses.
ParallelOptions rows(unsigned threads, const char* name) {
  ParallelOptions options;
  options.threads = threads;
  options.grain = kImageRowsPerChunk;
  options.name = name;
  return options;
}

// exp(-x) for 0 <= x (clamped at 80, where it is 2e-35), as 2^-(x log2 e): the integer
// part goes into the float's exponent bits, the fraction (in (-1, 0]) through a degree-7
// Taylor polynomial of 2^f (relative error under 2e-6). The depth weights took half of
// the filter's time in libm's exp, and a lookup table's gathers kept the loop scalar
// (7.5 ns per tap at 320 x 240). No float comparison either: under the default
// -ftrapping-math GCC will not turn a float select into vector code, so the clamp
// compares bit patterns (ordered like the values for non-negative floats).
inline float negative_exp(float x) {
  const float clamped =
      std::bit_cast<float>(std::min(std::bit_cast<std::int32_t>(x), std::bit_cast<std::int32_t>(80.0f)));
  const float t = -clamped * 1.44269504f;
  const auto whole = static_cast<std::int32_t>(t);  // toward zero: t - whole is in (-1, 0]
  const float f = (t - static_cast<float>(whole)) * 0.693147181f;
  float p = 1.0f / 5040;
  p = p * f + 1.0f / 720;
  p = p * f + 1.0f / 120;
  p = p * f + 1.0f / 24;
  p = p * f + 1.0f / 6;
  p = p * f + 0.5f;
  p = p * f + 1.0f;
  p = p * f + 1.0f;
  return p * std::bit_cast<float>((whole + 127) << 23);
}
// One tap of the bilateral filter along a row: for every pixel x, the neighbour row[x]
// at the tap's offset adds spatial x exp(-(row[x] - centre[x])^2 range) to weight[x]
// and that weight x (row[x] - centre[x]) to sum[x]. Compiled twice, for AVX2 (eight
// floats a step) and for the baseline (four), and chosen when the program loads; the
// same operations in the same order either way (no FMA), so the same image.
__attribute__((target_clones("avx2", "default"))) void accumulate_tap(const float* row, const float* centre,
                                                                     float spatial, float range, float* sum,
                                                                     float* weight, int width) {
  const std::int32_t spatial_bits = std::bit_cast<std::int32_t>(spatial);
  for (int x = 0; x < width; ++x) {
    const float d = row[x], diff = d - centre[x];
    // Computed for holes too, then zeroed by masking the spatial weight's bits (a branch
    // or a float select would keep the loop scalar).
    const std::int32_t valid = -static_cast<std::int32_t>(std::bit_cast<std::int32_t>(d) > 0);
    const float wt = std::bit_cast<float>(spatial_bits & valid) * negative_exp(diff * diff * range);
    sum[x] += wt * diff;
    weight[x] += wt;
  }
}
}  // namespace

// Tap by tap over whole rows rather than pixel by pixel: for each of the (2r + 1)^2
// offsets, one pass along the row accumulates weight x (depth - centre depth) and weight
// for every pixel, which the compiler vectorises (in floats, the differences keep the
// sums' rounding far below a micrometre). The image is padded by r with zeros (holes, so
// weight 0) so that no pass tests the borders.
DepthImage bilateral_filter(const DepthImage& depth, int radius, double sigma_space, double sigma_depth,
                            unsigned threads) {
  DepthImage out{depth.width, depth.height, std::vector<float>(depth.metres.size(), 0.0f)};
  const int w = static_cast<int>(depth.width), h = static_cast<int>(depth.height);
  const int side = 2 * radius + 1;
  const float range = static_cast<float>(1.0 / (2 * sigma_depth * sigma_depth));
  std::vector<float> spatial(std::size_t(side) * side);
  for (int dy = -radius; dy <= radius; ++dy)
    for (int dx = -radius; dx <= radius; ++dx)
      spatial[std::size_t(dy + radius) * side + dx + radius] =
          static_cast<float>(std::exp(-(dx * dx + dy * dy) / (2 * sigma_space * sigma_space)));
  const std::size_t padded_width = std::size_t(w) + 2 * radius;
  std::vector<float> padded(padded_width * (std::size_t(h) + 2 * radius), 0.0f);
  for (int y = 0; y < h; ++y)
    std::copy_n(depth.metres.data() + std::size_t(y) * w, w, padded.data() + (y + radius) * padded_width + radius);
  const auto filter_rows = [&](std::size_t begin, std::size_t end) {
    std::vector<float> sums(w), weights(w);
    for (int y = static_cast<int>(begin); y < static_cast<int>(end); ++y) {
      std::fill(sums.begin(), sums.end(), 0.0f);
      std::fill(weights.begin(), weights.end(), 0.0f);
      const float* centre = depth.metres.data() + std::size_t(y) * w;
      for (int dy = 0; dy < side; ++dy)
        for (int dx = 0; dx < side; ++dx) {
          const float* row = padded.data() + (y + dy) * padded_width + dx;  // offset (dx - r, dy - r)
          accumulate_tap(row, centre, spatial[std::size_t(dy) * side + dx], range, sums.data(), weights.data(), w);
        }
      float* target = out.metres.data() + std::size_t(y) * w;
      for (int x = 0; x < w; ++x) target[x] = centre[x] > 0.0f ? centre[x] + sums[x] / weights[x] : 0.0f;
    }
  };
  parallel_for(depth.height, filter_rows, rows(threads, "slam.bilateral_filter"));
  return out;
}

DepthImage halve_depth(const DepthImage& depth, double sigma_depth, unsigned threads) {
  DepthImage out{depth.width / 2, depth.height / 2, {}};
  out.metres.assign(std::size_t{out.width} * out.height, 0.0f);
  parallel_for(
      out.height,
      [&](std::size_t begin, std::size_t end) {
        for (auto y = static_cast<std::uint32_t>(begin); y < end; ++y)
          for (std::uint32_t x = 0; x < out.width; ++x) {
            const float first = depth.at(2 * x, 2 * y);
            if (first <= 0.0f) continue;
            double sum = 0.0;
            int n = 0;
            for (std::uint32_t dy = 0; dy < 2; ++dy)
              for (std::uint32_t dx = 0; dx < 2; ++dx) {
                const float d = depth.at(2 * x + dx, 2 * y + dy);
                if (d > 0.0f && std::abs(d - first) <= 3 * sigma_depth) {
                  sum += d;
                  ++n;
                }
              }
            out.metres[std::size_t{y} * out.width + x] = static_cast<float>(sum / n);
          }
      },
      rows(threads, "slam.halve_depth"));
  return out;
}

VertexMap vertex_normal_map(const DepthImage& depth, const Intrinsics& k, unsigned threads) {
  const float nan = std::numeric_limits<float>::quiet_NaN();
  const std::size_t n = depth.metres.size();
  VertexMap map{depth.width, depth.height, std::vector<Eigen::Vector3f>(n, Eigen::Vector3f::Constant(nan)),
                std::vector<Eigen::Vector3f>(n, Eigen::Vector3f::Constant(nan))};
  parallel_for(
      depth.height,
      [&](std::size_t begin, std::size_t end) {
        for (auto y = static_cast<std::uint32_t>(begin); y < end; ++y)
          for (std::uint32_t x = 0; x < depth.width; ++x) {
            const float d = depth.at(x, y);
            if (d <= 0.0f) continue;
            map.vertices[std::size_t{y} * depth.width + x] = Eigen::Vector3f(
                static_cast<float>((x - k.cx) / k.fx * d), static_cast<float>((y - k.cy) / k.fy * d), d);
          }
      },
      rows(threads, "slam.vertex_map"));
  parallel_for(
      depth.height ? depth.height - 1 : 0,  // the last row has no lower neighbours
      [&](std::size_t begin, std::size_t end) {
        for (auto y = static_cast<std::uint32_t>(begin); y < end; ++y)
          for (std::uint32_t x = 0; x + 1 < depth.width; ++x) {
            const std::size_t i = std::size_t{y} * depth.width + x;
            const Eigen::Vector3f& v = map.vertices[i];
            const Eigen::Vector3f& right = map.vertices[i + 1];
            const Eigen::Vector3f& down = map.vertices[i + depth.width];
            if (!(v.x() == v.x() && right.x() == right.x() && down.x() == down.x())) continue;
            Eigen::Vector3f normal = (right - v).cross(down - v);
            const float length = normal.norm();
            if (!(length > 0.0f)) continue;
            normal /= length;
            if (normal.dot(v) > 0.0f) normal = -normal;  // face the camera, whatever the sign of fy
            map.normals[i] = normal;
          }
      },
      rows(threads, "slam.normal_map"));
  return map;
}

VertexMap halve_vertex_map(const VertexMap& map, unsigned threads) {
  const float nan = std::numeric_limits<float>::quiet_NaN();
  VertexMap out;
  out.width = map.width / 2;
  out.height = map.height / 2;
  const std::size_t n = std::size_t{out.width} * out.height;
  out.vertices.assign(n, Eigen::Vector3f::Constant(nan));
  out.normals.assign(n, Eigen::Vector3f::Constant(nan));
  parallel_for(
      out.height,
      [&](std::size_t begin, std::size_t end) {
        for (auto y = static_cast<std::uint32_t>(begin); y < end; ++y)
          for (std::uint32_t x = 0; x < out.width; ++x) {
            Eigen::Vector3f v = Eigen::Vector3f::Zero(), nsum = Eigen::Vector3f::Zero();
            int count = 0;
            for (std::uint32_t dy = 0; dy < 2; ++dy)
              for (std::uint32_t dx = 0; dx < 2; ++dx) {
                const std::size_t i = std::size_t{2 * y + dy} * map.width + 2 * x + dx;
                if (!map.valid(i)) continue;
                v += map.vertices[i];
                nsum += map.normals[i];
                ++count;
              }
            const float length = nsum.norm();
            if (count == 0 || !(length > 0.0f)) continue;
            out.vertices[std::size_t{y} * out.width + x] = v / static_cast<float>(count);
            out.normals[std::size_t{y} * out.width + x] = nsum / length;
          }
      },
      rows(threads, "slam.halve_vertex_map"));
  return out;
}

}  // namespace vola::slam
