#include "vola/learn/segment.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>

#include "vola/analysis/components.hpp"
#include "vola/analysis/crop.hpp"
#include "vola/builder.hpp"
#include "vola/error.hpp"
#include "vola/learn/classifier.hpp"
#include "vola/learn/occupancy.hpp"

namespace vola::learn {

PlaneRemoval remove_bounding_planes(const Tree& scene, const SegmentOptions& options) {
  if (!(options.plane_fill > 0 && options.plane_fill <= 1))
    throw InvalidArgument("plane_fill must be in (0, 1], got " + std::to_string(options.plane_fill));
  if (options.max_plane_layers < 0)
    throw InvalidArgument("max_plane_layers must be 0 or more, got " + std::to_string(options.max_plane_layers));
  PlaneRemoval result;
  if (scene.empty()) {
    result.rest = scene;
    result.min = {1, 1, 1};
    result.max = {0, 0, 0};
    return result;
  }
  // Voxels per layer along each axis, and the scene's bounding box.
  const std::uint32_t side = scene.side();
  std::array<std::vector<std::uint64_t>, 3> layer;
  for (auto& counts : layer) counts.assign(side, 0);
  scene.for_each_voxel([&](const Voxel& v) {
    ++layer[0][v.x];
    ++layer[1][v.y];
    ++layer[2][v.z];
  });
  std::array<std::uint32_t, 3> lo{}, hi{};
  for (int a = 0; a < 3; ++a) {
    const auto& counts = layer[std::size_t(a)];
    lo[std::size_t(a)] = std::uint32_t(std::find_if(counts.begin(), counts.end(), [](auto c) { return c > 0; }) - counts.begin());
    hi[std::size_t(a)] = std::uint32_t(side - 1 - (std::find_if(counts.rbegin(), counts.rend(), [](auto c) { return c > 0; }) - counts.rbegin()));
  }
  std::array<std::uint32_t, 3> keep_lo = lo, keep_hi = hi;
  for (int a = 0; a < 3; ++a) {
    const std::size_t u = std::size_t((a + 1) % 3), w = std::size_t((a + 2) % 3);
    const double cross_section = double(hi[u] - lo[u] + 1) * double(hi[w] - lo[w] + 1);
    const auto& counts = layer[std::size_t(a)];
    const auto is_plane = [&](std::uint32_t c) { return double(counts[c]) >= options.plane_fill * cross_section; };
    for (bool at_max : {false, true}) {
      RemovedPlane plane;
      plane.axis = a;
      plane.at_max = at_max;
      plane.first = at_max ? hi[std::size_t(a)] : lo[std::size_t(a)];
      for (int k = 0; k < options.max_plane_layers; ++k) {
        if (keep_lo[std::size_t(a)] > keep_hi[std::size_t(a)]) break;
        const std::uint32_t c = at_max ? keep_hi[std::size_t(a)] : keep_lo[std::size_t(a)];
        if (!is_plane(c)) break;
        plane.voxels += counts[c];
        ++plane.layers;
        if (at_max) {
          if (keep_hi[std::size_t(a)] == 0) {
            keep_lo[std::size_t(a)] = 1;  // nothing left on this axis
            break;
          }
          --keep_hi[std::size_t(a)];
        } else {
          ++keep_lo[std::size_t(a)];
        }
      }
      if (plane.layers > 0) result.planes.push_back(plane);
    }
  }
  result.min = {keep_lo[0], keep_lo[1], keep_lo[2]};
  result.max = {keep_hi[0], keep_hi[1], keep_hi[2]};
  const bool nothing = keep_lo[0] > keep_hi[0] || keep_lo[1] > keep_hi[1] || keep_lo[2] > keep_hi[2];
  result.rest = nothing ? build_from_voxels({}, scene.depth()) : analysis::crop(scene, result.min, result.max);
  return result;
}

namespace {

// The turn in [0, pi/2) (whole degrees) after which the object's horizontal layers have
// the smallest bounding rectangles, summed over the layers: each layer of furniture (a
// table top, a seat, a screen, a base plate) is a rectangle or a line along the
// object's own axes, while the footprint of the whole may be square and say nothing.
// Ties go to the smallest angle.
double footprint_angle_of(const std::vector<std::vector<std::array<double, 2>>>& layers) {
  double best_angle = 0, best_area = std::numeric_limits<double>::infinity();
  for (int degrees = 0; degrees < 90; ++degrees) {
    const double angle = degrees * std::numbers::pi / 180;
    const double c = std::cos(angle), s = std::sin(angle);
    double area = 0;
    for (const auto& cells : layers) {
      if (cells.empty()) continue;
      double x0 = 1e300, x1 = -1e300, y0 = 1e300, y1 = -1e300;
      for (const auto& p : cells) {
        // The cell turned by -angle (its layer's rectangle then lies along the axes).
        const double x = c * p[0] + s * p[1], y = -s * p[0] + c * p[1];
        x0 = std::min(x0, x);
        x1 = std::max(x1, x);
        y0 = std::min(y0, y);
        y1 = std::max(y1, y);
      }
      area += (x1 - x0 + 1) * (y1 - y0 + 1);
    }
    if (area < best_area - 1e-9) {
      best_area = area;
      best_angle = angle;
    }
  }
  return best_angle;
}

}  // namespace

Segmentation segment_object(const Tree& scene, const SegmentOptions& options) {
  Segmentation result;
  result.removal = remove_bounding_planes(scene, options);
  const Tree& rest = result.removal.rest;
  result.object = build_from_voxels({}, scene.depth());
  if (rest.empty()) return result;
  const auto labels = analysis::label_components(rest, analysis::Connectivity::corners);
  const auto& components = labels.components;
  // Pieces: components whose boxes come within join_gap empty voxels of each other
  // (union-find over the components; a thin bar voxelised in pieces is one piece).
  std::vector<std::size_t> parent(components.size());
  for (std::size_t i = 0; i < parent.size(); ++i) parent[i] = i;
  const auto root = [&](std::size_t i) {
    while (parent[i] != i) i = parent[i] = parent[parent[i]];
    return i;
  };
  const auto near = [&](const analysis::Component& a, const analysis::Component& b) {
    const std::uint32_t g = std::uint32_t(options.join_gap) + 1;
    return a.min.x <= b.max.x + g && b.min.x <= a.max.x + g && a.min.y <= b.max.y + g && b.min.y <= a.max.y + g &&
           a.min.z <= b.max.z + g && b.min.z <= a.max.z + g;
  };
  for (std::size_t i = 0; i < components.size(); ++i)
    for (std::size_t j = i + 1; j < components.size(); ++j)
      if (near(components[i], components[j])) parent[root(i)] = root(j);
  struct Piece {
    std::uint64_t voxels = 0;
    Voxel min{~0u, ~0u, ~0u}, max{0, 0, 0};
    double cx = 0, cy = 0;  // voxel-weighted centroid
  };
  std::vector<Piece> pieces(components.size());
  for (std::size_t i = 0; i < components.size(); ++i) {
    const auto& c = components[i];
    Piece& p = pieces[root(i)];
    p.voxels += c.voxels;
    p.min = {std::min(p.min.x, c.min.x), std::min(p.min.y, c.min.y), std::min(p.min.z, c.min.z)};
    p.max = {std::max(p.max.x, c.max.x), std::max(p.max.y, c.max.y), std::max(p.max.z, c.max.z)};
    p.cx += c.centroid[0] * double(c.voxels);
    p.cy += c.centroid[1] * double(c.voxels);
  }
  const double centre = scene.side() / 2.0;
  const auto volume = [](const Piece& p) {
    return double(p.max.x - p.min.x + 1) * double(p.max.y - p.min.y + 1) * double(p.max.z - p.min.z + 1);
  };
  const auto distance = [&](const Piece& p) {
    return std::hypot(p.cx / double(p.voxels) - centre, p.cy / double(p.voxels) - centre);
  };
  std::size_t chosen = pieces.size();
  for (std::size_t i = 0; i < pieces.size(); ++i) {
    const Piece& c = pieces[i];
    if (root(i) != i || c.voxels < options.min_voxels) continue;
    ++result.components;
    if (chosen == pieces.size()) {
      chosen = i;
      continue;
    }
    const Piece& b = pieces[chosen];
    const double vc = volume(c), vb = volume(b);
    if (vc > vb || (vc == vb && (c.voxels > b.voxels || (c.voxels == b.voxels && distance(c) < distance(b))))) chosen = i;
  }
  if (chosen == pieces.size()) return result;
  // The chosen piece and every piece standing in its footprint (its xy box).
  const Piece box = pieces[chosen];
  std::vector<bool> part(components.size(), false);
  result.min = box.min;
  result.max = box.max;
  for (std::size_t i = 0; i < components.size(); ++i) {
    const Piece& p = pieces[root(i)];
    if (root(i) != chosen && !(p.min.x <= box.max.x && p.max.x >= box.min.x && p.min.y <= box.max.y && p.max.y >= box.min.y))
      continue;
    part[i] = true;
    const auto& c = components[i];
    result.min = {std::min(result.min.x, c.min.x), std::min(result.min.y, c.min.y), std::min(result.min.z, c.min.z)};
    result.max = {std::max(result.max.x, c.max.x), std::max(result.max.y, c.max.y), std::max(result.max.z, c.max.z)};
  }
  std::vector<Voxel> voxels;
  std::vector<std::vector<std::array<double, 2>>> layers(std::size_t(result.max.z - result.min.z) + 1);
  std::uint64_t rank = 0;
  rest.for_each_voxel([&](const Voxel& v) {
    if (part[labels.label[rank++]]) {
      voxels.push_back(v);
      layers[v.z - result.min.z].push_back({v.x + 0.5, v.y + 0.5});
    }
  });
  // for_each_voxel visits in key order, which build_from_voxels accepts in any order.
  result.object = build_from_voxels(voxels, scene.depth());
  result.footprint_angle = footprint_angle_of(layers);
  return result;
}

Tree normalise_object(const Tree& object, double footprint_angle) {
  if (object.empty()) return build_from_voxels({}, kSceneDepth);
  // The object's voxel centres turned by -angle: their box sets the scale and centre.
  const double c = std::cos(footprint_angle), s = std::sin(footprint_angle);
  double lo[3] = {1e300, 1e300, 1e300}, hi[3] = {-1e300, -1e300, -1e300};
  object.for_each_voxel([&](const Voxel& v) {
    const double px = v.x + 0.5, py = v.y + 0.5;
    const double p[3] = {c * px + s * py, -s * px + c * py, v.z + 0.5};
    for (int a = 0; a < 3; ++a) {
      lo[a] = std::min(lo[a], p[a] - 0.5);
      hi[a] = std::max(hi[a], p[a] + 0.5);
    }
  });
  const double extent = std::max({hi[0] - lo[0], hi[1] - lo[1], hi[2] - lo[2]});
  const double scale = kSceneSide / extent;  // output voxels per object voxel
  const double mid[3] = {(lo[0] + hi[0]) / 2, (lo[1] + hi[1]) / 2, (lo[2] + hi[2]) / 2};
  const double limit = object.side();
  std::vector<Voxel> voxels;
  for (std::uint32_t x = 0; x < std::uint32_t(kSceneSide); ++x)
    for (std::uint32_t y = 0; y < std::uint32_t(kSceneSide); ++y) {
      // The output column's centre in the turned frame, then turned back by +angle.
      const double tx = mid[0] + (x + 0.5 - kSceneSide / 2.0) / scale;
      const double ty = mid[1] + (y + 0.5 - kSceneSide / 2.0) / scale;
      const double sx = c * tx - s * ty, sy = s * tx + c * ty;
      if (sx < 0 || sy < 0 || sx >= limit || sy >= limit) continue;
      for (std::uint32_t z = 0; z < std::uint32_t(kSceneSide); ++z) {
        const double sz = mid[2] + (z + 0.5 - kSceneSide / 2.0) / scale;
        if (sz < 0 || sz >= limit) continue;
        if (object.contains(std::uint32_t(sx), std::uint32_t(sy), std::uint32_t(sz))) voxels.push_back({x, y, z});
      }
    }
  return build_from_voxels(voxels, kSceneDepth);
}

std::vector<SegmentedClassification> classify_segmented(const Classifier& classifier, std::span<const Tree* const> scenes,
                                                        const SegmentOptions& options, int votes) {
  if (votes < 1) throw InvalidArgument("votes must be at least 1, got " + std::to_string(votes));
  std::vector<SegmentedClassification> results(scenes.size());
  std::vector<Tree> normal;
  std::vector<std::size_t> owner;
  for (std::size_t i = 0; i < scenes.size(); ++i) {
    results[i].segmentation = segment_object(*scenes[i], options);
    if (!results[i].segmentation.found()) continue;
    normal.push_back(normalise_object(results[i].segmentation.object, results[i].segmentation.footprint_angle));
    owner.push_back(i);
  }
  if (normal.empty()) return results;
  std::vector<const Tree*> inputs;
  for (const auto& t : normal) inputs.push_back(&t);
  const auto each = classifier.classify_votes(inputs, votes);
  for (std::size_t j = 0; j < normal.size(); ++j) {
    auto& r = results[owner[j]];
    const auto* first = &each[j * std::size_t(votes)];
    if (options.average_orientations) {
      for (std::size_t c = 0; c < std::size_t(kClassCount); ++c) {
        double sum = 0;
        for (int k = 0; k < votes; ++k) sum += first[k][c];
        r.probabilities[c] = float(sum / votes);
      }
      continue;
    }
    float best = -1;
    for (int k = 0; k < votes; ++k) {
      const float top = *std::max_element(first[k].begin(), first[k].end());
      if (top > best) {
        best = top;
        r.probabilities = first[k];
        r.vote = k;
      }
    }
  }
  return results;
}

}  // namespace vola::learn
