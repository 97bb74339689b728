#include "vola/voxel_reducer.hpp"

#include <algorithm>
#include <bit>
#include <cmath>
#include <limits>
#include <unordered_map>

#include "reductions.hpp"
#include "vola/error.hpp"
#include "vola/tree.hpp"

namespace vola {
VOLA_INLINE_NAMESPACE_BEGIN

namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

// Majority partials: each voxel's first value and its count in place; the values of a
// voxel that differ from its first are counted in a table beside, by (rank, value), so
// that memory follows distinct values per voxel, not points (most voxels hold one).
struct MajorityPartial {
  std::vector<double> first;
  std::vector<std::uint32_t> first_count;
  struct PairKey {
    std::uint64_t rank, bits;
    bool operator==(const PairKey&) const = default;
  };
  struct PairHash {
    std::size_t operator()(const PairKey& k) const noexcept {
      return static_cast<std::size_t>((k.rank * 0x9E3779B97F4A7C15ull) ^ (k.bits * 0xC2B2AE3D27D4EB4Full));
    }
  };
  std::unordered_map<PairKey, std::uint32_t, PairHash> others;

  static std::uint64_t bits_of(double v) noexcept {
    return std::isnan(v) ? 0x7FF8000000000000ull : std::bit_cast<std::uint64_t>(v == 0.0 ? 0.0 : v);  // -0 is 0
  }
  void add(std::uint64_t rank, double v) {
    if (first_count[rank] == 0) {
      first[rank] = v;
      first_count[rank] = 1;
    } else if (detail::same_value(first[rank], v)) {
      ++first_count[rank];
    } else {
      ++others[PairKey{rank, bits_of(v)}];
    }
  }
};

}  // namespace

struct VoxelReducer::State {
  std::vector<AttributeSpec> specs;
  std::uint64_t voxels = 0;
  std::vector<std::uint32_t> points;       // per voxel
  std::vector<std::vector<double>> value;  // per attribute but majority: sum or value per voxel
  std::vector<MajorityPartial> majority;   // per attribute (used by majority ones only)
  // Points added one at a time, reduced in batches.
  std::vector<std::uint64_t> pending_ranks;
  std::vector<std::vector<double>> pending_values;
};

VoxelReducer::VoxelReducer(std::vector<AttributeSpec> specs, std::uint64_t voxels) : state_(std::make_unique<State>()) {
  State& s = *state_;
  s.specs = std::move(specs);
  s.voxels = voxels;
  if (s.specs.empty()) return;
  s.points.assign(voxels, 0);
  s.value.resize(s.specs.size());
  s.majority.resize(s.specs.size());
  for (std::size_t a = 0; a < s.specs.size(); ++a) {
    switch (s.specs[a].reduction) {
      case Reduction::majority:
        s.majority[a].first.assign(voxels, 0.0);
        s.majority[a].first_count.assign(voxels, 0);
        break;
      case Reduction::max:
      case Reduction::min: s.value[a].assign(voxels, kNaN); break;  // fmax/fmin(NaN, v) = v
      default: s.value[a].assign(voxels, 0.0); break;
    }
  }
}
VoxelReducer::~VoxelReducer() = default;
VoxelReducer::VoxelReducer(VoxelReducer&&) noexcept = default;
VoxelReducer& VoxelReducer::operator=(VoxelReducer&&) noexcept = default;

std::uint64_t VoxelReducer::voxels() const noexcept { return state_->voxels; }

std::size_t VoxelReducer::memory_bytes() const noexcept {
  const State& s = *state_;
  std::size_t bytes = s.points.capacity() * 4;
  for (const auto& v : s.value) bytes += v.capacity() * 8;
  for (const auto& m : s.majority)
    bytes += m.first.capacity() * 8 + m.first_count.capacity() * 4 + m.others.size() * 40 + m.others.bucket_count() * 8;
  return bytes;
}

void VoxelReducer::add(std::span<const std::uint64_t> ranks, std::span<const std::span<const double>> values) {
  flush_pending();
  add_now(ranks, values);
}

void VoxelReducer::flush_pending() {
  State& s = *state_;
  if (s.pending_ranks.empty()) return;
  std::vector<std::span<const double>> values(s.pending_values.begin(), s.pending_values.end());
  add_now(s.pending_ranks, values);
  s.pending_ranks.clear();
  for (auto& v : s.pending_values) v.clear();
}

