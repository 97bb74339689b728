#include "elevation_grid.hpp"

#include <algorithm>
#include <functional>

#include "vola/parallel.hpp"

namespace vola::filters::detail {

namespace {

constexpr std::size_t kBandRows = 64;

// Min (or max) over the disk, band by band: for each half-width w = 0..r, R_w(x) is the
// extreme of the input row over [x - w, x + w] (built from R_{w-1} with two more cells),
// and every disk row dy whose half-width is w contributes R_w of row y + dy.
template <class Better>
void disk_filter(const ElevationGrid& in, ElevationGrid& out, int radius, Better better, float worst) {
  out = ElevationGrid(in.cols, in.rows, in.x0, in.y0, in.cell);
  const std::size_t cols = in.cols, rows = in.rows;
  const auto r = static_cast<std::ptrdiff_t>(radius);
  std::vector<std::ptrdiff_t> half(static_cast<std::size_t>(2 * r + 1));
  for (std::ptrdiff_t dy = -r; dy <= r; ++dy)
    half[static_cast<std::size_t>(dy + r)] = static_cast<std::ptrdiff_t>(std::floor(std::sqrt(static_cast<double>(r * r - dy * dy)) + 1e-9));
  const std::size_t bands = (rows + kBandRows - 1) / kBandRows;
  parallel_for(bands, [&](std::size_t first, std::size_t last) {
    std::vector<float> run;
    for (std::size_t band = first; band < last; ++band) {
      const auto y0 = static_cast<std::ptrdiff_t>(band * kBandRows);
      const auto y1 = std::min<std::ptrdiff_t>(y0 + static_cast<std::ptrdiff_t>(kBandRows), static_cast<std::ptrdiff_t>(rows));
      const std::ptrdiff_t ya = std::max<std::ptrdiff_t>(0, y0 - r);
      const std::ptrdiff_t yb = std::min<std::ptrdiff_t>(static_cast<std::ptrdiff_t>(rows), y1 + r);
      run.assign(in.z.begin() + ya * static_cast<std::ptrdiff_t>(cols), in.z.begin() + yb * static_cast<std::ptrdiff_t>(cols));
      std::fill(out.z.begin() + y0 * static_cast<std::ptrdiff_t>(cols), out.z.begin() + y1 * static_cast<std::ptrdiff_t>(cols), worst);
      for (std::ptrdiff_t w = 0; w <= r; ++w) {
        if (w > 0) {
          const auto uw = static_cast<std::size_t>(w);
          for (std::ptrdiff_t y = ya; y < yb; ++y) {
            const float* src = in.z.data() + static_cast<std::size_t>(y) * cols;
            float* dst = run.data() + static_cast<std::size_t>(y - ya) * cols;
            for (std::size_t x = 0; x < cols; ++x) {
              float v = dst[x];
              if (x >= uw) v = better(src[x - uw], v) ? src[x - uw] : v;
              if (x + uw < cols) v = better(src[x + uw], v) ? src[x + uw] : v;
              dst[x] = v;
            }
          }
        }
        for (std::ptrdiff_t dy = -r; dy <= r; ++dy) {
          if (half[static_cast<std::size_t>(dy + r)] != w) continue;
          for (std::ptrdiff_t y = y0; y < y1; ++y) {
            if (y + dy < ya || y + dy >= yb) continue;
            const float* src = run.data() + static_cast<std::size_t>(y + dy - ya) * cols;
            float* dst = out.z.data() + static_cast<std::size_t>(y) * cols;
            for (std::size_t x = 0; x < cols; ++x) dst[x] = better(src[x], dst[x]) ? src[x] : dst[x];
          }
        }
      }
    }
  });
}

}  // namespace

void erode_disk(const ElevationGrid& in, ElevationGrid& out, int radius) {
  disk_filter(in, out, radius, std::less<float>(), std::numeric_limits<float>::infinity());
}

void dilate_disk(const ElevationGrid& in, ElevationGrid& out, int radius) {
  disk_filter(in, out, radius, std::greater<float>(), -std::numeric_limits<float>::infinity());
}

void open_disk(const ElevationGrid& in, ElevationGrid& out, int radius) {
  ElevationGrid eroded;
  erode_disk(in, eroded, radius);
  dilate_disk(eroded, out, radius);
}

namespace {

// One pyramid level: weighted sums of values and their weights.
struct Level {
  std::size_t cols = 0, rows = 0;
  std::vector<double> value, weight;  // value = weighted mean where weight > 0
};

double bilinear(const Level& level, double u, double v) {
  const double cu = std::clamp(u, 0.0, static_cast<double>(level.cols - 1));
  const double cv = std::clamp(v, 0.0, static_cast<double>(level.rows - 1));
  const auto i0 = static_cast<std::size_t>(cu), j0 = static_cast<std::size_t>(cv);
  const std::size_t i1 = std::min(i0 + 1, level.cols - 1), j1 = std::min(j0 + 1, level.rows - 1);
  const double fu = cu - static_cast<double>(i0), fv = cv - static_cast<double>(j0);
  const auto at = [&](std::size_t i, std::size_t j) { return level.value[j * level.cols + i]; };
  return (1 - fv) * ((1 - fu) * at(i0, j0) + fu * at(i1, j0)) + fv * ((1 - fu) * at(i0, j1) + fu * at(i1, j1));
}

}  // namespace

void inpaint(ElevationGrid& grid) {
  std::vector<Level> levels(1);
  Level& base = levels[0];  // valid until the first push below
  base.cols = grid.cols;
  base.rows = grid.rows;
  base.value.resize(grid.cells());
  base.weight.resize(grid.cells());
  std::size_t known = 0;
  for (std::size_t i = 0; i < grid.cells(); ++i) {
    const bool filled = !std::isnan(grid.z[i]);
    base.value[i] = filled ? grid.z[i] : 0.0;
    base.weight[i] = filled ? 1.0 : 0.0;
    known += filled;
  }
  if (known == 0 || known == grid.cells()) return;
  // Push: halve until one cell, each cell the weighted mean of its (up to) 2x2 children.
  while (levels.back().cols > 1 || levels.back().rows > 1) {
    const Level& fine = levels.back();
    Level coarse;
    coarse.cols = (fine.cols + 1) / 2;
    coarse.rows = (fine.rows + 1) / 2;
    coarse.value.assign(coarse.cols * coarse.rows, 0.0);
    coarse.weight.assign(coarse.cols * coarse.rows, 0.0);
    for (std::size_t j = 0; j < fine.rows; ++j)
      for (std::size_t i = 0; i < fine.cols; ++i) {
        const std::size_t f = j * fine.cols + i, c = (j / 2) * coarse.cols + i / 2;
        coarse.value[c] += fine.value[f] * fine.weight[f];
        coarse.weight[c] += fine.weight[f];
      }
    for (std::size_t c = 0; c < coarse.value.size(); ++c)
      if (coarse.weight[c] > 0) {
        coarse.value[c] /= coarse.weight[c];
        coarse.weight[c] = std::min(1.0, coarse.weight[c]);
      }
    levels.push_back(std::move(coarse));
  }
  // Pull: from the coarsest level down, empty cells take the coarser level's bilinear value.
  for (std::size_t l = levels.size() - 1; l-- > 0;) {
    Level& fine = levels[l];
    const Level& coarse = levels[l + 1];
    for (std::size_t j = 0; j < fine.rows; ++j)
      for (std::size_t i = 0; i < fine.cols; ++i) {
        const std::size_t f = j * fine.cols + i;
        if (fine.weight[f] > 0) continue;
        fine.value[f] = bilinear(coarse, (static_cast<double>(i) + 0.5) / 2 - 0.5, (static_cast<double>(j) + 0.5) / 2 - 0.5);
      }
  }
  Level& finest = levels[0];  // the pushes moved the vector's storage
  // Laplace smoothing of the filled-in cells (Gauss-Seidel sweeps in row-major order): the
  // pyramid's blocks would otherwise show as steps, which the morphology would read as
  // relief. Rows and columns are walked directly (no list of holes, no division per
  // cell): a thinned survey over kilometres is almost all holes at 1 m cells.
  const std::size_t cols = grid.cols, rows = grid.rows;
  const auto smooth = [&](std::size_t f, std::size_t i, std::size_t j) {
    double sum = 0.0;
    int n = 0;
    if (i > 0) sum += finest.value[f - 1], ++n;
    if (i + 1 < cols) sum += finest.value[f + 1], ++n;
    if (j > 0) sum += finest.value[f - cols], ++n;
    if (j + 1 < rows) sum += finest.value[f + cols], ++n;
    finest.value[f] = sum / n;
  };
  constexpr int kSweeps = 24;
  for (int sweep = 0; sweep < kSweeps; ++sweep)
    for (std::size_t j = 0; j < rows; ++j) {
      const std::size_t row = j * cols;
      if (j == 0 || j + 1 == rows || cols < 3) {
        for (std::size_t i = 0; i < cols; ++i)
          if (finest.weight[row + i] == 0) smooth(row + i, i, j);
        continue;
      }
      if (finest.weight[row] == 0) smooth(row, 0, j);
      for (std::size_t f = row + 1; f < row + cols - 1; ++f)  // inside: four neighbours, in the same order
        if (finest.weight[f] == 0)
          finest.value[f] = (((finest.value[f - 1] + finest.value[f + 1]) + finest.value[f - cols]) + finest.value[f + cols]) / 4;
      if (finest.weight[row + cols - 1] == 0) smooth(row + cols - 1, cols - 1, j);
    }
  for (std::size_t f = 0; f < grid.cells(); ++f)
    if (finest.weight[f] == 0) grid.z[f] = static_cast<float>(finest.value[f]);
}

double interpolate(const ElevationGrid& grid, double x, double y) {
  const double u = std::clamp((x - grid.x0) / grid.cell - 0.5, 0.0, static_cast<double>(grid.cols - 1));
  const double v = std::clamp((y - grid.y0) / grid.cell - 0.5, 0.0, static_cast<double>(grid.rows - 1));
  const auto i0 = static_cast<std::size_t>(u), j0 = static_cast<std::size_t>(v);
  const std::size_t i1 = std::min(i0 + 1, grid.cols - 1), j1 = std::min(j0 + 1, grid.rows - 1);
  const double fu = u - static_cast<double>(i0), fv = v - static_cast<double>(j0);
  return (1 - fv) * ((1 - fu) * grid.at(i0, j0) + fu * grid.at(i1, j0)) +
         fv * ((1 - fu) * grid.at(i0, j1) + fu * grid.at(i1, j1));
}

}  // namespace vola::filters::detail
