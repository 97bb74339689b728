// vola view's server side against slow models: the cells of every level in storage
// order (CellIndex, from any offset), each cell's first voxel, the binary batches the
// page decodes, cell lookups and picks (against the reference DDA on the coarse tree).
#include <gtest/gtest.h>

#include <cstring>
#include <map>
#include <nlohmann/json.hpp>
#include <random>

#include "test_support.hpp"
#include "vola/builder.hpp"
#include "vola/error.hpp"
#include "vola/file.hpp"
#include "vola/raycast/reference_dda.hpp"
#include "vola/viewer/cell_index.hpp"
#include "vola/viewer/viewed_file.hpp"

namespace {

using namespace vola_test;
using vola::viewer::CellIndex;
using vola::viewer::ViewedFile;

std::vector<Xyz> cells_of(const CellIndex& index, int level, std::uint64_t first, std::uint64_t count) {
  std::vector<Xyz> out;
  std::uint64_t expected_index = first;
  index.for_each_cell(level, first, count, [&](std::uint64_t i, const vola::Voxel& c) {
    EXPECT_EQ(i, expected_index++);
    out.push_back(to_xyz(c));
  });
  return out;
}

TEST(ViewerCellIndex, EveryLevelFromAnyOffsetMatchesTheSlowStorageOrder) {
  std::mt19937_64 rng(7);
  for (const Shape shape : kAllShapes) {
    for (const std::uint64_t seed : seeds_for(shape, 1)) {
      const Scenario s = make_scenario(seed);
      const XyzSet unique = s.unique();
      std::vector<vola::Voxel> voxels;
      for (const auto& v : unique) voxels.push_back(to_voxel(v));
      const vola::Tree tree = vola::build_from_voxels(voxels, s.depth);
      const CellIndex index(tree);
      // Each voxel's rank is its place in storage order; a cell's first voxel is the
      // first voxel of that order inside it.
      const std::vector<Xyz> order = slow_storage_order(unique, s.depth);
      for (int level = 0; level < s.depth; ++level) {
        SCOPED_TRACE(s.describe() + " level " + std::to_string(level));
        const std::vector<Xyz> expected = slow_storage_order(slow_cells(unique, level, s.depth), level + 1);
        ASSERT_EQ(index.cell_count(level), expected.size());
        EXPECT_EQ(cells_of(index, level, 0, expected.size() + 5), expected);
        for (int trial = 0; trial < 8 && !expected.empty(); ++trial) {
          const std::uint64_t first = rng() % expected.size();
          const std::uint64_t count = 1 + rng() % 300;
          const std::uint64_t end = std::min<std::uint64_t>(first + count, expected.size());
          EXPECT_EQ(cells_of(index, level, first, count),
                    std::vector<Xyz>(expected.begin() + static_cast<std::ptrdiff_t>(first),
                                     expected.begin() + static_cast<std::ptrdiff_t>(end)));
          EXPECT_EQ(to_xyz(index.cell(level, first)), expected[first]);
        }
        EXPECT_TRUE(cells_of(index, level, expected.size(), 10).empty());
        std::map<Xyz, std::uint64_t> first_rank;
        for (std::uint64_t r = 0; r < order.size(); ++r) first_rank.emplace(coarse_cell(order[r], level, s.depth), r);
        for (std::uint64_t i = 0; i < expected.size(); i += 1 + expected.size() / 200)
          ASSERT_EQ(index.first_voxel_rank(level, i), first_rank.at(expected[i])) << "cell " << i;
      }
      EXPECT_THROW(index.for_each_cell(s.depth, 0, 1, [](std::uint64_t, const vola::Voxel&) {}),
                   vola::InvalidArgument);
      EXPECT_THROW(index.cell(0, index.cell_count(0)), vola::InvalidArgument);
    }
  }
}

// A depth-4 tree with a classification and colours, written and served from a file.
struct ServedScene {
  TempDir dir;
  std::vector<Xyz> voxels;
  std::unique_ptr<ViewedFile> file;

