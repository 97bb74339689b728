#include "vola/stream_builder.hpp"

#include <algorithm>
#include <limits>

#include "emit.hpp"
#include "vola/error.hpp"

namespace vola {
VOLA_INLINE_NAMESPACE_BEGIN

namespace {

// One attribute's partial reduction over the voxels of a run.
struct Partial {
  std::vector<double> value;          // mean: sum; max, min, last: the value
  std::vector<std::uint32_t> count;   // mean: number of points
  // majority: for voxel i, (histogram_value, histogram_count)[offsets[i] .. offsets[i+1])
  // sorted by value
  std::vector<std::uint64_t> offsets;
  std::vector<double> histogram_value;
  std::vector<std::uint32_t> histogram_count;

  std::size_t memory_bytes() const noexcept {
    return value.capacity() * 8 + count.capacity() * 4 + offsets.capacity() * 8 + histogram_value.capacity() * 8 +
           histogram_count.capacity() * 4;
  }
};

// Sorted unique voxel keys with their partial reductions.
struct Run {
  std::vector<Key> keys;
  std::vector<std::uint64_t> payloads;
  std::vector<Partial> partials;

  std::size_t memory_bytes() const noexcept {
    std::size_t bytes = keys.capacity() * 8 + payloads.capacity() * 8;
    for (const auto& p : partials) bytes += p.memory_bytes();
    return bytes;
  }
};

// Appends voxel `i` of `from` to `to` (as a new voxel).
void append(const Run& from, std::size_t i, Run& to, std::span<const AttributeSpec> specs, bool payload) {
  to.keys.push_back(from.keys[i]);
  if (payload) to.payloads.push_back(from.payloads[i]);
  for (std::size_t a = 0; a < specs.size(); ++a) {
    const Partial& p = from.partials[a];
    Partial& q = to.partials[a];
    if (specs[a].reduction == Reduction::majority) {
      q.histogram_value.insert(q.histogram_value.end(), p.histogram_value.begin() + p.offsets[i],
                               p.histogram_value.begin() + p.offsets[i + 1]);
      q.histogram_count.insert(q.histogram_count.end(), p.histogram_count.begin() + p.offsets[i],
                               p.histogram_count.begin() + p.offsets[i + 1]);
      q.offsets.push_back(q.histogram_value.size());
    } else {
      q.value.push_back(p.value[i]);
      if (specs[a].reduction == Reduction::mean) q.count.push_back(p.count[i]);
    }
  }
}

// Appends the combination of voxel i of `older` and voxel j of `newer` (same key).
void append_combined(const Run& older, std::size_t i, const Run& newer, std::size_t j, Run& to,
                     std::span<const AttributeSpec> specs, bool payload) {
  to.keys.push_back(older.keys[i]);
  if (payload) to.payloads.push_back(newer.payloads[j]);  // the later point wins
  for (std::size_t a = 0; a < specs.size(); ++a) {
    const Partial& p = older.partials[a];
    const Partial& r = newer.partials[a];
    Partial& q = to.partials[a];
    switch (specs[a].reduction) {
      case Reduction::mean:
        q.value.push_back(p.value[i] + r.value[j]);
        q.count.push_back(p.count[i] + r.count[j]);
        break;
      case Reduction::max: q.value.push_back(std::max(p.value[i], r.value[j])); break;
      case Reduction::min: q.value.push_back(std::min(p.value[i], r.value[j])); break;
      case Reduction::last: q.value.push_back(r.value[j]); break;
      case Reduction::majority: {
        std::uint64_t x = p.offsets[i], y = r.offsets[j];
        const std::uint64_t x_end = p.offsets[i + 1], y_end = r.offsets[j + 1];
        while (x < x_end || y < y_end) {
          if (y == y_end || (x < x_end && p.histogram_value[x] < r.histogram_value[y])) {
            q.histogram_value.push_back(p.histogram_value[x]);
            q.histogram_count.push_back(p.histogram_count[x++]);
          } else if (x == x_end || r.histogram_value[y] < p.histogram_value[x]) {
            q.histogram_value.push_back(r.histogram_value[y]);
            q.histogram_count.push_back(r.histogram_count[y++]);
          } else {
            q.histogram_value.push_back(p.histogram_value[x]);
            q.histogram_count.push_back(p.histogram_count[x++] + r.histogram_count[y++]);
          }
        }
        q.offsets.push_back(q.histogram_value.size());
        break;
      }
    }
  }
}

// Majority partials of one chunk: per voxel, the sorted distinct values and their counts.
void reduce_majority(const double* values, const std::uint32_t* index, const std::vector<std::uint32_t>& starts,
                     Partial& p) {
  std::vector<double> scratch;
  const std::size_t voxels = starts.size() - 1;
  p.offsets.reserve(voxels + 1);
  for (std::size_t v = 0; v < voxels; ++v) {
    const std::uint32_t b = starts[v], e = starts[v + 1];
    if (e - b == 1) {  // the common case: one point
      p.histogram_value.push_back(values[index[b]]);
      p.histogram_count.push_back(1);
    } else {
      scratch.clear();
      for (std::uint32_t k = b; k < e; ++k) scratch.push_back(values[index[k]]);
      std::sort(scratch.begin(), scratch.end());
      for (std::size_t k = 0; k < scratch.size();) {
        std::size_t l = k;
        while (l < scratch.size() && scratch[l] == scratch[k]) ++l;
        p.histogram_value.push_back(scratch[k]);
        p.histogram_count.push_back(static_cast<std::uint32_t>(l - k));
        k = l;
      }
    }
    p.offsets.push_back(p.histogram_value.size());
  }
}

Run empty_run(std::span<const AttributeSpec> specs) {
  Run run;
  run.partials.resize(specs.size());
  for (std::size_t a = 0; a < specs.size(); ++a)
    if (specs[a].reduction == Reduction::majority) run.partials[a].offsets.push_back(0);
  return run;
}

Run merge(const Run& older, const Run& newer, std::span<const AttributeSpec> specs, bool payload) {
  Run out = empty_run(specs);
  if (specs.empty() && !payload) {  // occupancy only: a plain sorted union
    out.keys.resize(older.keys.size() + newer.keys.size());
    const auto end = std::set_union(older.keys.begin(), older.keys.end(), newer.keys.begin(), newer.keys.end(),
                                    out.keys.begin());
    out.keys.resize(static_cast<std::size_t>(end - out.keys.begin()));
    return out;
  }
  out.keys.reserve(older.keys.size() + newer.keys.size());
  std::size_t i = 0, j = 0;
  while (i < older.keys.size() || j < newer.keys.size()) {
    if (j == newer.keys.size() || (i < older.keys.size() && older.keys[i] < newer.keys[j])) {
      append(older, i++, out, specs, payload);
    } else if (i == older.keys.size() || newer.keys[j] < older.keys[i]) {
      append(newer, j++, out, specs, payload);
    } else {
      append_combined(older, i++, newer, j++, out, specs, payload);
    }
  }
  return out;
}

}  // namespace

struct StreamBuilder::State {
  Quantizer quantizer;
  std::vector<AttributeSpec> specs;
  bool payload = false;
  std::vector<Run> runs;  // oldest first; sizes roughly halve towards the back
  std::uint64_t points_in = 0;
  std::uint64_t points_outside = 0;
  // Scratch reused across chunks.
  std::vector<Key> keys;
  std::vector<std::uint32_t> index;
  std::vector<std::uint32_t> starts;
};

StreamBuilder::StreamBuilder(const Quantizer& quantizer, std::vector<AttributeSpec> attributes, bool payload)
    : state_(std::make_unique<State>(State{quantizer, std::move(attributes), payload, {}, 0, 0, {}, {}, {}})) {}
StreamBuilder::~StreamBuilder() = default;
StreamBuilder::StreamBuilder(StreamBuilder&&) noexcept = default;
StreamBuilder& StreamBuilder::operator=(StreamBuilder&&) noexcept = default;

std::uint64_t StreamBuilder::points_in() const noexcept { return state_->points_in; }
std::uint64_t StreamBuilder::points_outside() const noexcept { return state_->points_outside; }

std::size_t StreamBuilder::memory_bytes() const noexcept {
  std::size_t bytes = state_->keys.capacity() * 8 + state_->index.capacity() * 4;
  for (const auto& run : state_->runs) bytes += run.memory_bytes();
  return bytes;
}

void StreamBuilder::add(std::span<const double> xyz, std::span<const std::span<const double>> values,
                        std::span<const std::uint64_t> payloads) {
  State& s = *state_;
  const std::size_t n = xyz.size() / 3;
  if (xyz.size() != 3 * n) VOLA_THROW(InvalidArgument("stream builder: xyz size is not a multiple of 3"));
  if (values.size() != s.specs.size())
    VOLA_THROW(InvalidArgument("stream builder: " + std::to_string(values.size()) + " attribute arrays for " +
                          std::to_string(s.specs.size()) + " attributes"));
  for (const auto& v : values)
    if (v.size() != n) VOLA_THROW(InvalidArgument("stream builder: an attribute array's length differs from the points'"));
  if (s.payload && payloads.size() != n) VOLA_THROW(InvalidArgument("stream builder: one payload per point, please"));
  if (n > std::numeric_limits<std::uint32_t>::max()) VOLA_THROW(InvalidArgument("stream builder: chunk too large"));
  s.points_in += n;

  const bool per_point = s.payload || !s.specs.empty();
  s.keys.clear();
  s.index.clear();
  for (std::size_t i = 0; i < n; ++i) {
    Voxel v;
    if (!s.quantizer.to_voxel({xyz[3 * i], xyz[3 * i + 1], xyz[3 * i + 2]}, v)) {
      ++s.points_outside;
      continue;
    }
    s.keys.push_back(encode(v));
    if (per_point) s.index.push_back(static_cast<std::uint32_t>(i));
  }
  radix_sort(s.keys, per_point ? &s.index : nullptr, 6 * s.quantizer.depth());

  Run run = empty_run(s.specs);
  if (!per_point) {
    run.keys.assign(s.keys.begin(), std::unique(s.keys.begin(), s.keys.end()));
  } else {
    // Runs of equal keys hold one voxel's points in input order: [starts[v], starts[v+1]).
    std::vector<std::uint32_t>& starts = s.starts;
    starts.clear();
    for (std::size_t k = 0; k < s.keys.size(); ++k) {
      if (k == 0 || s.keys[k] != s.keys[k - 1]) {
        starts.push_back(static_cast<std::uint32_t>(k));
        run.keys.push_back(s.keys[k]);
      }
    }
    starts.push_back(static_cast<std::uint32_t>(s.keys.size()));
    const std::size_t voxels = run.keys.size();
    const std::uint32_t* index = s.index.data();
    if (s.payload) {
      run.payloads.resize(voxels);
      for (std::size_t v = 0; v < voxels; ++v) run.payloads[v] = payloads[index[starts[v + 1] - 1]];
    }
    // Attribute by attribute, each with a tight loop over the voxels.
    for (std::size_t a = 0; a < s.specs.size(); ++a) {
      const double* values_of = values[a].data();
      Partial& p = run.partials[a];
      const Reduction reduction = s.specs[a].reduction;
      if (reduction == Reduction::majority) {
        reduce_majority(values_of, index, starts, p);
        continue;
      }
      p.value.resize(voxels);
      if (reduction == Reduction::mean) p.count.resize(voxels);
      for (std::size_t v = 0; v < voxels; ++v) {
        const std::uint32_t b = starts[v], e = starts[v + 1];
        double r = values_of[index[reduction == Reduction::last ? e - 1 : b]];
        switch (reduction) {
          case Reduction::mean:
            for (std::uint32_t k = b + 1; k < e; ++k) r += values_of[index[k]];
            p.count[v] = e - b;
            break;
          case Reduction::max:
            for (std::uint32_t k = b + 1; k < e; ++k) r = std::max(r, values_of[index[k]]);
            break;
          case Reduction::min:
            for (std::uint32_t k = b + 1; k < e; ++k) r = std::min(r, values_of[index[k]]);
            break;
          default: break;
        }
        p.value[v] = r;
      }
    }
  }
  s.runs.push_back(std::move(run));
  // Binary-counter merging keeps O(log chunks) runs and merges each record O(log) times.
  while (s.runs.size() >= 2 && s.runs[s.runs.size() - 2].keys.size() <= 2 * s.runs.back().keys.size()) {
    Run merged = merge(s.runs[s.runs.size() - 2], s.runs.back(), s.specs, s.payload);
    s.runs.pop_back();
    s.runs.back() = std::move(merged);
  }
}

Tree StreamBuilder::finish() {
  State& s = *state_;
  Run all = empty_run(s.specs);
  for (auto& run : s.runs) {
    all = merge(all, run, s.specs, s.payload);
    run = Run{};
  }
  s.runs.clear();
  const int depth = s.quantizer.depth();
  Tree tree = detail::emit_levels(all.keys, depth, all.payloads, s.payload);
  if (s.payload) tree.set_voxel_payloads(std::move(all.payloads));
  const std::size_t voxels = all.keys.size();
  for (std::size_t a = 0; a < s.specs.size(); ++a) {
    const AttributeSpec& spec = s.specs[a];
    const Partial& p = all.partials[a];
    AttributeColumn column(spec.name, spec.type, spec.reduction, voxels);
    for (std::size_t v = 0; v < voxels; ++v) {
      switch (spec.reduction) {
        case Reduction::mean: column.set(v, p.value[v] / p.count[v]); break;
        case Reduction::majority: {
          // The most frequent value; ties go to the smallest (the histogram is sorted).
          std::uint64_t best = p.offsets[v];
          for (std::uint64_t k = p.offsets[v]; k < p.offsets[v + 1]; ++k)
            if (p.histogram_count[k] > p.histogram_count[best]) best = k;
          column.set(v, p.histogram_value[best]);
          break;
        }
        default: column.set(v, p.value[v]); break;
      }
    }
    tree.attributes().add(std::move(column));
  }
  tree.set_frame(s.quantizer.frame());
  return tree;
}

VOLA_INLINE_NAMESPACE_END
}  // namespace vola
