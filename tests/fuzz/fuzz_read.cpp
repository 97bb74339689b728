// Fuzz entry point: parse arbitrary bytes; whatever parses must behave like a tree.
// Only vola::Error may escape parse(); any other exception, a crash, a sanitizer
// report or a broken invariant (abort) is a finding.
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <span>
#include <vector>

#include "fuzz_seeds.hpp"
#include "vola/vola.hpp"

namespace {

using vola_fuzz::check;

void exercise(const vola::Tree& tree) {
  // Walk every voxel; the first few are queried one by one.
  std::vector<vola::Voxel> first;
  std::uint64_t count = 0;
  tree.for_each_voxel([&](const vola::Voxel& v) {
    if (first.size() < 64) first.push_back(v);
    ++count;
  });
  check(count == tree.voxel_count());
  for (std::size_t i = 0; i < first.size(); ++i) {
    const vola::Voxel& v = first[i];
    check(v.x < tree.side() && v.y < tree.side() && v.z < tree.side());
    check(tree.contains(v));
    check(tree.rank(v) == std::optional<std::uint64_t>(i));
    check(tree.voxel_payload(v).has_value() == (tree.has_payload() || !tree.voxel_payloads().empty()));
    (void)tree.block_payload(v);
    // A neighbour that may or may not be occupied, and one outside the grid.
    const vola::Voxel next{v.x ^ 1u, v.y, v.z};
    check(tree.contains(next) == tree.rank(next).has_value());
    check(!tree.contains(v.x + tree.side(), v.y, v.z));
    check(!tree.rank(vola::Voxel{v.x, v.y, v.z + tree.side()}).has_value());
  }
  for (int level = 0; level < tree.depth(); ++level) {
    std::uint64_t cells = 0;
    tree.for_each_node(level, [&](const vola::Voxel& c) {
      if (cells < 16) check(tree.contains_node(level, c));
      ++cells;
    });
    check(cells == tree.node_count(level));
  }
  const auto keys = tree.keys();
  for (std::size_t i = 1; i < keys.size(); ++i) check(keys[i - 1] < keys[i]);
  for (const auto& column : tree.attributes().columns()) {
    check(column.size() == tree.voxel_count());
    if (column.size()) (void)column.get(column.size() - 1);
  }
  for (int depth = 1; depth < tree.depth(); ++depth)
    check(tree.level_of_detail(depth).voxel_count() == tree.node_count(depth - 1));

  // The grid the file describes must be usable: the reader has accepted its frame.
  const vola::Quantizer quantizer = tree.quantizer();
  for (const vola::Voxel& v : first) {
    vola::Voxel back;
    (void)quantizer.to_voxel(quantizer.center(v), back);
  }

  // Set operations of a tree with itself.
  check(vola::unite(tree, tree).keys() == keys);
  check(vola::intersect(tree, tree).keys() == keys);
  check(vola::subtract(tree, tree).empty());

  // What we write, we read back identically.
  const auto bytes = vola::serialize(tree);
  const vola::Tree back = vola::parse(bytes, "reserialized");
  check(back.keys() == keys);
  check(vola::serialize(back) == bytes);
  if (tree.depth() <= 3) {
    const vola::Tree dense = vola::parse(vola::serialize(tree, {.layout = vola::Layout::dense}), "dense");
    check(dense.keys() == keys);
  }
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  vola::Tree tree;
  try {
    tree = vola::parse(std::span<const std::uint8_t>(data, size), "fuzz");
  } catch (const vola::Error&) {
    ++vola_fuzz::stats().refused;
    return 0;  // refusing bad bytes with the library's error is the expected outcome
  }
  ++vola_fuzz::stats().parsed;
  exercise(tree);  // a parsed tree must never throw
  return 0;
}
