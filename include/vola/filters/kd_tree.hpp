// A static k-d tree over points in 2 or 3 dimensions, for the k nearest neighbours of
// any query (outlier statistics, height above ground, nearest ground). Built once in
// O(n log n) by median splits of an index array; a query visits the near side first and
// prunes boxes farther than the current k-th distance, O(log n + k) on spread points.
// The points are not copied: they must outlive the tree.
#pragma once

#include <algorithm>
#include <array>
#include <cstddef>
#include <cstdint>
#include <limits>
#include <numeric>
#include <queue>
#include <span>
#include <utility>
#include <vector>

namespace vola::filters {

template <int Dim>
class KdTree {
 public:
  // Point i is coords[i * stride .. i * stride + Dim); `ids` picks which points are in the
  // tree (all when empty). Neighbours are reported by point index.
  KdTree(std::span<const double> coords, std::size_t stride, std::vector<std::uint32_t> ids = {})
      : coords_(coords), stride_(stride), index_(std::move(ids)) {
    if (index_.empty()) {
      index_.resize(coords.size() / stride);
      std::iota(index_.begin(), index_.end(), 0u);
    }
    if (!index_.empty()) build(0, index_.size(), 0);
  }

  std::size_t size() const noexcept { return index_.size(); }

  // Up to k nearest points to `q` by squared distance, nearest first: (squared distance,
  // index). Ties are broken by index, so results do not depend on the build's order.
  std::vector<std::pair<double, std::uint32_t>> nearest(const std::array<double, Dim>& q, std::size_t k) const {
    std::vector<std::pair<double, std::uint32_t>> heap;  // max-heap of the best k
    if (k == 0 || index_.empty()) return heap;
    heap.reserve(k + 1);
    search(0, index_.size(), 0, q, k, heap);
    std::sort_heap(heap.begin(), heap.end());
    return heap;
  }

 private:
  double coordinate(std::uint32_t i, int axis) const { return coords_[std::size_t{i} * stride_ + axis]; }

  // Splits [begin, end) at its median along `axis` (the node's point), recursively.
  void build(std::size_t begin, std::size_t end, int axis) {
    if (end - begin <= 1) return;
    const std::size_t mid = begin + (end - begin) / 2;
    std::nth_element(index_.begin() + static_cast<std::ptrdiff_t>(begin), index_.begin() + static_cast<std::ptrdiff_t>(mid),
                     index_.begin() + static_cast<std::ptrdiff_t>(end), [&](std::uint32_t a, std::uint32_t b) {
                       return coordinate(a, axis) < coordinate(b, axis);
                     });
    build(begin, mid, (axis + 1) % Dim);
    build(mid + 1, end, (axis + 1) % Dim);
  }

  void offer(double d2, std::uint32_t i, std::size_t k, std::vector<std::pair<double, std::uint32_t>>& heap) const {
    const std::pair<double, std::uint32_t> item{d2, i};
    if (heap.size() < k) {
      heap.push_back(item);
      std::push_heap(heap.begin(), heap.end());
    } else if (item < heap.front()) {
      std::pop_heap(heap.begin(), heap.end());
      heap.back() = item;
      std::push_heap(heap.begin(), heap.end());
    }
  }

  void search(std::size_t begin, std::size_t end, int axis, const std::array<double, Dim>& q, std::size_t k,
              std::vector<std::pair<double, std::uint32_t>>& heap) const {
    if (begin >= end) return;
    const std::size_t mid = begin + (end - begin) / 2;
    const std::uint32_t p = index_[mid];
    double d2 = 0.0;
    for (int a = 0; a < Dim; ++a) {
      const double d = coordinate(p, a) - q[static_cast<std::size_t>(a)];
      d2 += d * d;
    }
    offer(d2, p, k, heap);
    if (end - begin == 1) return;
    const double delta = q[static_cast<std::size_t>(axis)] - coordinate(p, axis);
    const int next = (axis + 1) % Dim;
    if (delta < 0) search(begin, mid, next, q, k, heap);
    else search(mid + 1, end, next, q, k, heap);
    // The far side can hold a nearer point only within the splitting plane's distance
    // (<= so that equal distances reach the tie-break by index).
    if (heap.size() < k || delta * delta <= heap.front().first) {
      if (delta < 0) search(mid + 1, end, next, q, k, heap);
      else search(begin, mid, next, q, k, heap);
    }
  }

  std::span<const double> coords_;
  std::size_t stride_;
  std::vector<std::uint32_t> index_;
};

}  // namespace vola::filters
