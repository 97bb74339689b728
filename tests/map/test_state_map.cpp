// The state map (occupied / free / unknown in one tree): decisions equal the
// OccupancyMap's voxel for voxel after a file round trip, on random scenes; every level's
// state words equal a slow recount; all-free blocks (zero state words) survive sparse and
// compressed files; the marker is checked on reading.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <map>
#include <random>
#include <set>

#include "test_support.hpp"
#include "vola/builder.hpp"
#include "vola/error.hpp"
#include "vola/file.hpp"
#include "vola/map/occupancy_map.hpp"
#include "vola/map/state_map.hpp"

namespace {

using vola::map::OccupancyMap;
using vola::map::VoxelState;

// A few scans of random rays from random origins, some cut by max_range: known voxels of
// both states, at negative indices too.
OccupancyMap random_map(std::uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> coord(-4.0, 4.0);
  OccupancyMap map(0.25);
  for (int scan = 0; scan < 4; ++scan) {
    const vola::Point origin{coord(rng) / 4, coord(rng) / 4, coord(rng) / 4};
    std::vector<double> xyz;
    for (int n = 0; n < 300; ++n) xyz.insert(xyz.end(), {coord(rng), coord(rng), coord(rng)});
    map.insert_scan(xyz, origin, scan % 2 ? 3.0 : 0.0, 1);
  }
  return map;
}

vola::Point centre(const OccupancyMap& map, const vola::map::VoxelIndex& v) {
  return {(v.i + 0.5) * map.voxel_size(), (v.j + 0.5) * map.voxel_size(), (v.k + 0.5) * map.voxel_size()};
}

std::filesystem::path temp_file(const char* name) { return std::filesystem::temp_directory_path() / name; }

vola::Tree round_trip(const vola::Tree& tree, const vola::WriteOptions& options, const char* name) {
  const auto path = temp_file(name);
  vola::write(tree, path.string(), options);
  vola::Tree back = vola::read(path.string());
  std::filesystem::remove(path);
  return back;
}

// Every known voxel's state and log-odds, and unknown for voxels next to them that the map
// never updated, through the tree's own frame.
void expect_same_decisions(const OccupancyMap& map, const vola::Tree& tree) {
  ASSERT_TRUE(vola::map::is_state_map(tree));
  const vola::map::StateLookup lookup(tree);
  std::uint64_t occupied = 0, unknown_checked = 0;
  for (const auto& [v, value] : map.voxels()) {
    const auto got = lookup.at(centre(map, v));
    const VoxelState want = map.occupied(value) ? VoxelState::occupied : VoxelState::free;
    occupied += want == VoxelState::occupied;
    ASSERT_EQ(got.state, want) << v.i << " " << v.j << " " << v.k;
    ASSERT_TRUE(got.log_odds.has_value());
    EXPECT_EQ(*got.log_odds, value);
    for (const int d : {-1, 1}) {
      const vola::map::VoxelIndex next{v.i + d, v.j, v.k};
      if (map.log_odds(next)) continue;
      ++unknown_checked;
      const auto u = lookup.at(centre(map, next));
      EXPECT_EQ(u.state, VoxelState::unknown);
      EXPECT_FALSE(u.log_odds.has_value());
    }
  }
  EXPECT_GT(occupied, 0u);
  EXPECT_GT(unknown_checked, 0u);
  EXPECT_EQ(tree.voxel_count(), map.size());
  const auto counts = vola::map::state_counts(tree);
  EXPECT_EQ(counts.occupied, occupied);
  EXPECT_EQ(counts.free, map.size() - occupied);
}

TEST(StateMap, DecisionsEqualTheMapsAfterSparseAndCompressedFiles) {
  for (const std::uint64_t seed : {1u, 2u, 3u, 4u, 5u}) {
    SCOPED_TRACE(seed);
    const OccupancyMap map = random_map(seed);
    const vola::Tree tree = vola::map::freeze(map);
    expect_same_decisions(map, tree);
    expect_same_decisions(map, round_trip(tree, {}, "vola_state_map_sparse.vol"));
    vola::WriteOptions compressed;
    compressed.compress = true;
    if (vola::compression_available())
      expect_same_decisions(map, round_trip(tree, compressed, "vola_state_map_compressed.vol"));
  }
}

TEST(StateMap, EveryLevelsStateWordsEqualASlowRecount) {
  const OccupancyMap map = random_map(7);
  const vola::Tree tree = vola::map::freeze(map);
  const vola::Frame frame = tree.frame();
  // The map's occupied voxels as tree voxels.
  std::set<std::array<std::uint32_t, 3>> occupied;
  for (const auto& [v, value] : map.voxels())
    if (map.occupied(value))
      occupied.insert({static_cast<std::uint32_t>(std::llround(v.i - frame.origin[0] / frame.voxel_size)),
                       static_cast<std::uint32_t>(std::llround(v.j - frame.origin[1] / frame.voxel_size)),
                       static_cast<std::uint32_t>(std::llround(v.k - frame.origin[2] / frame.voxel_size))});
  for (int level = 0; level < tree.depth(); ++level) {
    const int shift = 2 * (tree.depth() - 1 - level);  // voxel -> level cell
    std::set<std::array<std::uint32_t, 3>> cells;
    for (const auto& o : occupied) cells.insert({o[0] >> shift, o[1] >> shift, o[2] >> shift});
    std::size_t checked = 0;
    tree.for_each_block(level, [&](std::size_t block, std::uint64_t word, std::uint32_t ox, std::uint32_t oy,
                                   std::uint32_t oz) {
      std::uint64_t want = 0;
      for (unsigned b = 0; b < 64; ++b)
        if (((word >> b) & 1u) && cells.count({ox + (b & 3u), oy + ((b >> 2) & 3u), oz + (b >> 4)})) want |= 1ull << b;
      EXPECT_EQ(tree.payload(level)[block], want) << "level " << level << " block " << block;
      ++checked;
    });
    EXPECT_EQ(checked, tree.occupancy(level).size());
  }
}

// Rays cut by max_range hit nothing: every known voxel is free and every state word is 0,
// the words the reference writer drops (FORMAT.md section 9); vola writes them.
TEST(StateMap, AnAllFreeMapSurvivesSparseAndCompressedFiles) {
  OccupancyMap map(0.5);
  map.insert_scan(std::vector<double>{10, 0, 0, 0, 10, 0, 0, 0, 10, -7, -7, 3}, {0.1, 0.1, 0.1}, 2.0);
  const vola::Tree tree = vola::map::freeze(map);
  ASSERT_GT(tree.voxel_count(), 4u);
  for (int level = 0; level < tree.depth(); ++level)
    for (const std::uint64_t w : tree.payload(level)) EXPECT_EQ(w, 0u);
  const auto bytes = vola::serialize(tree);
  // Header, then per level occupancy and payload words: twice the occupancy words.
  std::size_t occupancy_words = 0;
  for (int level = 0; level < tree.depth(); ++level) occupancy_words += tree.occupancy(level).size();
  EXPECT_EQ(tree.words().size(), 2 * occupancy_words);
  const vola::Tree back = vola::parse(bytes, "all-free");
  EXPECT_TRUE(std::ranges::equal(back.words(), tree.words()));
  EXPECT_EQ(vola::map::state_counts(back).free, map.size());
  EXPECT_EQ(vola::map::occupied_tree(back).voxel_count(), 0u);
  EXPECT_EQ(vola::map::free_tree(back).voxel_count(), map.size());
  if (vola::compression_available()) {
    vola::WriteOptions compressed;
    compressed.compress = true;
    const vola::Tree packed = round_trip(tree, compressed, "vola_state_map_all_free.vol");
    EXPECT_TRUE(std::ranges::equal(packed.words(), tree.words()));
    EXPECT_TRUE(vola::map::is_state_map(packed));
  }
}

TEST(StateMap, OccupiedAndFreeTreesPartitionTheKnownVoxels) {
  const OccupancyMap map = random_map(11);
  const vola::Tree tree = vola::map::freeze(map);
  const vola::Tree occupied = vola::map::occupied_tree(tree);
  const vola::Tree free = vola::map::free_tree(tree);
  EXPECT_EQ(occupied.voxel_count() + free.voxel_count(), tree.voxel_count());
  EXPECT_EQ(occupied.frame(), tree.frame());
  EXPECT_EQ(free.frame(), tree.frame());
  tree.for_each_voxel([&](const vola::Voxel& v) {
    const bool is_occupied = vola::map::state_at(tree, v) == VoxelState::occupied;
    EXPECT_EQ(occupied.contains(v), is_occupied);
    EXPECT_EQ(free.contains(v), !is_occupied);
    const vola::Tree& part = is_occupied ? occupied : free;
    EXPECT_EQ(part.attributes().find("log_odds")->get(*part.rank(v)),
              tree.attributes().find("log_odds")->get(*tree.rank(v)));
  });
  // A plain tree: its voxels are occupied, everything else free; occupied_tree keeps it.
  EXPECT_EQ(vola::map::state_at(occupied, vola::Voxel{0, 0, 0}),
            occupied.contains(vola::Voxel{0, 0, 0}) ? VoxelState::occupied : VoxelState::free);
  EXPECT_TRUE(std::ranges::equal(vola::map::occupied_tree(occupied).words(), occupied.words()));
  EXPECT_THROW(vola::map::free_tree(occupied), vola::InvalidArgument);
}

TEST(StateMap, BuiltFromVoxelListsItEqualsTheFrozenMap) {
  // The occupied and free voxels of a frozen map, shuffled, with their log-odds: the same
  // tree as freeze's, word for word and value for value (what a converted OctoMap becomes).
  const vola::Tree frozen = vola::map::freeze(random_map(17));
  std::vector<vola::Voxel> occupied, free;
  std::vector<float> occupied_log_odds, free_log_odds;
  const vola::AttributeColumn& column = *frozen.attributes().find("log_odds");
  frozen.for_each_voxel([&](const vola::Voxel& v) {
    const bool is_occupied = vola::map::state_at(frozen, v) == VoxelState::occupied;
    (is_occupied ? occupied : free).push_back(v);
    (is_occupied ? occupied_log_odds : free_log_odds).push_back(static_cast<float>(column.get(*frozen.rank(v))));
  });
  std::mt19937_64 rng(3);
  std::vector<std::size_t> order(free.size());
  for (std::size_t n = 0; n < order.size(); ++n) order[n] = n;
  std::shuffle(order.begin(), order.end(), rng);
  std::vector<vola::Voxel> shuffled;
  std::vector<float> shuffled_log_odds;
  for (std::size_t n : order) {
    shuffled.push_back(free[n]);
    shuffled_log_odds.push_back(free_log_odds[n]);
  }
  const vola::Tree built = vola::map::state_map_from_voxels(occupied, occupied_log_odds, shuffled, shuffled_log_odds,
                                                            frozen.depth(), frozen.frame());
  EXPECT_TRUE(std::ranges::equal(built.words(), frozen.words()));
  EXPECT_EQ(built.nbits(), frozen.nbits());
  EXPECT_TRUE(vola::map::is_state_map(built));
  ASSERT_EQ(built.attributes().find("log_odds")->bytes().size(), column.bytes().size());
  EXPECT_TRUE(std::ranges::equal(built.attributes().find("log_odds")->bytes(), column.bytes()));
  // No log-odds: OctoMap's clamping values, by state.
  const vola::Tree plain = vola::map::state_map_from_voxels(occupied, {}, free, {}, frozen.depth(), frozen.frame());
  const vola::map::SensorModel model;
  const vola::AttributeColumn& defaults = *plain.attributes().find("log_odds");
  plain.for_each_voxel([&](const vola::Voxel& v) {
    const bool is_occupied = vola::map::state_at(plain, v) == VoxelState::occupied;
    EXPECT_EQ(defaults.get(*plain.rank(v)), is_occupied ? model.clamp_max : model.clamp_min);
  });
  // A voxel in both states, a short log-odds list or a voxel off the grid is refused.
  std::vector<vola::Voxel> both = free;
  both.push_back(occupied.front());
  EXPECT_THROW(vola::map::state_map_from_voxels(occupied, {}, both, {}, frozen.depth(), frozen.frame()),
               vola::InvalidArgument);
  const std::vector<float> one_value{1.0f};
  EXPECT_THROW(vola::map::state_map_from_voxels(occupied, one_value, free, {}, frozen.depth(), frozen.frame()),
               vola::InvalidArgument);
  const std::vector<vola::Voxel> outside{{vola::side_of(frozen.depth()), 0, 0}};
  EXPECT_THROW(vola::map::state_map_from_voxels(outside, {}, {}, {}, frozen.depth(), frozen.frame()),
               vola::InvalidArgument);
}

TEST(StateMap, ACoarserLevelOfDetailSaysWhereAnyObstacleIs) {
  const OccupancyMap map = random_map(13);
  const vola::Tree tree = vola::map::freeze(map);
  const vola::Tree coarse = tree.level_of_detail(tree.depth() - 1);
  ASSERT_TRUE(vola::map::is_state_map(coarse));
  tree.for_each_voxel([&](const vola::Voxel& v) {
    const vola::Voxel cell{v.x / 4, v.y / 4, v.z / 4};
    if (vola::map::state_at(tree, v) == VoxelState::occupied)
      EXPECT_EQ(vola::map::state_at(coarse, cell), VoxelState::occupied);
    else
      EXPECT_NE(vola::map::state_at(coarse, cell), VoxelState::unknown);
  });
}

TEST(StateMap, TheMarkerIsCheckedOnReadingAndDenseFilesAreRefused) {
  OccupancyMap map(0.5);
  map.insert_scan(std::vector<double>{2.2, 0.3, 0.3}, {0.1, 0.1, 0.1});
  const vola::Tree tree = vola::map::freeze(map);
  vola::WriteOptions dense;
  dense.layout = vola::Layout::dense;
  EXPECT_THROW(vola::serialize(tree, dense), vola::InvalidArgument);
  std::vector<std::uint8_t> bytes = vola::serialize(tree);
  // The record: tag 5, flags, length 8, then the meaning byte.
  std::size_t at = 0;
  for (std::size_t i = vola::kHeaderSize; i + 17 <= bytes.size(); i += 8)
    if (vola_test::get_le<std::uint32_t>(bytes, i) == 5 && vola_test::get_le<std::uint64_t>(bytes, i + 8) == 8) at = i;
  ASSERT_NE(at, 0u);
  EXPECT_EQ(bytes[at + 16], 1u);
  bytes[at + 16] = 7;
  const auto e = vola_test::format_error_of([&] { vola::parse(bytes, "marked.vol"); });
  ASSERT_TRUE(e.has_value());
  EXPECT_NE(std::string(e->what()).find("unknown payload meaning 7"), std::string::npos) << e->what();
  // A plain tree gets no record, and a tree without payload cannot be marked.
  vola::Tree plain = vola::build_from_voxels(std::vector<vola::Voxel>{{1, 2, 3}}, 2);
  EXPECT_FALSE(vola::map::is_state_map(vola::parse(vola::serialize(plain))));
  EXPECT_THROW(plain.set_payload_meaning(vola::PayloadMeaning::occupancy_state), vola::InvalidArgument);
}

}  // namespace

