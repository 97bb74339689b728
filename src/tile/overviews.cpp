#include "overviews.hpp"

#include <algorithm>
#include <array>
#include <cstring>
#include <filesystem>
#include <map>
#include <optional>
#include <span>

#include "vola/builder.hpp"
#include "vola/error.hpp"
#include "vola/file.hpp"
#include "vola/parallel.hpp"
#include "vola/voxel_reducer.hpp"

namespace vola::tile {

namespace fs = std::filesystem;

namespace {

struct Node {  // one file of a level: a tile (level 0) or an overview
  TileIndex tile;
  std::string file;
  Box bbox;
};

TileIndex parent_of(const TileIndex& t) { return {t.i >> 2, t.j >> 2, t.k >> 2}; }  // floor division by 4

Box unite(const Box& a, const Box& b) {
  Box u;
  for (int i = 0; i < 3; ++i) {
    u.min[i] = std::min(a.min[i], b.min[i]);
    u.max[i] = std::max(a.max[i], b.max[i]);
  }
  return u;
}

// A child's offset in the parent's voxels, per axis: children are 4x4x4 tiles, each a
// quarter of the parent's voxels along an axis.
std::array<std::uint32_t, 3> child_offset(const TileIndex& parent, const Node& child, int depth) {
  const std::uint32_t child_span = side_of(depth - 1);
  return {static_cast<std::uint32_t>(child.tile.i - 4 * parent.i) * child_span,
          static_cast<std::uint32_t>(child.tile.j - 4 * parent.j) * child_span,
          static_cast<std::uint32_t>(child.tile.k - 4 * parent.k) * child_span};
}

Tree open_child(const Node& child, const OverviewContext& c) {
  Tree tree = open_mapped((fs::path(c.output_dir) / child.file).string());
  if (tree.depth() != c.grid.depth)
    throw FormatError(child.file, 0, "depth " + std::to_string(tree.depth()) + " differs from the tile set's " +
                                         std::to_string(c.grid.depth));
  return tree;
}

RecordField::Kind field_kind(ValueType t) {
  using K = RecordField::Kind;
  switch (t) {
    case ValueType::u8: return K::u8;
    case ValueType::u16: return K::u16;
    case ValueType::u32: return K::u32;
    case ValueType::u64: return K::u64;
    case ValueType::i8: return K::i8;
    case ValueType::i16: return K::i16;
    case ValueType::i32: return K::i32;
    case ValueType::i64: return K::i64;
    case ValueType::f32: return K::f32;
    default: return K::f64;
  }
}

// The parent's attribute columns: each child voxel's values reduced into the parent
// voxel that covers it, by the column's own reduction (a mean is the mean of the finer
// voxels' values, each finer voxel counting once), children in index order and voxels
// in rank order, so the result is the same whoever builds it. Children are opened a
// second time rather than kept open: only one child's columns are in memory at once.
// `keys`: the parent's voxel keys, sorted; a voxel's rank is its place among them.
void reduce_children(const TileIndex& parent, const std::vector<const Node*>& children, const OverviewContext& c,
                     std::span<const Key> keys, Tree& tree) {
  std::vector<AttributeSpec> specs;
  std::optional<VoxelReducer> reducer;  // made with the first child's columns
  std::vector<std::uint64_t> ranks;      // a child's voxels' parent voxels
  for (const Node* child : children) {
    const Tree tree_of_child = open_child(*child, c);
    if (!reducer) {
      for (const AttributeColumn& column : tree_of_child.attributes().columns())
        specs.push_back({column.name(), column.type(), column.reduction()});
      if (specs.empty()) return;
      reducer.emplace(specs, tree.voxel_count());
    }
    std::vector<const AttributeColumn*> columns;
    for (const AttributeSpec& spec : specs) {
      const AttributeColumn* column = tree_of_child.attributes().find(spec.name);
      if (!column || column->type() != spec.type || column->reduction() != spec.reduction)
        throw FormatError(child->file, 0, "has no attribute column '" + spec.name + "' like its neighbours'");
      columns.push_back(column);
    }
    const auto [ox, oy, oz] = child_offset(parent, *child, c.grid.depth);
    // A child's voxels come in key order, and so do the parent voxels that cover them
    // (the child is an aligned block of the parent): one walk along the parent's keys.
    ranks.clear();
    std::size_t at = 0;
    tree_of_child.for_each_voxel([&](const Voxel& v) {
      const Key up = encode(ox + v.x / 4, oy + v.y / 4, oz + v.z / 4);
      if (ranks.empty()) at = static_cast<std::size_t>(std::lower_bound(keys.begin(), keys.end(), up) - keys.begin());
      while (keys[at] < up) ++at;
      ranks.push_back(at);
    });
    // The child's columns read in place (little-endian values of their type).
    std::vector<FieldColumn> in;
    for (const AttributeColumn* column : columns)
      in.push_back({reinterpret_cast<const std::uint8_t*>(column->bytes().data()), size_of(column->type()),
                    {.kind = field_kind(column->type()), .scaled = false}});
    reducer->add_columns(ranks, in);
  }
  reducer->finish_into(tree);
}

Tree build_parent(const TileIndex& parent, const std::vector<const Node*>& children, const OverviewContext& c) {
  const int depth = c.grid.depth;
  std::vector<Key> keys;
  for (const Node* child : children) {
    const Tree tree = open_child(*child, c);
    const auto [ox, oy, oz] = child_offset(parent, *child, depth);
    tree.for_each_node(depth - 2, [&](const Voxel& cell) { keys.push_back(encode(ox + cell.x, oy + cell.y, oz + cell.z)); });
  }
  radix_sort(keys, nullptr, 6 * depth);
  keys.erase(std::unique(keys.begin(), keys.end()), keys.end());
  Tree tree = build_from_sorted_keys(keys, depth);
  reduce_children(parent, children, c, keys, tree);
  return tree;
}

}  // namespace

std::vector<OverviewEntry> build_overviews(
    const std::vector<TileEntry>& tiles, const OverviewContext& c, Communicator& comm,
    const std::function<void(const std::string&, std::uint64_t, std::uint64_t)>& progress) {
  std::vector<OverviewEntry> out;
  const int depth = c.grid.depth;
  std::vector<Node> level;
  for (const TileEntry& t : tiles) level.push_back({t.tile, t.file, t.bbox});
  const int rank = comm.rank(), ranks = comm.size();
  for (int L = 1; level.size() > 1 && L <= depth - 1; ++L) {
    std::map<TileIndex, std::vector<const Node*>> parents;
    for (const Node& n : level) parents[parent_of(n.tile)].push_back(&n);
    std::vector<TileIndex> order;
    for (const auto& [p, children] : parents) order.push_back(p);
    const fs::path folder = fs::path("overviews") / std::string("L").append(std::to_string(L));
    fs::create_directories(fs::path(c.output_dir) / folder);
    const double scale = static_cast<double>(std::uint64_t{1} << (2 * L));  // 4^L
    std::vector<std::uint64_t> voxels(order.size(), 0);
    std::vector<Node> next(order.size());
    ParallelOptions parallel;
    parallel.threads = c.workers;
    parallel.name = "tile.overviews";
    const auto build_parents = [&](std::size_t begin, std::size_t end) {
      for (std::size_t p = begin; p < end; ++p) {
        const auto& children = parents.at(order[p]);
        Box bbox = children.front()->bbox;
        for (const Node* child : children) bbox = unite(bbox, child->bbox);
        next[p] = {order[p], (folder / tile_file_name(order[p])).string(), bbox};
        if (static_cast<int>(p % static_cast<std::size_t>(ranks)) != rank) continue;
        Tree tree = build_parent(order[p], children, c);
        Frame frame;
        frame.quantization = Quantization::grid;
        frame.voxel_size = c.grid.voxel_size() * scale;
        frame.origin = {c.grid.origin[0] + order[p].i * c.grid.tile_size * scale,
                        c.grid.origin[1] + order[p].j * c.grid.tile_size * scale,
                        c.grid.origin[2] + order[p].k * c.grid.tile_size * scale};
        tree.set_frame(frame);
        c.georef.apply(tree, bbox);
        write(tree, (fs::path(c.output_dir) / next[p].file).string());
        voxels[p] = tree.voxel_count();
      }
    };
    parallel_for(order.size(), build_parents, parallel);
    // Gathering the counts is also the barrier: every rank has written this level.
    std::vector<std::uint8_t> mine;
    for (std::size_t p = 0; p < order.size(); ++p)
      if (static_cast<int>(p % static_cast<std::size_t>(ranks)) == rank) {
        const std::uint64_t pair[2] = {p, voxels[p]};
        const auto* b = reinterpret_cast<const std::uint8_t*>(pair);
        mine.insert(mine.end(), b, b + sizeof pair);
      }
    for (const auto& message : comm.all_gather(mine))
      for (std::size_t at = 0; at + 16 <= message.size(); at += 16) {
        std::uint64_t pair[2];
        std::memcpy(pair, message.data() + at, sizeof pair);
        if (pair[0] < voxels.size()) voxels[pair[0]] = pair[1];
      }
    for (std::size_t p = 0; p < order.size(); ++p) out.push_back({L, order[p], next[p].file, voxels[p]});
    if (rank == 0 && progress) progress("overview level " + std::to_string(L), order.size(), order.size());
    level = std::move(next);
  }
  return out;
}

}  // namespace vola::tile
