// Merging StreamBuilder's runs: column by column, in place from the back, so that each
// pass is a tight loop over arrays and the older run's memory is reused.
#include "stream_runs.hpp"

#include <functional>

#include "reductions.hpp"

namespace vola {
VOLA_INLINE_NAMESPACE_BEGIN
namespace stream {

// The source of each key of the sorted union of the keys a and b, in order, into
// `from`; returns the union's size.
std::size_t plan_merge(std::span<const Key> a, std::span<const Key> b, std::vector<Source>& from) {
  from.resize(a.size() + b.size());
  std::size_t i = 0, j = 0, o = 0;
  while (i < a.size() && j < b.size()) {
    const Key x = a[i], y = b[j];
    const bool take_a = x <= y, take_b = y <= x;
    from[o++] = static_cast<Source>(take_a | take_b << 1);
    i += take_a;
    j += take_b;
  }
  std::fill(from.begin() + static_cast<std::ptrdiff_t>(o), from.begin() + static_cast<std::ptrdiff_t>(o + a.size() - i), kOlder);
  o += a.size() - i;
  std::fill(from.begin() + static_cast<std::ptrdiff_t>(o), from.begin() + static_cast<std::ptrdiff_t>(o + b.size() - j), kNewer);
  return o + b.size() - j;
}

// n elements (uninitialized beyond the old size); room for as much again when the
// vector has to move, so that the next merges into it stay in place.
template <class T>
void grow(Column<T>& column, std::size_t n) {
  if (column.capacity() < n) column.reserve(2 * n);
  column.resize(n);
}

// One per-voxel column of a merge, in place in the older run's column a: a voxel in
// both runs gets both(older's value, newer's value). From the back: output o is at or
// after every older value not yet read, so nothing is overwritten before it is read.
// Merging in place instead of into new vectors halves the fresh memory, whose page
// faults and zeroing by the kernel took half of the conversion.
template <class T, class Both>
void merge_column(Column<T>& a, const Column<T>& b, std::span<const Source> plan, Both both) {
  std::size_t i = a.size(), j = b.size();
  grow(a, plan.size());
  T* out = a.data();
  for (std::size_t o = plan.size(); o-- > 0;) {
    switch (plan[o]) {
      case kOlder: out[o] = out[--i]; break;
      case kNewer: out[o] = b[--j]; break;
      case kBoth:
        --i;
        out[o] = both(out[i], b[--j]);
        break;
    }
  }
}

// Majority partials: the union of two sorted (key, value) pair lists in place in a,
// counts of equal pairs added; from the back, as merge_column.
void merge_pairs(Partial& a, const Partial& b) {
  const std::size_t na = a.pair_key.size(), nb = b.pair_key.size();
  auto before = [](Key x, double u, Key y, double w) { return x < y || (x == y && detail::value_before(u, w)); };
  std::size_t united = 0, i = 0, j = 0;
  while (i < na && j < nb) {
    const bool take_a = !before(b.pair_key[j], b.pair_value[j], a.pair_key[i], a.pair_value[i]);
    const bool take_b = !before(a.pair_key[i], a.pair_value[i], b.pair_key[j], b.pair_value[j]);
    i += take_a;
    j += take_b;
    ++united;
  }
  united += (na - i) + (nb - j);
  grow(a.pair_key, united);
  grow(a.pair_value, united);
  grow(a.pair_count, united);
  Key* key = a.pair_key.data();
  double* value = a.pair_value.data();
  std::uint32_t* count = a.pair_count.data();
  i = na;
  j = nb;
  for (std::size_t o = united; o-- > 0;) {
    const bool has_a = i > 0, has_b = j > 0;
    const bool take_a = has_a && (!has_b || !before(key[i - 1], value[i - 1], b.pair_key[j - 1], b.pair_value[j - 1]));
    const bool take_b = has_b && (!has_a || !before(b.pair_key[j - 1], b.pair_value[j - 1], key[i - 1], value[i - 1]));
    if (take_a && take_b) {
      --i;
      --j;
      key[o] = key[i];
      value[o] = value[i];
      count[o] = count[i] + b.pair_count[j];
    } else if (take_a) {
      --i;
      key[o] = key[i];
      value[o] = value[i];
      count[o] = count[i];
    } else {
      --j;
      key[o] = b.pair_key[j];
      value[o] = b.pair_value[j];
      count[o] = b.pair_count[j];
    }
  }
}

// The union of two runs with attributes or payloads, left in `older`; voxels in both
// combine their partials (the newer's payload wins: it holds the later point). Column
// by column, so that each pass is a tight loop over arrays.
void merge_into(Run& older, const Run& newer, std::span<const AttributeSpec> specs, bool payload,
                std::vector<Source>& plan_buffer) {
  const std::size_t older_voxels = older.keys.size(), newer_voxels = newer.keys.size();
  const std::size_t voxels = plan_merge(older.keys, newer.keys, plan_buffer);
  const std::span<const Source> plan(plan_buffer.data(), voxels);
  merge_column(older.keys, newer.keys, plan, [](Key k, Key) { return k; });
  if (has_mean(specs)) merge_column(older.points, newer.points, plan, std::plus<>());
  if (payload) merge_column(older.payloads, newer.payloads, plan, [](std::uint64_t, std::uint64_t n) { return n; });
  for (std::size_t a = 0; a < specs.size(); ++a) {
    Column<double>& p = older.partials[a].value;
    const Column<double>& r = newer.partials[a].value;
    if (specs[a].reduction == Reduction::majority) {
      merge_pairs(older.partials[a], newer.partials[a]);
      continue;
    }
    detail::with_reduction(specs[a].reduction, [&](auto reduction) {
      merge_column(p, r, plan, [](double x, double y) { return detail::combine<decltype(reduction)::value>(x, y); });
    });
    Column<std::uint32_t>& older_nans = older.partials[a].nans;
    const Column<std::uint32_t>& newer_nans = newer.partials[a].nans;
    if (older_nans.empty() && newer_nans.empty()) continue;  // no point without a value yet
    if (older_nans.empty()) older_nans.assign(older_voxels, 0);
    if (newer_nans.empty()) {
      merge_column(older_nans, Column<std::uint32_t>(newer_voxels, 0), plan, std::plus<>());
    } else {
      merge_column(older_nans, newer_nans, plan, std::plus<>());
    }
  }
}


// Room for `voxels` in every column the run uses (address space only).
void reserve_voxels(Run& run, std::span<const AttributeSpec> specs, bool payload, std::uint64_t voxels) {
  run.keys.reserve(voxels);
  if (has_mean(specs)) run.points.reserve(voxels);
  if (payload) run.payloads.reserve(voxels);
  run.partials.resize(specs.size());
  for (std::size_t a = 0; a < specs.size(); ++a) {
    Partial& p = run.partials[a];
    if (specs[a].reduction != Reduction::majority) {
      p.value.reserve(voxels);
    } else {
      p.pair_key.reserve(voxels);
      p.pair_value.reserve(voxels);
      p.pair_count.reserve(voxels);
    }
  }
}

// Majority partials of one chunk: per voxel (starts: its points' range in index), its
// sorted distinct values and their counts.
void reduce_majority(std::span<const Key> voxel_keys, const double* values, const std::uint32_t* index,
                     const std::vector<std::uint32_t>& starts, Partial& p, std::vector<double>& scratch) {
  const std::size_t voxels = voxel_keys.size(), points = starts.back();
  p.pair_key.resize(points);  // at most one pair per point; trimmed below
  p.pair_value.resize(points);
  p.pair_count.resize(points);
  std::size_t o = 0;
  for (std::size_t v = 0; v < voxels; ++v) {
    const std::uint32_t b = starts[v], e = starts[v + 1];
    if (e - b == 1) {  // the common case: one point
      p.pair_key[o] = voxel_keys[v];
      p.pair_value[o] = values[index[b]];
      p.pair_count[o++] = 1;
      continue;
    }
    scratch.clear();
    for (std::uint32_t k = b; k < e; ++k) scratch.push_back(values[index[k]]);
    detail::distinct_counts(scratch, [&](double value, std::uint32_t count) {
      p.pair_key[o] = voxel_keys[v];
      p.pair_value[o] = value;
      p.pair_count[o++] = count;
    });
  }
  p.pair_key.resize(o);
  p.pair_value.resize(o);
  p.pair_count.resize(o);
}

// The most frequent value of each voxel (ties to the smallest: values are sorted),
// stored at the voxel's rank in keys.
void store_majority(std::span<const Key> keys, const Partial& p, AttributeColumn& column) {
  std::size_t k = 0;
  for (std::size_t v = 0; v < keys.size(); ++v) {
    std::size_t best = k;
    for (; k < p.pair_key.size() && p.pair_key[k] == keys[v]; ++k)
      if (p.pair_count[k] > p.pair_count[best]) best = k;
    column.set(v, detail::canonical_value(p.pair_value[best]));
  }
}

}  // namespace stream
VOLA_INLINE_NAMESPACE_END
}  // namespace vola