  ServedScene() {
    std::mt19937_64 rng(11);
    const auto raw = random_voxels(rng, 4, Shape::clustered, 4000);
    const XyzSet unique(raw.begin(), raw.end());
    std::vector<vola::Voxel> list;
    for (const auto& v : unique) list.push_back(to_voxel(v));
    vola::Tree tree = vola::build_from_voxels(list, 4);
    voxels = slow_storage_order(unique, 4);  // rank order
    const std::size_t n = voxels.size();
    vola::AttributeColumn classes("classification", vola::ValueType::u8, vola::Reduction::majority, n);
    std::array<vola::AttributeColumn, 3> rgb{
        vola::AttributeColumn("red", vola::ValueType::u16, vola::Reduction::mean, n),
        vola::AttributeColumn("green", vola::ValueType::u16, vola::Reduction::mean, n),
        vola::AttributeColumn("blue", vola::ValueType::u16, vola::Reduction::mean, n)};
    for (std::size_t r = 0; r < n; ++r) {
      classes.set(r, static_cast<double>(voxels[r][2] % 7));
      for (int c = 0; c < 3; ++c) rgb[c].set(r, static_cast<double>((voxels[r][c] * 1031 + r) % 65536));
    }
    tree.attributes().add(std::move(classes));
    for (auto& c : rgb) tree.attributes().add(std::move(c));
    tree.set_frame(vola::Frame{vola::Quantization::grid, {1000.0, 2000.0, 50.0}, 0.5});
    vola::write(tree, (dir / "scene.vol").string());
    file = std::make_unique<ViewedFile>((dir / "scene.vol").string());
  }
};

template <class T>
T read_le(const std::string& bytes, std::size_t at) {
  T v{};
  std::memcpy(&v, bytes.data() + at, sizeof(T));
  return v;
}

TEST(ViewerFile, BatchesCarryTheCellsAndTheirFirstVoxelsClassAndColour) {
  const ServedScene scene;
  const ViewedFile& f = *scene.file;
  const nlohmann::json meta = f.metadata();
  EXPECT_EQ(meta["voxels"], scene.voxels.size());
  EXPECT_EQ(meta["has_classes"], true);
  EXPECT_EQ(meta["has_colours"], true);
  std::uint64_t class_total = 0;
  for (const auto& c : meta["classes"]) class_total += c["voxels"].get<std::uint64_t>();
  EXPECT_EQ(class_total, scene.voxels.size());
  for (int level = 0; level < 4; ++level) {
    const std::uint64_t cells = f.cells().cell_count(level);
    for (const std::uint64_t first : {std::uint64_t{0}, cells / 3}) {
      const std::string batch = f.cell_batch(level, first, 1000);
      ASSERT_EQ(std::memcmp(batch.data(), "VOLC", 4), 0);
      EXPECT_EQ(read_le<std::uint32_t>(batch, 4), static_cast<std::uint32_t>(level));
      ASSERT_EQ(read_le<std::uint32_t>(batch, 8), 2u);
      EXPECT_EQ(read_le<std::uint32_t>(batch, 12), vola::viewer::kBatchFlagClasses | vola::viewer::kBatchFlagColours);
      EXPECT_EQ(read_le<std::uint64_t>(batch, 16), first);
      const auto n = read_le<std::uint64_t>(batch, 24);
      ASSERT_EQ(n, std::min<std::uint64_t>(1000, cells - first));
      ASSERT_EQ(batch.size(), vola::viewer::kBatchHeaderBytes + n * 6 + n + 3 * n);
      for (std::uint64_t k = 0; k < n; ++k) {
        const Xyz cell = to_xyz(f.cells().cell(level, first + k));
        for (int a = 0; a < 3; ++a)
          ASSERT_EQ(read_le<std::uint16_t>(batch, vola::viewer::kBatchHeaderBytes + 6 * k + 2 * a), cell[a]);
        // The first voxel in rank order inside the cell speaks for it.
        std::size_t r = 0;
        while (coarse_cell(scene.voxels[r], level, 4) != cell) ++r;
        const std::size_t classes_at = vola::viewer::kBatchHeaderBytes + 6 * n;
        EXPECT_EQ(static_cast<unsigned char>(batch[classes_at + k]), scene.voxels[r][2] % 7);
        for (int c = 0; c < 3; ++c)
          EXPECT_EQ(static_cast<unsigned char>(batch[classes_at + n + 3 * k + c]),
                    ((scene.voxels[r][c] * 1031 + r) % 65536) >> 8);  // 16-bit colours scaled to 8 bits
      }
    }
    EXPECT_EQ(read_le<std::uint64_t>(f.cell_batch(level, cells + 5, 10), 24), 0u);
  }
  EXPECT_THROW(f.cell_batch(4, 0, 1), vola::InvalidArgument);
  EXPECT_THROW(f.cell_batch(-1, 0, 1), vola::InvalidArgument);
  EXPECT_THROW(f.cell_batch(0, 0, vola::viewer::kMaxBatchCells + 1), vola::InvalidArgument);
}

TEST(ViewerFile, CellInfoAndPicksMatchTheTreeAndTheReferenceCaster) {
  const ServedScene scene;
  const ViewedFile& f = *scene.file;
  std::mt19937_64 rng(3);
  for (int level = 0; level < 4; ++level) {
    const vola::Tree coarse = f.tree().level_of_detail(level + 1);
    const std::uint32_t side = vola::side_of(level + 1);
    for (int trial = 0; trial < 200; ++trial) {
      const vola::Voxel cell{static_cast<std::uint32_t>(rng() % side), static_cast<std::uint32_t>(rng() % side),
                             static_cast<std::uint32_t>(rng() % side)};
      const nlohmann::json info = f.cell_info(level, cell);
      ASSERT_EQ(info["occupied"].get<bool>(), coarse.contains(cell));
      if (!info["occupied"].get<bool>()) continue;
      const auto rank = info["rank"].get<std::size_t>();
      const Xyz voxel = scene.voxels[rank];
      EXPECT_EQ(coarse_cell(voxel, level, 4), to_xyz(cell));
      for (std::size_t r = 0; r < rank; ++r) ASSERT_NE(coarse_cell(scene.voxels[r], level, 4), to_xyz(cell));
      EXPECT_EQ(info["voxel"], nlohmann::json(voxel));
      EXPECT_EQ(info["attributes"]["classification"].get<double>(), voxel[2] % 7);
      EXPECT_DOUBLE_EQ(info["voxel_centre"][0].get<double>(), 1000.0 + (voxel[0] + 0.5) * 0.5);
      const double size = 0.5 * (1 << (2 * (3 - level)));
      EXPECT_DOUBLE_EQ(info["centre"][2].get<double>(), 50.0 + (cell.z + 0.5) * size);
    }
    for (int trial = 0; trial < 300; ++trial) {
      vola::raycast::Ray ray;
      std::uniform_real_distribution<double> pos(-2.0, side + 2.0), dir(-1.0, 1.0);
      ray.origin = {pos(rng), pos(rng), pos(rng)};
      ray.direction = {dir(rng), dir(rng), dir(rng)};
      if (trial % 3 == 0) ray.direction = {0.0, 0.0, -1.0};
      const auto expected = vola::raycast::reference_cast(coarse, ray);
      const nlohmann::json pick = f.pick(level, ray);
      ASSERT_EQ(pick["hit"].get<bool>(), expected.has_value());
      if (!expected) continue;
      EXPECT_EQ(pick["cell"], nlohmann::json(to_xyz(expected->voxel)));
      EXPECT_DOUBLE_EQ(pick["t"].get<double>(), expected->t);
    }
  }
  EXPECT_THROW(f.cell_info(1, vola::Voxel{16, 0, 0}), vola::InvalidArgument);
  vola::raycast::Ray zero;
  zero.direction = {0, 0, 0};
  EXPECT_THROW(f.pick(0, zero), vola::InvalidArgument);
  EXPECT_THROW(f.pick(4, vola::raycast::Ray{}), vola::InvalidArgument);
}

TEST(ViewerFile, ABadFileIsAFormatErrorNamingIt) {
  TempDir dir;
  write_bytes(dir / "bad.vol", std::vector<std::uint8_t>(40, 7));
  try {
    ViewedFile f((dir / "bad.vol").string());
    FAIL() << "opened a 40-byte file";
  } catch (const vola::FormatError& e) {
    EXPECT_NE(std::string(e.what()).find("bad.vol"), std::string::npos) << e.what();
  }
}

}  // namespace
