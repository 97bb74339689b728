#include "morphology_walk.hpp"

#include <functional>

#include <algorithm>
#include <array>
#include <bit>
#include <cmath>
#include <cstddef>
#include <span>
#include <string>
#include <utility>
#include <vector>

#include "vola/error.hpp"

namespace vola::analysis::detail {

namespace {

// Bits of a brick word (bit x + 4y + 16z) whose coordinate along `axis` (0 = x, 1 = y,
// 2 = z) is below n (0..4).
constexpr std::uint64_t coordinate_below(int axis, int n) noexcept {
  std::uint64_t m = 0;
  for (unsigned b = 0; b < 64; ++b) {
    const unsigned c = axis == 0 ? (b & 3u) : axis == 1 ? ((b >> 2) & 3u) : (b >> 4);
    if (static_cast<int>(c) < n) m |= std::uint64_t{1} << b;
  }
  return m;
}
template <int Axis>
constexpr std::array<std::uint64_t, 5> kBelowAlong = {coordinate_below(Axis, 0), coordinate_below(Axis, 1),
                                                      coordinate_below(Axis, 2), coordinate_below(Axis, 3),
                                                      coordinate_below(Axis, 4)};
constexpr std::array<std::array<std::uint64_t, 5>, 3> kBelow = {kBelowAlong<0>, kBelowAlong<1>, kBelowAlong<2>};
constexpr unsigned kStride[3] = {1, 4, 16};

// floor(e / 4) and e - 4 * floor(e / 4).
inline std::pair<int, int> split(int e) noexcept {
  const int q = e >= 0 ? e / 4 : -((-e + 3) / 4);
  return {q, e - 4 * q};
}

// A row of bricks along `axis`, seen s voxels (1..3) further on: voxel u of the result
// is voxel u + s of the row, found in `lo` (the brick itself) or `hi` (the next one).
inline std::uint64_t pick(std::uint64_t lo, std::uint64_t hi, int axis, int s) noexcept {
  const unsigned t = kStride[axis];
  const std::uint64_t stay = kBelow[axis][4 - s];
  return ((lo >> (static_cast<unsigned>(s) * t)) & stay) | ((hi << (static_cast<unsigned>(4 - s) * t)) & ~stay);
}

// The brick at a[i] of an array whose bricks follow each other `step` apart along
// `axis`, seen e voxels further on (e may be negative): voxel u of the result is voxel
// u + e of the array. Reads a[i + floor(e/4) step] and, unless e is a multiple of 4, the
// brick after it.
inline std::uint64_t seen_at(const std::uint64_t* a, std::ptrdiff_t i, std::ptrdiff_t step, int axis, int e) noexcept {
  const auto [q, s] = split(e);
  const std::uint64_t lo = a[i + q * step];
  return s == 0 ? lo : pick(lo, a[i + (q + 1) * step], axis, s);
}

// Dilation (OR over the element's offsets) or erosion (AND) of the c^3 bricks at the
// centre of a dense n^3 array of brick words, n = c + 2 halo (index x + n (y + n z)),
// by the element of radius r <= 4 halo; results in index order x + c (y + c z). The
// array holds zeros where there are no voxels, inside the grid or not, which is what
// both operations need at the grid's edge: dilation never emits bricks outside it, and
// erosion treats cells outside as empty. Both elements are symmetric, so a result voxel
// looks at the input voxels at the element's offsets from it.
class BrickKernel {
 public:
  BrickKernel(Operation operation, Element element, int radius, int halo, int centre)
      : dilate_(operation == Operation::dilate),
        cube_(element == Element::cube),
        r_(radius),
        h_(halo),
        c_(centre),
        n_(centre + 2 * halo) {
    const auto n = static_cast<std::size_t>(n_), c = static_cast<std::size_t>(c_);
    along_x_.assign(c * n * n, 0);
    if (cube_) along_y_.assign(c * c * n, 0);
    if (cube_) return;
    // The sphere as runs along x: for each (dy, dz) of the disc dy^2 + dz^2 <= r^2, the
    // run of half width floor(sqrt(r^2 - dy^2 - dz^2)); grouped by half width, so that
    // the x-dilation by each half width is computed once.
    disc_.resize(static_cast<std::size_t>(radius) + 1);
    const long r2 = static_cast<long>(radius) * radius;
    for (int dz = -radius; dz <= radius; ++dz)
      for (int dy = -radius; dy <= radius; ++dy) {
        const long rest = r2 - static_cast<long>(dy) * dy - static_cast<long>(dz) * dz;
        if (rest < 0) continue;
        long w = static_cast<long>(std::sqrt(static_cast<double>(rest)));
        while (w * w > rest) --w;  // exact integer square root
        while ((w + 1) * (w + 1) <= rest) ++w;
        disc_[static_cast<std::size_t>(w)].emplace_back(dy, dz);
      }
  }

