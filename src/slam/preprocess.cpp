#include "vola/slam/preprocess.hpp"

#include <cmath>
#include <limits>

#include "vola/parallel.hpp"

namespace vola::slam {

namespace {
constexpr std::size_t kRowsPerChunk = 4;  // every pixel is written on its own: any chunking gives the same image

// exp(-x) for x >= 0, linear between 4096 samples over [0, 32] (absolute error under
// 8e-6) and 0 beyond (e^-32 is 1e-14): the bilateral filter's depth weights, which took
// half of the filter's time in libm's exp.
class NegativeExpTable {
 public:
  static constexpr double kEnd = 32.0;
  static constexpr int kSteps = 4096;
  NegativeExpTable() {
    for (int i = 0; i <= kSteps + 1; ++i) values_[i] = std::exp(-i * (kEnd / kSteps));
  }
  double operator()(double x) const {
    if (!(x < kEnd)) return 0.0;
    const double at = x * (kSteps / kEnd);
    const int i = static_cast<int>(at);
    return values_[i] + (at - i) * (values_[i + 1] - values_[i]);
  }

 private:
  double values_[kSteps + 2];
};
}  // namespace

DepthImage bilateral_filter(const DepthImage& depth, int radius, double sigma_space, double sigma_depth,
                            unsigned threads) {
  DepthImage out{depth.width, depth.height, std::vector<float>(depth.metres.size(), 0.0f)};
  const double space = 1.0 / (2 * sigma_space * sigma_space), range = 1.0 / (2 * sigma_depth * sigma_depth);
  std::vector<double> spatial((2 * radius + 1) * (2 * radius + 1));
  for (int dy = -radius; dy <= radius; ++dy)
    for (int dx = -radius; dx <= radius; ++dx)
      spatial[(dy + radius) * (2 * radius + 1) + dx + radius] = std::exp(-(dx * dx + dy * dy) * space);
  static const NegativeExpTable negative_exp;
  const int w = static_cast<int>(depth.width), h = static_cast<int>(depth.height);
  ParallelOptions parallel;
  parallel.threads = threads;
  parallel.grain = kRowsPerChunk;
  parallel.name = "slam.bilateral_filter";
  const auto filter_rows = [&](std::size_t begin, std::size_t end) {
    for (int y = static_cast<int>(begin); y < static_cast<int>(end); ++y)
      for (int x = 0; x < w; ++x) {
        const float centre = depth.metres[std::size_t(y) * w + x];
        if (centre <= 0.0f) continue;
        double sum = 0.0, weights = 0.0;
        for (int dy = std::max(-radius, -y); dy <= std::min(radius, h - 1 - y); ++dy)
          for (int dx = std::max(-radius, -x); dx <= std::min(radius, w - 1 - x); ++dx) {
            const float d = depth.metres[std::size_t(y + dy) * w + x + dx];
            if (d <= 0.0f) continue;
            const double diff = d - centre;
            const double weight =
                spatial[(dy + radius) * (2 * radius + 1) + dx + radius] * negative_exp(diff * diff * range);
            sum += weight * d;
            weights += weight;
          }
        out.metres[std::size_t(y) * w + x] = static_cast<float>(sum / weights);
      }
  };
  parallel_for(depth.height, filter_rows, parallel);
  return out;
}

DepthImage halve_depth(const DepthImage& depth, double sigma_depth) {
  DepthImage out{depth.width / 2, depth.height / 2, {}};
  out.metres.assign(std::size_t{out.width} * out.height, 0.0f);
  for (std::uint32_t y = 0; y < out.height; ++y)
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
  return out;
}

VertexMap vertex_normal_map(const DepthImage& depth, const Intrinsics& k) {
  const float nan = std::numeric_limits<float>::quiet_NaN();
  const std::size_t n = depth.metres.size();
  VertexMap map{depth.width, depth.height, std::vector<Eigen::Vector3f>(n, Eigen::Vector3f::Constant(nan)),
                std::vector<Eigen::Vector3f>(n, Eigen::Vector3f::Constant(nan))};
  for (std::uint32_t y = 0; y < depth.height; ++y)
    for (std::uint32_t x = 0; x < depth.width; ++x) {
      const float d = depth.at(x, y);
      if (d <= 0.0f) continue;
      map.vertices[std::size_t{y} * depth.width + x] =
          Eigen::Vector3f(static_cast<float>((x - k.cx) / k.fx * d), static_cast<float>((y - k.cy) / k.fy * d), d);
    }
  for (std::uint32_t y = 0; y + 1 < depth.height; ++y)
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
  return map;
}

VertexMap halve_vertex_map(const VertexMap& map) {
  const float nan = std::numeric_limits<float>::quiet_NaN();
  VertexMap out;
  out.width = map.width / 2;
  out.height = map.height / 2;
  const std::size_t n = std::size_t{out.width} * out.height;
  out.vertices.assign(n, Eigen::Vector3f::Constant(nan));
  out.normals.assign(n, Eigen::Vector3f::Constant(nan));
  for (std::uint32_t y = 0; y < out.height; ++y)
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
  return out;
}

}  // namespace vola::slam