// Incremental equals batch: scans inserted into a map thawed from a saved state map (read
// back from a file) give the bytes of inserting every scan into one map.
TEST(StateMap, InsertingIntoAThawedMapEqualsInsertingAllAtOnce) {
  std::mt19937_64 rng(11);
  std::uniform_real_distribution<double> coord(-4.0, 4.0);
  std::vector<std::pair<vola::Point, std::vector<double>>> scans;
  for (int scan = 0; scan < 6; ++scan) {
    const vola::Point origin{coord(rng) / 4, coord(rng) / 4, coord(rng) / 4};
    std::vector<double> xyz;
    for (int n = 0; n < 300; ++n) xyz.insert(xyz.end(), {coord(rng), coord(rng), coord(rng)});
    scans.emplace_back(origin, std::move(xyz));
  }
  OccupancyMap batch(0.25), first(0.25);
  for (std::size_t s = 0; s < scans.size(); ++s) {
    batch.insert_scan(scans[s].second, scans[s].first, 3.0, 2);
    if (s < 3) first.insert_scan(scans[s].second, scans[s].first, 3.0, 1);
  }
  const vola::Tree saved = round_trip(vola::map::freeze(first), {}, "vola_thaw.vol");
  OccupancyMap resumed = vola::map::thaw(saved);
  EXPECT_EQ(vola::serialize(vola::map::freeze(resumed)), vola::serialize(vola::map::freeze(first)));
  for (std::size_t s = 3; s < scans.size(); ++s) resumed.insert_scan(scans[s].second, scans[s].first, 3.0, 1);
  EXPECT_EQ(resumed.size(), batch.size());
  EXPECT_EQ(vola::serialize(vola::map::freeze(resumed)), vola::serialize(vola::map::freeze(batch)));

  const std::vector<vola::Voxel> one{{1, 2, 3}};
  EXPECT_THROW(vola::map::thaw(vola::build_from_voxels(one, 2)), vola::InvalidArgument);
  vola::Tree no_column = vola::map::freeze(first);
  no_column.attributes().clear();
  EXPECT_THROW(vola::map::thaw(no_column), vola::InvalidArgument);
}