  int side() const noexcept { return n_; }

  void run(const std::uint64_t* in, std::uint64_t* out) {
    if (cube_) {
      if (dilate_)
        cube<true>(in, out);
      else
        cube<false>(in, out);
    } else {
      if (dilate_)
        sphere<true>(in, out);
      else
        sphere<false>(in, out);
    }
  }

 private:
  template <bool Dilate>
  static void combine(std::uint64_t& acc, std::uint64_t v) noexcept {
    if constexpr (Dilate)
      acc |= v;
    else
      acc &= v;
  }

  // The rows along x of the array, dilated or eroded by `reach` voxels, into along_x_
  // (c x n x n: the centre columns of every row); with `grow`, ORed / ANDed into what
  // along_x_ holds (the same rows by reach - 1).
  template <bool Dilate>
  void rows_along_x(const std::uint64_t* in, int reach, bool grow) {
    const int n = n_, c = c_, h = h_;
    std::uint64_t* ax = along_x_.data();
    for (int yz = 0; yz < n * n; ++yz) {
      const std::uint64_t* row = in + static_cast<std::ptrdiff_t>(yz) * n;
      std::uint64_t* dst = ax + static_cast<std::ptrdiff_t>(yz) * c;
      for (int x = 0; x < c; ++x) {
        const int i = x + h;
        if constexpr (Dilate) {
          std::uint64_t any = 0;  // no voxel within reach: nothing to do
          for (int j = i - h; j <= i + h; ++j) any |= row[j];
          if (!any) {
            if (!grow) dst[x] = 0;
            continue;
          }
        } else {
          if (!row[i]) {  // erosion stays inside the voxels
            dst[x] = 0;
            continue;
          }
        }
        std::uint64_t acc = grow ? dst[x] : row[i];
        for (int e = grow ? reach : 1; e <= reach; ++e) {
          combine<Dilate>(acc, seen_at(row, i, 1, 0, e));
          combine<Dilate>(acc, seen_at(row, i, 1, 0, -e));
        }
        dst[x] = acc;
      }
    }
  }

  // Separable: x, then y, then z, each by r.
  template <bool Dilate>
  void cube(const std::uint64_t* in, std::uint64_t* out) {
    const int n = n_, c = c_, h = h_, r = r_;
    rows_along_x<Dilate>(in, r, false);
    const std::uint64_t* ax = along_x_.data();
    std::uint64_t* ay = along_y_.data();
    for (int z = 0; z < n; ++z)
      for (int y = 0; y < c; ++y)
        for (int x = 0; x < c; ++x) {
          const std::ptrdiff_t i = x + c * ((y + h) + n * z);
          std::uint64_t acc = ax[i];
          if (!Dilate && !acc) {
            ay[x + c * (y + c * z)] = 0;
            continue;
          }
          for (int e = 1; e <= r; ++e) {
            combine<Dilate>(acc, seen_at(ax, i, c, 1, e));
            combine<Dilate>(acc, seen_at(ax, i, c, 1, -e));
          }
          ay[x + c * (y + c * z)] = acc;
        }
    for (int z = 0; z < c; ++z)
      for (int y = 0; y < c; ++y)
        for (int x = 0; x < c; ++x) {
          const std::ptrdiff_t i = x + c * (y + c * (z + h));
          std::uint64_t acc = ay[i];
          if (Dilate || acc)
            for (int e = 1; e <= r; ++e) {
              combine<Dilate>(acc, seen_at(ay, i, c * c, 2, e));
              combine<Dilate>(acc, seen_at(ay, i, c * c, 2, -e));
            }
          out[x + c * (y + c * z)] = acc;
        }
  }

  // The union (intersection) over the disc's (dy, dz) of the x-runs by their half width,
  // seen at (dy, dz).
  template <bool Dilate>
  void sphere(const std::uint64_t* in, std::uint64_t* out) {
    const int n = n_, c = c_, h = h_;
    std::fill(out, out + c * c * c, Dilate ? std::uint64_t{0} : ~std::uint64_t{0});
    const std::uint64_t* ax = along_x_.data();
    for (std::size_t w = 0; w < disc_.size(); ++w) {
      rows_along_x<Dilate>(in, static_cast<int>(w), w > 0);
      for (const auto& [dy, dz] : disc_[w]) {
        const auto [qz, sz] = split(dz);
        for (int z = 0; z < c; ++z)
          for (int y = 0; y < c; ++y)
            for (int x = 0; x < c; ++x) {
              const std::ptrdiff_t i = x + c * ((y + h) + n * (z + h + qz));
              std::uint64_t v = seen_at(ax, i, c, 1, dy);
              if (sz) v = pick(v, seen_at(ax, i + static_cast<std::ptrdiff_t>(c) * n, c, 1, dy), 2, sz);
              combine<Dilate>(out[x + c * (y + c * z)], v);
            }
      }
    }
  }

