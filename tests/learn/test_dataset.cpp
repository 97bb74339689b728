// Dataset scenes, the stratified split, class names, mesh grids and the network input
// filled from the VOLA bits against a brute-force dense fill.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <numbers>
#include <numeric>
#include <optional>
#include <set>

#include "batch_producer.hpp"
#include "learn_test_data.hpp"
#include "test_support.hpp"
#include "vola/builder.hpp"
#include "vola/error.hpp"
#include "vola/learn/dataset.hpp"
#include "vola/learn/occupancy.hpp"

namespace {

using namespace vola::learn;
using vola_learn_test::shape_grid;

TEST(Dataset, CleanSceneScalesEachCellToABlock) {
  const auto grid = shape_grid(4, 7);
  const vola::Tree tree = clean_scene(grid, 32);
  EXPECT_EQ(tree.depth(), 3);
  std::size_t cells = 0;
  for (auto c : grid) cells += c;
  EXPECT_EQ(tree.voxel_count(), 8 * cells);
  for (std::uint32_t x = 0; x < 64; x += 3)
    for (std::uint32_t y = 0; y < 64; y += 5)
      for (std::uint32_t z = 0; z < 64; ++z)
        EXPECT_EQ(tree.contains(x, y, z), grid[((x / 2) * 32 + y / 2) * 32 + z / 2] != 0) << x << ' ' << y << ' ' << z;
  EXPECT_THROW(clean_scene(std::span(grid).first(100), 32), vola::InvalidArgument);
  EXPECT_THROW(clean_scene(grid, 31), vola::InvalidArgument);
}

TEST(Dataset, RoomSceneHasFloorWallsObjectAndClutter) {
  const auto grid = shape_grid(8, 3);
  std::size_t object_cells = 0;
  for (auto c : grid) object_cells += c;
  std::mt19937_64 a(5), b(5), c(6);
  const vola::Tree room = room_scene(grid, 32, a);
  EXPECT_EQ(vola_test::voxel_set(room), vola_test::voxel_set(room_scene(grid, 32, b)));  // seeded
  EXPECT_NE(vola_test::voxel_set(room), vola_test::voxel_set(room_scene(grid, 32, c)));
  for (std::uint32_t u = 0; u < 64; u += 7)
    for (std::uint32_t v = 0; v < 64; v += 7) {
      EXPECT_TRUE(room.contains(u, v, 0));   // floor
      EXPECT_TRUE(room.contains(0, u, v));   // wall x = 0
      EXPECT_TRUE(room.contains(u, 0, v));   // wall y = 0
    }
  const std::uint64_t shell = 64 * 64 + 64 * 63 + 63 * 63;
  // The object at 5/4 scale holds about (5/4)^3 as many voxels as its grid cells
  // (turning loses or gains a few), and clutter adds at least two 3^3 boxes.
  const double object = double(room.voxel_count() - shell);
  EXPECT_GT(object, 1.9 * 0.8 * double(object_cells) + 54);
  // An empty object leaves the room and its clutter.
  std::vector<std::uint8_t> empty(32 * 32 * 32, 0);
  std::mt19937_64 d(1);
  EXPECT_GT(room_scene(empty, 32, d).voxel_count(), shell);
}

TEST(Dataset, StratifiedSplitKeepsClassShares) {
  std::vector<int> labels;
  for (int k = 0; k < 10; ++k)
    for (int i = 0; i < 10 * (k + 1); ++i) labels.push_back(k);
  const Split split = stratified_split(labels, 0.2, 42);
  EXPECT_EQ(split.train.size() + split.validation.size(), labels.size());
  std::set<std::size_t> all(split.train.begin(), split.train.end());
  all.insert(split.validation.begin(), split.validation.end());
  EXPECT_EQ(all.size(), labels.size());
  std::vector<int> held(10, 0);
  for (auto i : split.validation) ++held[std::size_t(labels[i])];
  for (int k = 0; k < 10; ++k) EXPECT_EQ(held[std::size_t(k)], 2 * (k + 1)) << "class " << k;
  EXPECT_EQ(stratified_split(labels, 0.2, 42).validation, split.validation);
  EXPECT_NE(stratified_split(labels, 0.2, 43).validation, split.validation);
  // A class of two still gives one to validation; a class of one gives none.
  const std::vector<int> few = {3, 3, 5};
  EXPECT_EQ(stratified_split(few, 0.1, 1).validation.size(), 1u);
  EXPECT_THROW(stratified_split(labels, 1.0, 1), vola::InvalidArgument);
  EXPECT_THROW(stratified_split(std::vector<int>{11}, 0.1, 1), vola::InvalidArgument);
}

TEST(Dataset, ClassNamesInFileNames) {
  EXPECT_EQ(class_from_file_name("bathtub_0001.off"), 0);
  EXPECT_EQ(class_from_file_name("gomesh_normalized_chair_0059.off"), 2);
  EXPECT_EQ(class_from_file_name("night_stand_0007.stl"), 6);
  EXPECT_EQ(class_from_file_name("table12.obj"), 8);
  EXPECT_EQ(class_from_file_name("bedroom.obj"), std::nullopt);
  EXPECT_EQ(class_from_file_name("thing.off"), std::nullopt);
  EXPECT_EQ(class_index("monitor"), 5);
  EXPECT_EQ(class_index("Monitor"), std::nullopt);
}

TEST(Dataset, ListsClassFoldersAndRefusesOthers) {
  vola_test::TempDir dir;
  const vola::Tree tree = clean_scene(shape_grid(1, 1), 32);
  std::filesystem::create_directories(dir / "chair");
  std::filesystem::create_directories(dir / "sofa");
  vola::write(tree, (dir / "sofa" / "b.vol").string());
  vola::write(tree, (dir / "chair" / "a.vol").string());
  vola_test::write_bytes(dir / "run.json", {'{', '}'});
  const auto entries = list_dataset(dir.path().string());
  ASSERT_EQ(entries.size(), 2u);
  EXPECT_EQ(entries[0].label, 2);
  EXPECT_EQ(entries[1].label, 7);
  std::filesystem::create_directories(dir / "chiar");
  EXPECT_THROW(list_dataset(dir.path().string()), vola::InvalidArgument);
  vola_test::TempDir empty;
  EXPECT_THROW(list_dataset(empty.path().string()), vola::InvalidArgument);
}

TEST(Dataset, MeshBecomesACentredSolidGrid) {
  VOLA_REQUIRE_DATA(data);
  const auto grid = mesh_object_grid((data / "modelnet" / "off" / "bathtub_0001.off").string());
  ASSERT_EQ(grid.size(), 32u * 32 * 32);
  int low[3] = {32, 32, 32}, high[3] = {-1, -1, -1};
  std::size_t filled = 0;
  for (int x = 0; x < 32; ++x)
    for (int y = 0; y < 32; ++y)
      for (int z = 0; z < 32; ++z)
        if (grid[(std::size_t(x) * 32 + y) * 32 + z]) {
          ++filled;
          const int v[3] = {x, y, z};
          for (int a = 0; a < 3; ++a) low[a] = std::min(low[a], v[a]), high[a] = std::max(high[a], v[a]);
        }
  EXPECT_GT(filled, 500u);
  bool spans = false;
  for (int a = 0; a < 3; ++a) {
    spans |= low[a] == 0 && high[a] == 31;
    EXPECT_LE(std::abs((low[a] + high[a]) - 31), 2) << "axis " << a << " not centred";
  }
  EXPECT_TRUE(spans);
  EXPECT_THROW(mesh_object_grid((data / "modelnet" / "modelnet10_32_train.npz").string()), vola::Error);
}

// The obvious fill: every cell of the tree's grid asked with contains(), mapped the
// same way (turn, then floor(v * out / side)).
std::vector<float> brute_fill(const vola::Tree& tree, int out_side, double angle) {
  const std::uint32_t side = tree.side();
  std::vector<float> out(std::size_t(out_side) * out_side * out_side, 0.0f);
  const double c = std::cos(angle), s = std::sin(angle), centre = side / 2.0;
  for (std::uint32_t x = 0; x < side; ++x)
    for (std::uint32_t y = 0; y < side; ++y)
      for (std::uint32_t z = 0; z < side; ++z) {
        if (!tree.contains(x, y, z)) continue;
        double tx = x, ty = y;
        if (angle != 0) {
          const double px = x + 0.5 - centre, py = y + 0.5 - centre;
          tx = c * px - s * py + centre;
          ty = s * px + c * py + centre;
          if (!(tx >= 0 && ty >= 0 && tx < side && ty < side)) continue;
        }
        const std::uint64_t ox = std::uint64_t(tx) * out_side / side, oy = std::uint64_t(ty) * out_side / side,
                            oz = std::uint64_t(z) * out_side / side;
        out[(ox * out_side + oy) * out_side + oz] = 1.0f;
      }
  return out;
}

TEST(Occupancy, FillFromBitsEqualsBruteForceDenseFill) {
  std::mt19937_64 random(11);
  for (int trial = 0; trial < 4; ++trial) {
    std::vector<vola::Voxel> voxels;
    for (int i = 0; i < 3000; ++i)
      voxels.push_back({std::uint32_t(random() % 64), std::uint32_t(random() % 64), std::uint32_t(random() % 64)});
    std::sort(voxels.begin(), voxels.end(), [](auto& a, auto& b) { return std::tie(a.x, a.y, a.z) < std::tie(b.x, b.y, b.z); });
    voxels.erase(std::unique(voxels.begin(), voxels.end()), voxels.end());
    const vola::Tree tree = vola::build_from_voxels(voxels, 3);
    for (int out_side : {64, 32, 16})
      for (double angle : {0.0, 0.4, -2.5}) {
        std::vector<float> fast(std::size_t(out_side) * out_side * out_side, 7.0f);  // stale values get zeroed
        fill_occupancy(tree, out_side, angle, fast);
        EXPECT_EQ(fast, brute_fill(tree, out_side, angle)) << "side " << out_side << " angle " << angle;
      }
  }
  const vola::Tree tree = clean_scene(shape_grid(2, 2), 32);
  std::vector<float> wrong(100);
  EXPECT_THROW(fill_occupancy(tree, 32, 0, wrong), vola::InvalidArgument);
  std::vector<float> big(std::size_t(128) * 128 * 128);
  EXPECT_THROW(fill_occupancy(tree, 128, 0, big), vola::InvalidArgument);
}


// The ground the voting's invariance stands on: a grid turned exactly by a quarter turn
// (turn_quarters), then filled at a vote's angle, is the same input as the original
// filled at the angle a quarter turn further, for every multiple of 30 degrees.
TEST(Occupancy, QuarterTurnThenVoteAngleEqualsTheLaterVoteAngle) {
  const vola::Tree tree = clean_scene(shape_grid(3, 7), 32);
  const std::size_t cells = std::size_t(32) * 32 * 32;
  for (int quarters = 1; quarters < 4; ++quarters) {
    const vola::Tree turned = turn_quarters(tree, quarters);
    EXPECT_EQ(turned.voxel_count(), tree.voxel_count());
    for (int k = 0; k < 12; ++k) {
      std::vector<float> a(cells), b(cells);
      fill_occupancy(turned, 32, 2 * std::numbers::pi * k / 12, a);
      fill_occupancy(tree, 32, 2 * std::numbers::pi * (k + 3 * quarters) / 12, b);
      EXPECT_EQ(a, b) << quarters << " quarter turns, vote " << k;
    }
  }
  // Not a tautology: the turned grid differs from the original.
  std::vector<float> a(cells), b(cells);
  fill_occupancy(turn_quarters(tree, 1), 32, 0.0, a);
  fill_occupancy(tree, 32, 0.0, b);
  EXPECT_NE(a, b);
}

// An asymmetric object, its four quarter turns as 64^3 inputs, and one batch of 40 copies
// of it made with `augmentation`.
struct TurnedBatch {
  static constexpr std::size_t kCells = std::size_t(64) * 64 * 64;
  vola::Tree tree = clean_scene(shape_grid(3, 7), 32);
  std::vector<std::vector<float>> turned = std::vector<std::vector<float>>(4, std::vector<float>(kCells));
  std::vector<Sample> samples = std::vector<Sample>(40, Sample{tree, 0});
  std::optional<Batch> batch;

