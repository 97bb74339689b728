#include "vola/learn/dataset.hpp"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <functional>
#include <cctype>
#include <numbers>
#include <tuple>

#include "vola/builder.hpp"
#include "vola/error.hpp"

namespace vola::learn {

namespace {

void check_grid(std::span<const std::uint8_t> grid, int side) {
  if (side <= 0 || kSceneSide % side != 0)
    throw InvalidArgument("object grid side " + std::to_string(side) + " does not divide " + std::to_string(kSceneSide));
  if (grid.size() != std::size_t(side) * side * side)
    throw InvalidArgument("object grid has " + std::to_string(grid.size()) + " cells, expected " +
                          std::to_string(side) + "^3");
}

// Room furniture sizes (cells of the 64^3 room).
constexpr int kClutterMin = 3, kClutterMax = 10;
constexpr int kClutterBoxesMin = 2, kClutterBoxesMax = 5;
// The object at 5/4 of its grid size: a 32^3 object becomes 40 cells, whose diagonal
// (57) still fits between the walls whatever the angle.
constexpr double kRoomObjectScale = 1.25;

struct Extent {
  int min[3] = {kSceneSide, kSceneSide, kSceneSide};
  int max[3] = {-1, -1, -1};
  void add(int x, int y, int z) {
    const int v[3] = {x, y, z};
    for (int a = 0; a < 3; ++a) {
      min[a] = std::min(min[a], v[a]);
      max[a] = std::max(max[a], v[a]);
    }
  }
};

}  // namespace

std::optional<int> class_index(std::string_view name) noexcept {
  for (int i = 0; i < kClassCount; ++i)
    if (kClassNames[i] == name) return i;
  return std::nullopt;
}

Tree clean_scene(std::span<const std::uint8_t> grid, int side) {
  check_grid(grid, side);
  const std::uint32_t factor = std::uint32_t(kSceneSide / side);
  std::vector<Voxel> voxels;
  for (int x = 0; x < side; ++x)
    for (int y = 0; y < side; ++y)
      for (int z = 0; z < side; ++z) {
        if (!grid[(std::size_t(x) * side + y) * side + z]) continue;
        for (std::uint32_t dx = 0; dx < factor; ++dx)
          for (std::uint32_t dy = 0; dy < factor; ++dy)
            for (std::uint32_t dz = 0; dz < factor; ++dz)
              voxels.push_back({x * factor + dx, y * factor + dy, z * factor + dz});
      }
  return build_from_voxels(voxels, kSceneDepth);
}

Tree room_scene(std::span<const std::uint8_t> grid, int side, std::mt19937_64& random) {
  check_grid(grid, side);
  const double scale = kRoomObjectScale * kObjectSide / side;  // grid cells -> room cells
  const double angle = std::uniform_real_distribution<double>(0, 2 * std::numbers::pi)(random);
  const double c = std::cos(angle), s = std::sin(angle);
  const double half = side * scale / 2;  // the scaled object's centre
  const int reach = static_cast<int>(std::ceil(half * std::numbers::sqrt2)) + 1;
  const int height = static_cast<int>(std::ceil(side * scale));

  // Sample the turned, scaled object backwards (room cell -> grid cell): no holes.
  std::vector<std::array<int, 3>> object;
  Extent extent;
  for (int u = -reach; u < reach; ++u)
    for (int v = -reach; v < reach; ++v) {
      const double pu = u + 0.5, pv = v + 0.5;
      const double gx = (c * pu + s * pv + half) / scale, gy = (-s * pu + c * pv + half) / scale;
      if (gx < 0 || gy < 0 || gx >= side || gy >= side) continue;
      const int ix = static_cast<int>(gx), iy = static_cast<int>(gy);
      for (int w = 0; w < height; ++w) {
        const int iz = std::min(side - 1, static_cast<int>((w + 0.5) / scale));
        if (!grid[(std::size_t(ix) * side + iy) * side + iz]) continue;
        object.push_back({u, v, w});
        extent.add(u + reach, v + reach, w);
      }
    }

  std::vector<Voxel> voxels;
  const auto add = [&](int x, int y, int z) {
    voxels.push_back({std::uint32_t(x), std::uint32_t(y), std::uint32_t(z)});
  };
  // Floor at z = 0, walls at x = 0 and y = 0.
  for (int a = 0; a < kSceneSide; ++a)
    for (int b = 0; b < kSceneSide; ++b) {
      add(a, b, 0);
      if (b > 0) add(0, a, b);
      if (a > 0 && b > 0) add(a, 0, b);
    }

  // The object stands on the floor somewhere between the walls.
  int placed[3][2] = {{0, 0}, {0, 0}, {0, 0}};  // per axis: the object's room cells [min, max]
  if (!object.empty()) {
    int shift[3];
    for (int a = 0; a < 2; ++a) {
      const int size = extent.max[a] - extent.min[a] + 1;
      const int room = kSceneSide - 1 - size;  // free cells beside the wall, >= 0 by kRoomObjectScale
      const int start = 1 + std::uniform_int_distribution<int>(0, std::max(0, room))(random);
      shift[a] = start - extent.min[a];
      placed[a][0] = start;
      placed[a][1] = start + size - 1;
    }
    shift[2] = 1 - extent.min[2];
    for (const auto& p : object) {
      const int x = p[0] + reach + shift[0], y = p[1] + reach + shift[1], z = p[2] + shift[2];
      if (x > 0 && y > 0 && z > 0 && x < kSceneSide && y < kSceneSide && z < kSceneSide) add(x, y, z);
    }
  }

  // Clutter: boxes on the floor that keep a cell of space around the object.
  const int boxes = std::uniform_int_distribution<int>(kClutterBoxesMin, kClutterBoxesMax)(random);
  std::uniform_int_distribution<int> size_of(kClutterMin, kClutterMax);
  for (int b = 0, tries = 0; b < boxes && tries < 50; ++tries) {
    const int sx = size_of(random), sy = size_of(random), sz = size_of(random);
    const int x0 = std::uniform_int_distribution<int>(1, kSceneSide - sx)(random);
    const int y0 = std::uniform_int_distribution<int>(1, kSceneSide - sy)(random);
    const bool clear = object.empty() || x0 + sx < placed[0][0] - 1 || x0 > placed[0][1] + 1 ||
                       y0 + sy < placed[1][0] - 1 || y0 > placed[1][1] + 1;
    if (!clear) continue;
    for (int x = x0; x < x0 + sx; ++x)
      for (int y = y0; y < y0 + sy; ++y)
        for (int z = 1; z <= sz; ++z) add(x, y, z);
    ++b;
  }
  std::sort(voxels.begin(), voxels.end(), [](const Voxel& a, const Voxel& b) {
    return std::tie(a.x, a.y, a.z) < std::tie(b.x, b.y, b.z);
  });
  voxels.erase(std::unique(voxels.begin(), voxels.end()), voxels.end());
  return build_from_voxels(voxels, kSceneDepth);
}

namespace {

// Holds out count_of(class size) shuffled members of each class.
Split split_by_class(std::span<const int> labels, std::uint64_t seed, const std::function<std::size_t(std::size_t)>& count_of) {
  std::vector<std::vector<std::size_t>> by_class(kClassCount);
  for (std::size_t i = 0; i < labels.size(); ++i) {
    if (labels[i] < 0 || labels[i] >= kClassCount) throw InvalidArgument("label " + std::to_string(labels[i]) + " out of 0..9");
    by_class[std::size_t(labels[i])].push_back(i);
  }
  std::mt19937_64 random(seed);
  std::vector<bool> held_out(labels.size(), false);
  for (auto& members : by_class) {
    const std::size_t count = std::min(count_of(members.size()), members.size());
    std::shuffle(members.begin(), members.end(), random);
    for (std::size_t k = 0; k < count; ++k) held_out[members[k]] = true;
  }
  Split split;
  for (std::size_t i = 0; i < labels.size(); ++i) (held_out[i] ? split.validation : split.train).push_back(i);
  return split;
}

}  // namespace

Split stratified_split(std::span<const int> labels, double validation_fraction, std::uint64_t seed) {
  if (!(validation_fraction >= 0 && validation_fraction < 1))
    throw InvalidArgument("validation fraction must be in [0, 1), got " + std::to_string(validation_fraction));
  return split_by_class(labels, seed, [&](std::size_t size) {
    std::size_t count = static_cast<std::size_t>(std::llround(double(size) * validation_fraction));
    if (validation_fraction > 0 && size >= 2) count = std::max<std::size_t>(count, 1);
    return count;
  });
}

Split balanced_split(std::span<const int> labels, std::size_t per_class, std::uint64_t seed) {
  return split_by_class(labels, seed, [&](std::size_t size) { return std::min(per_class, size / 2); });
}

std::optional<int> class_from_file_name(std::string_view file_name) noexcept {
  const auto separator = [](char ch) { return ch == '_' || ch == '-' || ch == '.' || ch == ' '; };
  std::optional<int> best;
  for (int k = 0; k < kClassCount; ++k) {
    const std::string_view name = kClassNames[k];
    for (std::size_t at = file_name.find(name); at != std::string_view::npos; at = file_name.find(name, at + 1)) {
      const std::size_t end = at + name.size();
      const bool starts = at == 0 || separator(file_name[at - 1]);
      const bool ends = end == file_name.size() || separator(file_name[end]) ||
                        std::isdigit(static_cast<unsigned char>(file_name[end]));
      if (starts && ends && (!best || kClassNames[*best].size() < name.size())) best = k;
    }
  }
  return best;
}

std::vector<DatasetEntry> list_dataset(const std::string& dir) {
  namespace fs = std::filesystem;
  std::error_code error;
  if (!fs::is_directory(dir, error)) throw IoError(dir + ": not a directory");
  std::vector<DatasetEntry> entries;
  for (const auto& item : fs::directory_iterator(dir)) {
    if (!item.is_directory()) continue;  // a run's JSON or a README beside the classes
    const std::string name = item.path().filename().string();
    const auto label = class_index(name);
    if (!label)
      throw InvalidArgument(item.path().string() + ": not a ModelNet10 class folder (expected bathtub, bed, chair, desk, "
                            "dresser, monitor, night_stand, sofa, table or toilet)");
    for (const auto& file : fs::directory_iterator(item.path()))
      if (file.is_regular_file() && file.path().extension() == ".vol") entries.push_back({file.path().string(), *label});
  }
  if (entries.empty()) throw InvalidArgument(dir + ": no <class>/*.vol files (make a dataset with `vola dataset`)");
  std::sort(entries.begin(), entries.end(), [](const DatasetEntry& a, const DatasetEntry& b) {
    return std::tie(a.label, a.path) < std::tie(b.label, b.path);
  });
  return entries;
}

}  // namespace vola::learn