  bool dilate_, cube_;
  int r_, h_, c_, n_;
  std::vector<std::uint64_t> along_x_, along_y_;
  std::vector<std::vector<std::pair<int, int>>> disc_;  // by half width along x
};

int ceil_quarter(int v) { return (v + 3) / 4; }

// One pass over the tree for an element whose radius fits the halo of every level.
class Walk {
 public:
  // `report(done, total)`, when given, hears every kReportEvery blocks how many of the
  // input's blocks above the leaves were walked.
  Walk(const Tree& tree, Operation operation, int radius, Element element,
       std::function<void(std::uint64_t, std::uint64_t)> report = {})
      : report_(std::move(report)),
        depth_(tree.depth()),
        dilate_(operation == Operation::dilate),
        half_(halves(tree.depth(), radius)),
        leaf_(operation, element, radius, half_[static_cast<std::size_t>(depth_ - 1)], depth_ == 1 ? 1 : 4) {
    for (int l = 0; l < depth_; ++l) words_[l] = tree.occupancy(l);
    // The index of each block's first child, for every level above the leaves: the
    // children of word i are words first_child[i] .. of the next level.
    for (int l = 0; l + 1 < depth_; ++l) {
      auto& first = first_child_[l];
      first.resize(words_[l].size());
      std::uint64_t sum = 0;
      for (std::size_t i = 0; i < first.size(); ++i) {
        first[i] = sum;
        sum += static_cast<std::uint64_t>(std::popcount(words_[l][i]));
      }
    }
    for (int l = 0; l + 1 < depth_; ++l) {
      Window& w = window_[l];
      w.half = half_[static_cast<std::size_t>(l)];
      w.side = 2 * w.half + 1;
      const auto cells = static_cast<std::size_t>(w.side) * w.side * w.side;
      w.word.assign(cells, 0);
      w.child.assign(cells, 0);
      // Dilation visits the children of a block that have an input block within their
      // own window's reach; a cube of that many cells over the window's words says which.
      if (dilate_ && l + 2 < depth_)
        reach_.emplace_back(Operation::dilate, Element::cube, half_[static_cast<std::size_t>(l) + 1], w.half, 1);
    }
    bricks_.assign(static_cast<std::size_t>(leaf_.side()) * leaf_.side() * leaf_.side(), 0);
    if (depth_ >= 2) {
      // Which bricks of each block of the window around a level depth-2 block fall into
      // the brick array: its 4^3 children and a halo of half_[depth - 1] bricks.
      const Window& w = window_[depth_ - 2];
      const int h = half_[static_cast<std::size_t>(depth_ - 1)], n = leaf_.side();
      auto along = [&](int axis, int p) {
        const int o = 4 * (p - w.half) + h;
        const int lo = std::max(0, -o), hi = std::min(3, n - 1 - o);
        std::uint64_t m = 0;
        for (int v = lo; v <= hi; ++v) m |= coordinate_below(axis, v + 1) & ~coordinate_below(axis, v);
        return m;
      };
      for (int pz = 0; pz < w.side; ++pz)
        for (int py = 0; py < w.side; ++py)
          for (int px = 0; px < w.side; ++px) leaf_mask_.push_back(along(0, px) & along(1, py) & along(2, pz));
    }
  }

  Tree run() {
    if (depth_ == 1) {
      const int n = leaf_.side();
      bricks_[static_cast<std::size_t>(n * n * n / 2)] = words_[0][0];  // the centre of an odd cube
      std::uint64_t word = 0;
      leaf_.run(bricks_.data(), &word);
      return Tree::from_levels(1, false, {word});
    }
    Window& root = window_[0];
    const std::size_t centre = root.word.size() / 2;
    root.word[centre] = words_[0][0];
    root.child[centre] = 0;
    if (visit(0) == 0) out_[0].push_back(0);  // an empty result: the zero root word
    if (report_) report_(walked_, words_[depth_ - 2].size());  // every input block: the whole

    // The levels one after the other, in the leaf level's vector (the largest).
    std::size_t total = 0;
    for (int l = 0; l < depth_; ++l) total += out_[l].size();
    std::vector<std::uint64_t> words = std::move(out_[depth_ - 1]);
    const std::size_t leaves = words.size();
    words.resize(total);
    std::copy_backward(words.begin(), words.begin() + static_cast<std::ptrdiff_t>(leaves), words.end());
    auto at = words.begin();
    for (int l = 0; l + 1 < depth_; ++l) {
      at = std::copy(out_[l].begin(), out_[l].end(), at);
      out_[l] = {};
    }
    return Tree::from_levels(depth_, false, std::move(words));
  }