  explicit TurnedBatch(const Augmentation& augmentation) {
    for (int q = 0; q < 4; ++q) fill_occupancy(turn_quarters(tree, q), 64, 0.0, turned[std::size_t(q)]);
    std::vector<std::size_t> order(samples.size());
    std::iota(order.begin(), order.end(), 0);
    BatchProducer producer(samples, order, samples.size(), 64, 5, augmentation);
    batch = producer.next();
  }
  std::vector<float> input(std::size_t k) const {
    return {batch->inputs.begin() + std::ptrdiff_t(k * kCells),
            batch->inputs.begin() + std::ptrdiff_t((k + 1) * kCells)};
  }
};

// --quarter-turns alone: every training input is the sample turned by a whole number of
// quarter turns (the exact turn_quarters grid), and all four turns occur.
TEST(Augmentation, QuarterTurnsTurnTheSampleByWholeQuarters) {
  Augmentation augmentation;
  augmentation.quarter_turns = true;
  const TurnedBatch t(augmentation);
  ASSERT_TRUE(t.batch && t.batch->count() == t.samples.size());
  std::set<int> seen;
  for (std::size_t k = 0; k < t.batch->count(); ++k) {
    const auto match = std::find(t.turned.begin(), t.turned.end(), t.input(k));
    ASSERT_NE(match, t.turned.end()) << "input " << k << " is not a quarter turn of the sample";
    seen.insert(int(match - t.turned.begin()));
  }
  EXPECT_EQ(seen.size(), 4u);
  EXPECT_NE(t.turned[0], t.turned[1]);  // the shape is not symmetric under a quarter turn
}

// --orientation-bins 4 alone: each input is the sample turned by the step its label says.
TEST(Augmentation, OrientationBinsLabelTheTurnEachInputGot) {
  Augmentation augmentation;
  augmentation.orientation_bins = 4;
  const TurnedBatch t(augmentation);
  ASSERT_TRUE(t.batch && t.batch->count() == t.samples.size());
  ASSERT_EQ(t.batch->orientations.size(), t.samples.size());
  std::set<std::int64_t> seen;
  for (std::size_t k = 0; k < t.batch->count(); ++k) {
    const std::int64_t step = t.batch->orientations[k];
    ASSERT_TRUE(step >= 0 && step < 4) << step;
    EXPECT_EQ(t.input(k), t.turned[std::size_t(step)]) << "input " << k << " is not turned by its label's quarter";
    seen.insert(step);
  }
  EXPECT_EQ(seen.size(), 4u);
}

TEST(Dataset, BalancedSplitHoldsOutAFixedCountPerClass) {
  std::vector<int> labels;
  const int sizes[kClassCount] = {106, 515, 889, 200, 200, 465, 200, 680, 392, 344};  // ModelNet10's train split
  for (int k = 0; k < kClassCount; ++k) labels.insert(labels.end(), std::size_t(sizes[k]), k);
  const Split split = balanced_split(labels, 100, 1);
  std::vector<int> held(kClassCount, 0);
  for (std::size_t i : split.validation) ++held[std::size_t(labels[i])];
  EXPECT_EQ(held[0], 53);  // half of 106: bathtub keeps 53 to train on
  for (int k = 1; k < kClassCount; ++k) EXPECT_EQ(held[std::size_t(k)], 100) << kClassNames[std::size_t(k)];
  EXPECT_EQ(split.train.size() + split.validation.size(), labels.size());
  EXPECT_EQ(balanced_split(labels, 100, 1).validation, split.validation);
  EXPECT_NE(balanced_split(labels, 100, 2).validation, split.validation);
}

}  // namespace