void VoxelReducer::add_now(std::span<const std::uint64_t> ranks, std::span<const std::span<const double>> values) {
  State& s = *state_;
  if (values.size() != s.specs.size())
    VOLA_THROW(InvalidArgument("voxel reducer: " + std::to_string(values.size()) + " attribute arrays for " +
                               std::to_string(s.specs.size()) + " attributes"));
  for (const auto& v : values)
    if (v.size() != ranks.size())
      VOLA_THROW(InvalidArgument("voxel reducer: an attribute array's length differs from the ranks'"));
  if (s.specs.empty()) return;
  for (const std::uint64_t r : ranks)
    if (r >= s.voxels)
      VOLA_THROW(InvalidArgument("voxel reducer: rank " + std::to_string(r) + " of " + std::to_string(s.voxels) +
                                 " voxels"));
  for (const std::uint64_t r : ranks) ++s.points[r];
  // Attribute by attribute, each a tight loop over the points.
  for (std::size_t a = 0; a < s.specs.size(); ++a) {
    const double* in = values[a].data();
    if (s.specs[a].reduction == Reduction::majority) {
      for (std::size_t i = 0; i < ranks.size(); ++i) s.majority[a].add(ranks[i], in[i]);
      continue;
    }
    double* partial = s.value[a].data();
    detail::with_reduction(s.specs[a].reduction, [&](auto r) {
      constexpr Reduction R = decltype(r)::value;
      for (std::size_t i = 0; i < ranks.size(); ++i) {
        double& p = partial[ranks[i]];
        p = detail::combine<R>(p, in[i]);
      }
    });
  }
}

void VoxelReducer::add(std::uint64_t rank, std::span<const double> values) {
  State& s = *state_;
  if (values.size() != s.specs.size())
    VOLA_THROW(InvalidArgument("voxel reducer: " + std::to_string(values.size()) + " values for " +
                               std::to_string(s.specs.size()) + " attributes"));
  constexpr std::size_t kBatch = 4096;  // points reduced at once: a batch stays in cache
  s.pending_values.resize(s.specs.size());
  s.pending_ranks.push_back(rank);
  for (std::size_t a = 0; a < values.size(); ++a) s.pending_values[a].push_back(values[a]);
  if (s.pending_ranks.size() == kBatch) flush_pending();
}

std::vector<AttributeColumn> VoxelReducer::finish() {
  flush_pending();
  State& s = *state_;
  std::vector<AttributeColumn> columns;
  for (std::size_t a = 0; a < s.specs.size(); ++a) {
    const AttributeSpec& spec = s.specs[a];
    AttributeColumn column(spec.name, spec.type, spec.reduction, s.voxels);
    if (spec.reduction == Reduction::majority) {
      MajorityPartial& m = s.majority[a];
      // The other values per voxel, in rank order, to compare with each first value.
      std::vector<std::pair<MajorityPartial::PairKey, std::uint32_t>> others(m.others.begin(), m.others.end());
      m.others = {};
      std::sort(others.begin(), others.end(), [](const auto& x, const auto& y) { return x.first.rank < y.first.rank; });
      std::size_t at = 0;
      for (std::uint64_t v = 0; v < s.voxels; ++v) {
        double best = m.first[v];
        std::uint32_t best_count = m.first_count[v];
        for (; at < others.size() && others[at].first.rank == v; ++at) {
          const double value = std::bit_cast<double>(others[at].first.bits);
          const std::uint32_t count = others[at].second;
          if (count > best_count || (count == best_count && detail::value_before(value, best)))
            best = value, best_count = count;
        }
        column.set(v, detail::canonical_value(best));  // 0 where no point came: first is 0
      }
      m = MajorityPartial{};
    } else {
      const std::vector<double>& partial = s.value[a];
      for (std::uint64_t v = 0; v < s.voxels; ++v)
        column.set(v, s.points[v] == 0 ? 0.0 : detail::finish(spec.reduction, partial[v], s.points[v]));
      s.value[a] = {};
    }
    columns.push_back(std::move(column));
  }
  s.points = {};
  s.pending_values = {};
  s.voxels = 0;
  return columns;
}

void VoxelReducer::finish_into(Tree& tree) {
  if (tree.voxel_count() != state_->voxels)
    VOLA_THROW(InvalidArgument("voxel reducer: " + std::to_string(state_->voxels) + " voxels reduced for a tree of " +
                               std::to_string(tree.voxel_count())));
  for (AttributeColumn& column : finish()) tree.attributes().add(std::move(column));
}

VOLA_INLINE_NAMESPACE_END
}  // namespace vola