 private:
  struct Window {
    int half = 0, side = 0;
    // Per block of the input's level around the visited one (index x + side (y + side
    // z)): its occupancy word (0 where there is none) and the index of its first child.
    std::vector<std::uint64_t> word, child;
  };

  // The window half width (in blocks) of every level: ceil(r / 4) bricks around a
  // brick, and at each level above, enough blocks to hold the windows of all children.
  static std::array<int, kMaxDepth> halves(int depth, int radius) {
    std::array<int, kMaxDepth> half{};
    half[static_cast<std::size_t>(depth - 1)] = ceil_quarter(radius);
    for (int l = depth - 2; l >= 0; --l)
      half[static_cast<std::size_t>(l)] = ceil_quarter(half[static_cast<std::size_t>(l) + 1]);
    return half;
  }

  // The result's block at the centre of window_[level] (level <= depth - 2): appends its
  // descendants and then its word (when not zero) to the result's levels, returns the word.
  std::uint64_t visit(int level) {
    std::uint64_t word = 0;
    if (level == depth_ - 2) {
      word = leaves();
      const Window& w = window_[level];
      if (report_ && w.word[w.word.size() / 2] != 0 && ++walked_ % kReportEvery == 0)
        report_(walked_, words_[level].size());
    } else {
      const Window& w = window_[level];
      std::uint64_t todo = w.word[w.word.size() / 2];  // erosion keeps only input voxels
      if (dilate_) {
        todo = 0;
        reach_[static_cast<std::size_t>(level)].run(w.word.data(), &todo);
      }
      while (todo) {
        const auto cell = static_cast<unsigned>(std::countr_zero(todo));
        todo &= todo - 1;
        gather(level, cell);
        if (visit(level + 1)) word |= std::uint64_t{1} << cell;
      }
    }
    if (word) out_[level].push_back(word);
    return word;
  }

  // window_[level + 1] around child `cell` of the block at the centre of window_[level].
  void gather(int level, unsigned cell) {
    const Window& w = window_[level];
    Window& cw = window_[level + 1];
    const std::uint64_t* words = words_[level + 1].data();
    const std::uint64_t* first = first_child_[level + 1].data();
    const int m = w.side, h = cw.half;
    const int cx = static_cast<int>(cell & 3u), cy = static_cast<int>((cell >> 2) & 3u),
              cz = static_cast<int>(cell >> 4);
    std::size_t j = 0;
    for (int oz = -h; oz <= h; ++oz) {
      const int gz = 4 * w.half + cz + oz;
      for (int oy = -h; oy <= h; ++oy) {
        const int gy = 4 * w.half + cy + oy;
        for (int ox = -h; ox <= h; ++ox, ++j) {
          const int gx = 4 * w.half + cx + ox;
          const std::size_t p = static_cast<std::size_t>((gx >> 2) + m * ((gy >> 2) + m * (gz >> 2)));
          const unsigned bit = static_cast<unsigned>((gx & 3) + 4 * (gy & 3) + 16 * (gz & 3));
          const std::uint64_t pw = w.word[p];
          if ((pw >> bit) & 1u) {
            const std::uint64_t i =
                w.child[p] + static_cast<std::uint64_t>(std::popcount(pw & ((std::uint64_t{1} << bit) - 1)));
            cw.word[j] = words[i];
            cw.child[j] = first[i];
          } else {
            cw.word[j] = 0;
          }
        }
      }
    }
  }

  // The 64 result bricks of the level depth-2 block at the centre of its window.
  std::uint64_t leaves() {
    const Window& w = window_[depth_ - 2];
    const int h = half_[static_cast<std::size_t>(depth_ - 1)], n = leaf_.side();
    const std::uint64_t* leaf_words = words_[depth_ - 1].data();
    std::fill(bricks_.begin(), bricks_.end(), 0);
    bool any = false;
    std::size_t p = 0;
    for (int pz = 0; pz < w.side; ++pz)
      for (int py = 0; py < w.side; ++py)
        for (int px = 0; px < w.side; ++px, ++p) {
          const std::uint64_t full = w.word[p];
          std::uint64_t wanted = full & leaf_mask_[p];
          if (!wanted) continue;
          any = true;
          const int ox = 4 * (px - w.half) + h, oy = 4 * (py - w.half) + h, oz = 4 * (pz - w.half) + h;
          while (wanted) {
            const auto b = static_cast<unsigned>(std::countr_zero(wanted));
            wanted &= wanted - 1;
            const std::uint64_t i =
                w.child[p] + static_cast<std::uint64_t>(std::popcount(full & ((std::uint64_t{1} << b) - 1)));
            const int x = ox + static_cast<int>(b & 3u), y = oy + static_cast<int>((b >> 2) & 3u),
                      z = oz + static_cast<int>(b >> 4);
            bricks_[static_cast<std::size_t>(x + n * (y + n * z))] = leaf_words[i];
          }
        }
    if (!any) return 0;
    leaf_.run(bricks_.data(), result_.data());
    std::uint64_t word = 0;
    auto& out = out_[depth_ - 1];
    for (unsigned b = 0; b < 64; ++b)
      if (result_[b]) {
        out.push_back(result_[b]);
        word |= std::uint64_t{1} << b;
      }
    return word;
  }

  // Blocks of level depth - 2 between two reports (each computes 64 bricks: a report is
  // a small cost beside them).
  static constexpr std::uint64_t kReportEvery = 64;

  std::function<void(std::uint64_t, std::uint64_t)> report_;
  std::uint64_t walked_ = 0;  // input blocks of level depth - 2 visited
  int depth_;
  bool dilate_;
  std::array<int, kMaxDepth> half_;
  std::array<std::span<const std::uint64_t>, kMaxDepth> words_{};
  std::array<std::vector<std::uint64_t>, kMaxDepth> first_child_{};
  std::array<Window, kMaxDepth> window_{};
  std::vector<BrickKernel> reach_;  // dilation, levels 0 .. depth - 3
  BrickKernel leaf_;
  std::vector<std::uint64_t> bricks_;     // leaf_.side()^3 leaf words around a level depth-2 block
  std::vector<std::uint64_t> leaf_mask_;  // per block of window_[depth - 2]: its bricks in bricks_
  std::array<std::uint64_t, 64> result_{};
  std::array<std::vector<std::uint64_t>, kMaxDepth> out_{};  // the result's levels
};

}  // namespace

Tree morph(const Tree& tree, Operation operation, int radius, Element element, const MorphProgress& progress) {
  if (radius == 0) {  // the voxels themselves, without payload
    std::vector<std::uint64_t> words;
    for (int l = 0; l < tree.depth(); ++l) {
      const auto level = tree.occupancy(l);
      words.insert(words.end(), level.begin(), level.end());
    }
    return Tree::from_levels(tree.depth(), false, std::move(words));
  }
  // A cube goes in passes of radius 4 at most (below); each pass reports its share of a
  // million.
  const int passes = element == Element::sphere ? 1 : (radius + 3) / 4;
  constexpr std::uint64_t kWhole = 1'000'000;
  const auto pass_report = [&](int pass) -> std::function<void(std::uint64_t, std::uint64_t)> {
    if (!progress) return {};
    return [&progress, pass, passes](std::uint64_t done, std::uint64_t total) {
      const std::uint64_t share = total ? kWhole * std::min(done, total) / total : kWhole;
      progress((static_cast<std::uint64_t>(pass) * kWhole + share) / static_cast<std::uint64_t>(passes), kWhole);
    };
  };
  if (element == Element::sphere) return Walk(tree, operation, radius, element, pass_report(0)).run();
  // A cube of radius a + b is a cube of radius a grown by one of radius b, and both
  // operations compose that way (the grid is a box: a voxel within a + b of a source
  // inside it is within b of a cell within a of the source that is inside it too), so
  // a cube goes in steps of at most 4, one brick of halo each.
  Tree current = Walk(tree, operation, std::min(radius, 4), element, pass_report(0)).run();
  int pass = 1;
  for (int done = std::min(radius, 4); done < radius && !current.empty(); done += 4, ++pass)  // empty stays empty
    current = Walk(current, operation, std::min(radius - done, 4), element, pass_report(pass)).run();
  if (pass < passes && progress) progress(kWhole, kWhole);  // emptied early: the passes left have nothing to do
  return current;
}

void check_radius(const Tree& tree, int radius) {
  if (radius < 0 || static_cast<std::int64_t>(radius) >= std::int64_t{tree.side()})
    throw InvalidArgument("radius " + std::to_string(radius) + " outside 0.." + std::to_string(tree.side() - 1) +
                          " for a depth-" + std::to_string(tree.depth()) + " grid");
}

}  // namespace vola::analysis::detail
