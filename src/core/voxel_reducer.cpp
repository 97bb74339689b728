// VoxelReducer: one row of partials per voxel (its point count, then one slot per
// attribute), so that a point updates one row, usually one cache line: with points in
// random order, a column per attribute cost a cache miss per attribute and point.
//
// Slots are as narrow as exactness allows. A column of integer type whose values are
// whole numbers in a small range keeps them as such: a mean sums values in [0, 65535]
// into 32 bits, with a table beside for the rare voxel whose sum carries past 2^32
// (the sum is exact and below 2^48, so as a double it equals the double sum of
// vola::build, which is exact too); max, min, last and majority keep a u8 or u16 for
// u8 and u16 columns whose values fit. Every other slot is a double. The first value
// that does not fit a narrow slot (a fraction, a negative number, NaN) turns that
// attribute's slots into doubles for all voxels before it is added, holding the same
// partials, so results never depend on which slots were narrow. A mean's first NaN (a
// point without a value, which the mean skips) widens its slots once more, to the sum
// and a count of such points.
#include "vola/voxel_reducer.hpp"

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstring>
#include <limits>
#include <new>
#include <unordered_map>

#if defined(__linux__)
#include <sys/mman.h>
#endif

#include "reductions.hpp"
#include "store_value.hpp"
#include "vola/error.hpp"
#include "vola/little_endian.hpp"
#include "vola/tree.hpp"

namespace vola {
VOLA_INLINE_NAMESPACE_BEGIN

namespace {

// How one attribute's partial is kept in a row.
enum class Slot : std::uint8_t {
  f64,          // double: the sum (mean), the value (max, min, last), the first value (majority)
  sum_u32,      // mean of whole numbers in [0, 65535]: the sum's low 32 bits (carries beside)
  small_u8,     // max, min, last, majority of whole numbers in [0, 255]
  small_u16,    // the same in [0, 65535]
  sum_f64_nans  // mean with points without a value: the sum (double), then how many were NaN (u32)
};

std::size_t slot_bytes(Slot s) noexcept {
  switch (s) {
    case Slot::sum_f64_nans:
      return 12;
    case Slot::f64: return 8;
    case Slot::sum_u32: return 4;
    case Slot::small_u16: return 2;
    default: return 1;
  }
}

// The narrow slot an attribute starts with (it may widen to f64 later).
Slot initial_slot(const AttributeSpec& spec) noexcept {
  const ValueType t = spec.type;
  const bool integer = t != ValueType::f32 && t != ValueType::f64;
  if (spec.reduction == Reduction::mean) return integer ? Slot::sum_u32 : Slot::f64;
  if (t == ValueType::u8) return Slot::small_u8;
  if (t == ValueType::u16) return Slot::small_u16;
  return Slot::f64;
}

// Whether every value is a whole number in [0, hi] (NaN is not).
bool all_whole(const double* v, std::size_t n, double hi) noexcept {
  bool ok = true;
  for (std::size_t i = 0; i < n; ++i) {
    const double x = v[i];
    const bool in = x >= 0.0 && x <= hi;
    ok &= in && static_cast<double>(static_cast<std::uint32_t>(in ? x : 0.0)) == x;
  }
  return ok;
}

bool any_nan(const double* v, std::size_t n) noexcept {
  bool nan = false;
  for (std::size_t i = 0; i < n; ++i) nan |= std::isnan(v[i]);
  return nan;
}

bool fits(Slot s, const double* v, std::size_t n) noexcept {
  switch (s) {
    case Slot::sum_u32:
    case Slot::small_u16: return all_whole(v, n, 65535.0);
    case Slot::small_u8: return all_whole(v, n, 255.0);
    default: return true;
  }
}

template <class T>
T load(const std::byte* p) noexcept {
  T v;
  std::memcpy(&v, p, sizeof v);
  return v;
}
template <class T>
void put(std::byte* p, T v) noexcept {
  std::memcpy(p, &v, sizeof v);
}

// Zeroed memory for the rows: fresh anonymous pages (zero without being written),
// advised as transparent huge pages where the system has them (a page fault per 4 KiB
// of a few hundred megabytes touched at random was a large part of the time, and the
// random row accesses miss the TLB far less), and released from the front while
// finish() reads them in order.
class RowMemory {
 public:
  static constexpr std::size_t kHuge = std::size_t{2} << 20;
  static constexpr std::size_t kMapped = std::size_t{32} << 20;  // rows at least this large are mapped
  RowMemory() = default;
  explicit RowMemory(std::size_t bytes) {
    if (bytes == 0) return;
#if defined(__linux__)
    if (bytes >= kMapped) {
      bytes_ = (bytes + kHuge - 1) / kHuge * kHuge;
      void* p = ::mmap(nullptr, bytes_ + kHuge, PROT_READ | PROT_WRITE, MAP_PRIVATE | MAP_ANONYMOUS, -1, 0);
      if (p == MAP_FAILED)
        VOLA_THROW(Error("voxel reducer: cannot map " + std::to_string(bytes_ >> 20) + " MiB for the voxels' partials"));
      map_ = static_cast<std::byte*>(p);
      mapped_ = true;
      // Start on a huge-page boundary; the pages before it are never touched.
      data_ = reinterpret_cast<std::byte*>((reinterpret_cast<std::uintptr_t>(map_) + kHuge - 1) / kHuge * kHuge);
#ifdef MADV_HUGEPAGE
      ::madvise(data_, bytes_, MADV_HUGEPAGE);
#endif
      return;
    }
#endif
    // Small rows (a tile's, an overview's): heap memory the allocator hands out again,
    // zeroed here, costs less than fresh pages faulted in one by one.
    bytes_ = bytes;
    map_ = static_cast<std::byte*>(::operator new(bytes_, std::align_val_t{64}));
    std::memset(map_, 0, bytes_);
    data_ = map_;
  }
  ~RowMemory() { reset(); }
  RowMemory(RowMemory&& o) noexcept { *this = std::move(o); }
  RowMemory& operator=(RowMemory&& o) noexcept {
    if (this != &o) {
      reset();
      std::swap(map_, o.map_);
      std::swap(data_, o.data_);
      std::swap(bytes_, o.bytes_);
      std::swap(released_, o.released_);
      std::swap(mapped_, o.mapped_);
    }
    return *this;
  }
  std::byte* data() const noexcept { return data_; }
  std::size_t resident_bound() const noexcept { return bytes_ - released_; }
  // The pages wholly before byte `end` are not read again: give them back.
  void release_before(std::size_t end) noexcept {
#if defined(__linux__)
    if (!mapped_) return;
    const std::size_t upto = end / kHuge * kHuge;
    if (upto > released_) {
      ::madvise(data_ + released_, upto - released_, MADV_DONTNEED);
      released_ = upto;
    }
#else
    (void)end;
#endif
  }
  void reset() noexcept {
    if (!map_) return;
#if defined(__linux__)
    if (mapped_) ::munmap(map_, bytes_ + kHuge);
    else ::operator delete(map_, std::align_val_t{64});
#else
    ::operator delete(map_, std::align_val_t{64});
#endif
    map_ = data_ = nullptr;
    bytes_ = released_ = 0;
    mapped_ = false;
  }

 private:
  std::byte* map_ = nullptr;
  std::byte* data_ = nullptr;
  std::size_t bytes_ = 0, released_ = 0;
  bool mapped_ = false;
};

struct PairKey {
  std::uint64_t rank, bits;
  bool operator==(const PairKey&) const = default;
};
struct PairHash {
  std::size_t operator()(const PairKey& k) const noexcept {
    return static_cast<std::size_t>((k.rank * 0x9E3779B97F4A7C15ull) ^ (k.bits * 0xC2B2AE3D27D4EB4Full));
  }
};

std::uint64_t bits_of(double v) noexcept {
  return std::isnan(v) ? 0x7FF8000000000000ull : std::bit_cast<std::uint64_t>(v == 0.0 ? 0.0 : v);  // -0 is 0
}

}  // namespace

// Row: the voxel's point count (u32) at offset 0, then each attribute's slot at its
// offset. Majority keeps the voxel's first value in the row and counts the values that
// differ from it in `others`, by (rank, value): memory follows distinct values per
// voxel, not points (most voxels hold one); the first value's count is the voxel's
// points minus the others'.
struct VoxelReducer::State {
  std::vector<AttributeSpec> specs;
  std::uint64_t voxels = 0;
  std::vector<Slot> slot;
  std::vector<std::size_t> offset;
  std::size_t stride = 0;
  RowMemory rows;
  std::vector<std::unordered_map<std::uint64_t, std::uint32_t>> carries;  // sum_u32: rank -> carries past 2^32
  std::vector<std::unordered_map<PairKey, std::uint32_t, PairHash>> others;  // majority
  // Points added one at a time, reduced in batches.
  std::vector<std::uint64_t> pending_ranks;
  std::vector<std::vector<double>> pending_values;
  // finish_range(): the voxels finished so far; majority's other values sorted by rank,
  // and per attribute the first of them not yet used.
  struct Other {
    std::uint64_t rank, bits;
    std::uint32_t count;
  };
  bool finishing = false;
  std::uint64_t finished = 0;
  std::vector<std::vector<Other>> sorted_others;
  std::vector<std::size_t> at;

  void layout() {
    // The count at offset 0, then the doubles (unaligned loads cost nothing extra on
    // x86-64), then the narrow slots, widest first.
    offset.assign(specs.size(), 0);
    std::size_t next = 4;
    for (const std::size_t width : {12, 8, 4, 2, 1})
      for (std::size_t a = 0; a < specs.size(); ++a)
        if (slot_bytes(slot[a]) == width) offset[a] = next, next += width;
    stride = next;
  }

  double slot_value(const std::byte* row, std::size_t a, std::uint64_t rank) const {
    switch (slot[a]) {
      case Slot::f64:
      case Slot::sum_f64_nans:
        return load<double>(row + offset[a]);
      case Slot::sum_u32: {
        std::uint64_t sum = load<std::uint32_t>(row + offset[a]);
        if (!carries[a].empty()) {
          const auto it = carries[a].find(rank);
          if (it != carries[a].end()) sum += std::uint64_t{it->second} << 32;
        }
        return static_cast<double>(sum);  // below 2^48: exact
      }
      case Slot::small_u16: return load<std::uint16_t>(row + offset[a]);
      default: return static_cast<double>(load<std::uint8_t>(row + offset[a]));
    }
  }

  // Attribute a's slots become `wider` (f64, or sum_f64_nans for a mean) holding the same
  // partials, no NaN counted yet (voxels without points keep zero bytes: their slots are
  // written before they are read).
  void widen(std::size_t a, Slot wider) {
    State next;
    next.specs = specs;
    next.voxels = voxels;
    next.slot = slot;
    next.slot[a] = wider;
    next.layout();
    next.rows = RowMemory(next.stride * voxels);
    for (std::uint64_t v = 0; v < voxels; ++v) {
      const std::byte* from = rows.data() + v * stride;
      std::byte* to = next.rows.data() + v * next.stride;
      const std::uint32_t count = load<std::uint32_t>(from);
      if (count == 0) continue;
      put(to, count);
      for (std::size_t b = 0; b < specs.size(); ++b) {
        if (b == a) {
          put(to + next.offset[b], slot_value(from, b, v));
          if (next.slot[b] == Slot::sum_f64_nans) put(to + next.offset[b] + 8, std::uint32_t{0});
        } else {
          std::memcpy(to + next.offset[b], from + offset[b], slot_bytes(slot[b]));
        }
      }
    }
    slot = std::move(next.slot);
    offset = std::move(next.offset);
    stride = next.stride;
    rows = std::move(next.rows);
    carries[a].clear();
  }
};

VoxelReducer::VoxelReducer(std::vector<AttributeSpec> specs, std::uint64_t voxels) : state_(std::make_unique<State>()) {
  State& s = *state_;
  s.specs = std::move(specs);
  s.voxels = voxels;
  if (s.specs.empty()) return;
  for (const AttributeSpec& spec : s.specs) s.slot.push_back(initial_slot(spec));
  s.layout();
  s.rows = RowMemory(s.stride * voxels);
  s.carries.resize(s.specs.size());
  s.others.resize(s.specs.size());
}
VoxelReducer::~VoxelReducer() = default;
VoxelReducer::VoxelReducer(VoxelReducer&&) noexcept = default;
VoxelReducer& VoxelReducer::operator=(VoxelReducer&&) noexcept = default;

std::uint64_t VoxelReducer::voxels() const noexcept { return state_->voxels; }

std::size_t VoxelReducer::memory_bytes() const noexcept {
  const State& s = *state_;
  std::size_t bytes = s.rows.resident_bound();
  for (const auto& c : s.carries) bytes += c.size() * 32 + c.bucket_count() * 8;
  for (const auto& m : s.others) bytes += m.size() * 40 + m.bucket_count() * 8;
  return bytes;
}

namespace {

// One point's update of one slot; `first`: the voxel had no point before.
template <Reduction R>
inline void update_f64(std::byte* p, double v, bool first) noexcept {
  if (first) return put(p, v);
  put(p, detail::combine<R>(load<double>(p), v));
}

template <class T, Reduction R, class V>
inline void update_small(std::byte* p, V v, bool first) noexcept {
  const T x = static_cast<T>(v);
  if (first) return put(p, x);
  const T old = load<T>(p);
  if constexpr (R == Reduction::max) put(p, std::max(old, x));
  else if constexpr (R == Reduction::min) put(p, std::min(old, x));
  else put(p, x);  // last
}

// A narrow majority slot holds the voxel's first value; a point with another value is
// counted in `others` by (rank, value).
template <class T, class V, class Others>
inline void update_majority(std::byte* p, V v, bool first, Others& others, std::uint64_t rank) {
  const T x = static_cast<T>(v);
  if (first) put(p, x);
  else if (load<T>(p) != x) ++others[PairKey{rank, bits_of(static_cast<double>(v))}];
}

// What one attribute does per point, resolved once per call.
enum class Op : std::uint8_t {
  f64_mean,
  f64_max,
  f64_min,
  f64_last,
  f64_majority,
  f64_mean_nans,
  u32_sum,
  u8_max,
  u8_min,
  u8_last,
  u8_majority,
  u16_max,
  u16_min,
  u16_last,
  u16_majority
};

Op op_of(Slot s, Reduction r) noexcept {
  const int k = r == Reduction::max ? 1 : r == Reduction::min ? 2 : r == Reduction::last ? 3 : r == Reduction::majority ? 4 : 0;
  switch (s) {
    case Slot::f64: return static_cast<Op>(static_cast<int>(Op::f64_mean) + k);
    case Slot::sum_f64_nans:
      return Op::f64_mean_nans;
    case Slot::sum_u32: return Op::u32_sum;
    case Slot::small_u8: return static_cast<Op>(static_cast<int>(Op::u8_max) + k - 1);
    default: return static_cast<Op>(static_cast<int>(Op::u16_max) + k - 1);
  }
}

// One point's value v folded into its slot p of voxel `rank`'s row; `others` and
// `carries` are the attribute's majority counts and sum carries.
template <class Others, class Carries>
inline void fold(Op op, std::byte* p, double v, bool first, std::uint64_t rank, Others& others, Carries& carries) {
  switch (op) {
    case Op::f64_mean: update_f64<Reduction::mean>(p, v, first); break;
    case Op::f64_max: update_f64<Reduction::max>(p, v, first); break;
    case Op::f64_min: update_f64<Reduction::min>(p, v, first); break;
    case Op::f64_last: put(p, v); break;
    case Op::f64_mean_nans: {
      const std::uint32_t nan = std::isnan(v) ? 1 : 0;
      const double x = detail::mean_summand(v);
      if (first)
        put(p, x), put(p + 8, nan);
      else
        put(p, load<double>(p) + x), put(p + 8, load<std::uint32_t>(p + 8) + nan);
      break;
    }
    case Op::f64_majority: {
      if (first) put(p, v);
      else if (const double f = load<double>(p); !detail::same_value(f, v)) ++others[PairKey{rank, bits_of(v)}];
      break;
    }
    case Op::u32_sum: {
      const std::uint32_t x = static_cast<std::uint32_t>(v);
      if (first) {
        put(p, x);
      } else {
        const std::uint32_t old = load<std::uint32_t>(p), sum = old + x;
        put(p, sum);
        if (sum < old) ++carries[rank];
      }
      break;
    }
    case Op::u8_max: update_small<std::uint8_t, Reduction::max>(p, v, first); break;
    case Op::u8_min: update_small<std::uint8_t, Reduction::min>(p, v, first); break;
    case Op::u8_last: update_small<std::uint8_t, Reduction::last>(p, v, first); break;
    case Op::u8_majority: update_majority<std::uint8_t>(p, v, first, others, rank); break;
    case Op::u16_max: update_small<std::uint16_t, Reduction::max>(p, v, first); break;
    case Op::u16_min: update_small<std::uint16_t, Reduction::min>(p, v, first); break;
    case Op::u16_last: update_small<std::uint16_t, Reduction::last>(p, v, first); break;
    case Op::u16_majority: update_majority<std::uint16_t>(p, v, first, others, rank); break;
  }
}

}  // namespace

void VoxelReducer::add(std::span<const std::uint64_t> ranks, std::span<const std::span<const double>> values) {
  flush_pending();
  add_now(ranks, values);
}

void VoxelReducer::flush_pending() {
  State& s = *state_;
  if (s.pending_ranks.empty()) return;
  const std::vector<std::span<const double>> values(s.pending_values.begin(), s.pending_values.end());
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
  check_ranks(ranks);
  // A value a narrow slot cannot hold widens the attribute first (before any count of
  // this call is taken, so the widened partials are those of the earlier points), and a
  // mean's first NaN widens it to count them.
  for (std::size_t a = 0; a < s.specs.size(); ++a) {
    if (s.specs[a].reduction == Reduction::mean && s.slot[a] != Slot::sum_f64_nans &&
        any_nan(values[a].data(), ranks.size()))
      s.widen(a, Slot::sum_f64_nans);
    else if (s.slot[a] != Slot::f64 && s.slot[a] != Slot::sum_f64_nans &&
             !fits(s.slot[a], values[a].data(), ranks.size()))
      s.widen(a, Slot::f64);
  }

  struct Column {
    Op op;
    std::uint32_t offset;
    const double* in;
  };
  Column columns[64];
  std::vector<Column> many;
  Column* cols = columns;
  const std::size_t na = s.specs.size();
  if (na > 64) {
    many.resize(na);
    cols = many.data();
  }
  for (std::size_t a = 0; a < na; ++a)
    cols[a] = {op_of(s.slot[a], s.specs[a].reduction), static_cast<std::uint32_t>(s.offset[a]), values[a].data()};

  std::byte* const base = s.rows.data();
  const std::size_t stride = s.stride, n = ranks.size();
  constexpr std::size_t kAhead = 12;  // rows requested this many points ahead
  for (std::size_t i = 0; i < std::min(n, kAhead); ++i) {
    __builtin_prefetch(base + ranks[i] * stride, 1);
    __builtin_prefetch(base + ranks[i] * stride + stride - 1, 1);
  }
  for (std::size_t i = 0; i < n; ++i) {
    if (i + kAhead < n) {
      const std::byte* ahead = base + ranks[i + kAhead] * stride;
      __builtin_prefetch(ahead, 1);
      __builtin_prefetch(ahead + stride - 1, 1);
    }
    const std::uint64_t rank = ranks[i];
    std::byte* row = base + rank * stride;
    const std::uint32_t count = load<std::uint32_t>(row);
    const bool first = count == 0;
    for (std::size_t a = 0; a < na; ++a) {
      const Column& c = cols[a];
      std::byte* p = row + c.offset;
      fold(c.op, p, c.in[i], first, rank, s.others[a], s.carries[a]);
    }
    put(row, count + 1);
  }
}

void VoxelReducer::check_ranks(std::span<const std::uint64_t> ranks) const {
  const State& s = *state_;
  if (s.finishing) VOLA_THROW(InvalidArgument("voxel reducer: points added after finish_range()"));
  std::uint64_t highest = 0;
  for (const std::uint64_t r : ranks) highest = std::max(highest, r);
  if (!ranks.empty() && highest >= s.voxels)
    VOLA_THROW(InvalidArgument("voxel reducer: rank " + std::to_string(highest) + " of " + std::to_string(s.voxels) +
                               " voxels"));
}

namespace {

using Kind = RecordField::Kind;

// The raw bits of an unsigned field, shifted and masked.
inline std::uint64_t field_bits(const RecordField& f, const std::uint8_t* p) noexcept {
  std::uint64_t x;
  switch (f.kind) {
    case Kind::u8: x = p[0]; break;
    case Kind::u16: x = load_le<std::uint16_t>(p); break;
    case Kind::u32: x = load_le<std::uint32_t>(p); break;
    default: x = load_le<std::uint64_t>(p); break;
  }
  return (x >> f.shift) & f.mask;
}

// A field's value as las::extra_value and the LAS reader decode it: load, x * scale + add.
inline double field_value(const RecordField& f, const std::uint8_t* p) noexcept {
  double x;
  switch (f.kind) {
    case Kind::u8: case Kind::u16: case Kind::u32: case Kind::u64: x = static_cast<double>(field_bits(f, p)); break;
    case Kind::i8: x = load_le<std::int8_t>(p); break;
    case Kind::i16: x = load_le<std::int16_t>(p); break;
    case Kind::i32: x = load_le<std::int32_t>(p); break;
    case Kind::i64: x = static_cast<double>(load_le<std::int64_t>(p)); break;
    case Kind::f32: x = load_le<float>(p); break;
    default: x = load_le<double>(p); break;
  }
  if (f.has_no_data && x == f.no_data) return std::numeric_limits<double>::quiet_NaN();
  return f.scaled ? x * f.scale + f.add : x;
}

// Whether a field's decoded value can be NaN: a float, a no_data value, or a scale or
// offset that is not a finite number.
bool may_be_nan(const RecordField& f) noexcept {
  return f.kind == Kind::f32 || f.kind == Kind::f64 || f.has_no_data ||
         (f.scaled && (!std::isfinite(f.scale) || !std::isfinite(f.add)));
}

// The largest value of a field that is a whole number in a known range (u8 or u16, no
// scale or offset), or -1.
double whole_field_max(const RecordField& f) noexcept {
  if ((f.kind != Kind::u8 && f.kind != Kind::u16) || (f.scaled && (f.scale != 1.0 || f.add != 0.0)) || f.shift >= 16 ||
      f.has_no_data)
    return -1.0;
  const std::uint64_t top = (f.kind == Kind::u8 ? 255u : 65535u) >> f.shift;
  return static_cast<double>(std::min<std::uint64_t>(top, f.mask));
}

}  // namespace

void VoxelReducer::add_records(std::span<const std::uint64_t> ranks, const std::uint8_t* records, std::size_t stride,
                               std::span<const std::uint32_t> index, std::span<const RecordField> fields) {
  std::vector<FieldColumn> columns;
  for (const RecordField& f : fields) columns.push_back({records, stride, f});
  add_fields(ranks, index, columns);
}

void VoxelReducer::add_columns(std::span<const std::uint64_t> ranks, std::span<const FieldColumn> columns) {
  add_fields(ranks, {}, columns);
}

void VoxelReducer::add_fields(std::span<const std::uint64_t> ranks, std::span<const std::uint32_t> index,
                              std::span<const FieldColumn> columns) {
  flush_pending();
  State& s = *state_;
  const std::size_t na = s.specs.size(), n = ranks.size();
  if (columns.size() != na)
    VOLA_THROW(InvalidArgument("voxel reducer: " + std::to_string(columns.size()) + " record fields for " +
                               std::to_string(na) + " attributes"));
  if (!index.empty() && index.size() != n)
    VOLA_THROW(InvalidArgument("voxel reducer: the record index's length differs from the ranks'"));
  if (na == 0 || n == 0) return;
  check_ranks(ranks);
  const auto at = [&](std::size_t i) { return index.empty() ? i : std::size_t{index[i]}; };
  const auto record_of = [&](const FieldColumn& c, std::size_t i) { return c.data + at(i) * c.stride; };
  std::vector<RecordField> fields;
  for (const FieldColumn& c : columns) fields.push_back(c.field);
  // A narrow slot takes a whole-number field whose range it holds as is; any other field
  // is checked value by value first (and widens the slot as add() would), and so is a
  // mean's field that can be NaN, whose first NaN widens it to count them.
  std::vector<double> check;
  for (std::size_t a = 0; a < na; ++a) {
    const bool narrow = s.slot[a] != Slot::f64 && s.slot[a] != Slot::sum_f64_nans;
    const double top = whole_field_max(fields[a]);
    const double hi = s.slot[a] == Slot::small_u8 ? 255.0 : 65535.0;
    const bool narrow_unsure = narrow && !(top >= 0.0 && top <= hi);
    const bool nan_unsure =
        s.specs[a].reduction == Reduction::mean && s.slot[a] != Slot::sum_f64_nans && may_be_nan(fields[a]);
    if (!narrow_unsure && !nan_unsure) continue;
    check.resize(n);
    for (std::size_t i = 0; i < n; ++i) check[i] = field_value(fields[a], record_of(columns[a], i) + fields[a].offset);
    if (nan_unsure && any_nan(check.data(), n))
      s.widen(a, Slot::sum_f64_nans);
    else if (narrow_unsure && !fits(s.slot[a], check.data(), n))
      s.widen(a, Slot::f64);
  }

  // Per attribute, what a point does: whole-number fields into narrow slots fold as
  // integers; every other field is decoded to a double first.
  struct Column {
    Op op;
    bool whole;
    std::uint32_t row;
    RecordField field;
    const std::uint8_t* data;  // + the field's offset
    std::size_t stride;
  };
  std::vector<Column> cols(na);
  for (std::size_t a = 0; a < na; ++a) {
    RecordField f = fields[a];
    const std::uint8_t* data = columns[a].data + f.offset;
    f.offset = 0;
    const bool narrow = s.slot[a] != Slot::f64 && s.slot[a] != Slot::sum_f64_nans;
    cols[a] = {op_of(s.slot[a], s.specs[a].reduction),
               narrow && whole_field_max(f) >= 0.0,
               static_cast<std::uint32_t>(s.offset[a]),
               f,
               data,
               columns[a].stride};
  }

  std::byte* const base = s.rows.data();
  const std::size_t row_stride = s.stride;
  constexpr std::size_t kAhead = 12;  // rows requested this many points ahead
  for (std::size_t i = 0; i < std::min(n, kAhead); ++i) {
    __builtin_prefetch(base + ranks[i] * row_stride, 1);
    __builtin_prefetch(base + ranks[i] * row_stride + row_stride - 1, 1);
  }
  for (std::size_t i = 0; i < n; ++i) {
    if (i + kAhead < n) {
      const std::byte* ahead = base + ranks[i + kAhead] * row_stride;
      __builtin_prefetch(ahead, 1);
      __builtin_prefetch(ahead + row_stride - 1, 1);
    }
    const std::uint64_t rank = ranks[i];
    const std::size_t point = at(i);
    std::byte* row = base + rank * row_stride;
    const std::uint32_t count = load<std::uint32_t>(row);
    const bool first = count == 0;
    for (std::size_t a = 0; a < na; ++a) {
      const Column& c = cols[a];
      std::byte* p = row + c.row;
      if (c.whole) {
        const auto x = static_cast<std::uint32_t>(field_bits(c.field, c.data + point * c.stride));
        switch (c.op) {
          case Op::u32_sum: {
            if (first) {
              put(p, x);
            } else {
              const std::uint32_t old = load<std::uint32_t>(p), sum = old + x;
              put(p, sum);
              if (sum < old) ++s.carries[a][rank];
            }
            break;
          }
          case Op::u8_max: update_small<std::uint8_t, Reduction::max>(p, x, first); break;
          case Op::u8_min: update_small<std::uint8_t, Reduction::min>(p, x, first); break;
          case Op::u8_last: update_small<std::uint8_t, Reduction::last>(p, x, first); break;
          case Op::u8_majority: update_majority<std::uint8_t>(p, x, first, s.others[a], rank); break;
          case Op::u16_max: update_small<std::uint16_t, Reduction::max>(p, x, first); break;
          case Op::u16_min: update_small<std::uint16_t, Reduction::min>(p, x, first); break;
          case Op::u16_last: update_small<std::uint16_t, Reduction::last>(p, x, first); break;
          case Op::u16_majority: update_majority<std::uint16_t>(p, x, first, s.others[a], rank); break;
          default: break;  // (whole fields go to narrow slots only)
        }
        continue;
      }
      fold(c.op, p, field_value(c.field, c.data + point * c.stride), first, rank, s.others[a], s.carries[a]);
    }
    put(row, count + 1);
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

void VoxelReducer::finish_range(std::uint64_t first, std::uint64_t last, std::span<std::byte* const> out) {
  State& s = *state_;
  const std::size_t na = s.specs.size();
  if (out.size() != na)
    VOLA_THROW(InvalidArgument("voxel reducer: " + std::to_string(out.size()) + " columns for " +
                               std::to_string(na) + " attributes"));
  if (first < s.finished || first > last || last > s.voxels)
    VOLA_THROW(InvalidArgument("voxel reducer: voxels [" + std::to_string(first) + ", " + std::to_string(last) +
                               ") to finish after " + std::to_string(s.finished) + " of " + std::to_string(s.voxels)));
  if (!s.finishing) {
    flush_pending();
    // Majority: the other values per voxel, in rank order, to compare with each first value.
    s.sorted_others.assign(na, {});
    s.at.assign(na, 0);
    for (std::size_t a = 0; a < na; ++a) {
      auto& o = s.sorted_others[a];
      o.reserve(s.others[a].size());
      for (const auto& [key, count] : s.others[a]) o.push_back({key.rank, key.bits, count});
      s.others[a] = {};
      std::sort(o.begin(), o.end(), [](const State::Other& x, const State::Other& y) { return x.rank < y.rank; });
    }
    s.finishing = true;
  }
  for (std::size_t a = 0; a < na; ++a) {
    const AttributeSpec& spec = s.specs[a];
    detail::with_value_type(spec.type, [&](auto zero) {
      using T = decltype(zero);
      std::byte* const to = out[a];
      const std::vector<State::Other>& o = s.sorted_others[a];
      std::size_t k = s.at[a];
      while (k < o.size() && o[k].rank < first) ++k;  // voxels skipped over
      if (spec.reduction != Reduction::majority) {
        // The slot's kind and the reduction resolved once for the range, not per voxel.
        const std::byte* rows = s.rows.data() + s.offset[a];
        const std::size_t stride = s.stride;
        const Reduction r = spec.reduction;
        const auto run = [&](auto partial_of) {
          for (std::uint64_t v = first; v < last; ++v) {
            const std::byte* slot = rows + v * stride;
            const std::uint32_t count = load<std::uint32_t>(slot - s.offset[a]);
            const double value = count == 0 ? 0.0 : detail::finish(r, partial_of(slot, v), count);
            detail::store_as<T>(to + (v - first) * sizeof(T), value);
          }
        };
        switch (s.slot[a]) {
          case Slot::f64: run([](const std::byte* p, std::uint64_t) { return load<double>(p); }); break;
          case Slot::sum_f64_nans:  // the sum over the points with a value
            for (std::uint64_t v = first; v < last; ++v) {
              const std::byte* slot = rows + v * stride;
              const std::uint32_t count = load<std::uint32_t>(slot - s.offset[a]);
              const double value =
                  count == 0 ? 0.0 : detail::finish(r, load<double>(slot), count - load<std::uint32_t>(slot + 8));
              detail::store_as<T>(to + (v - first) * sizeof(T), value);
            }
            break;
          case Slot::sum_u32:
            if (s.carries[a].empty())
              run([](const std::byte* p, std::uint64_t) { return static_cast<double>(load<std::uint32_t>(p)); });
            else
              run([&](const std::byte* p, std::uint64_t v) { return s.slot_value(p - s.offset[a], a, v); });
            break;
          case Slot::small_u16:
            run([](const std::byte* p, std::uint64_t) { return static_cast<double>(load<std::uint16_t>(p)); });
            break;
          default: run([](const std::byte* p, std::uint64_t) { return static_cast<double>(load<std::uint8_t>(p)); });
        }
        s.at[a] = k;
        return;
      }
      for (std::uint64_t v = first; v < last; ++v) {
        const std::byte* row = s.rows.data() + v * s.stride;
        const std::uint32_t count = load<std::uint32_t>(row);
        double value = 0.0;  // where no point came
        if (count != 0) {
          const double partial = s.slot_value(row, a, v);
          if (spec.reduction == Reduction::majority) {
            double best = partial;
            std::uint32_t best_count = count;
            for (std::size_t j = k; j < o.size() && o[j].rank == v; ++j) best_count -= o[j].count;
            for (; k < o.size() && o[k].rank == v; ++k) {
              const double x = std::bit_cast<double>(o[k].bits);
              if (o[k].count > best_count || (o[k].count == best_count && detail::value_before(x, best)))
                best = x, best_count = o[k].count;
            }
            value = detail::canonical_value(best);
          } else {
            value = detail::finish(spec.reduction, partial, count);
          }
        }
        detail::store_as<T>(to + (v - first) * sizeof(T), value);
      }
      s.at[a] = k;
    });
  }
  s.finished = last;
  s.rows.release_before(static_cast<std::size_t>(last) * s.stride);
}

std::vector<AttributeColumn> VoxelReducer::finish() {
  State& s = *state_;
  const std::size_t na = s.specs.size();
  // Column bytes grow as the rows are read in order, and the rows read are released:
  // the partials and the columns are not both whole in memory at once.
  std::vector<std::vector<std::byte>> bytes(na);
  for (std::size_t a = 0; a < na; ++a) bytes[a].reserve(static_cast<std::size_t>(s.voxels) * size_of(s.specs[a].type));  // address space only
  std::vector<std::byte*> to(na);
  constexpr std::uint64_t kBlock = 1 << 16;
  for (std::uint64_t first = s.finished; first < s.voxels; first += kBlock) {
    const std::uint64_t last = std::min(s.voxels, first + kBlock);
    for (std::size_t a = 0; a < na; ++a) {
      const std::size_t size = size_of(s.specs[a].type);
      bytes[a].resize(static_cast<std::size_t>(last) * size);
      to[a] = bytes[a].data() + first * size;
    }
    finish_range(first, last, to);
  }
  std::vector<AttributeColumn> columns;
  for (std::size_t a = 0; a < na; ++a)
    columns.emplace_back(s.specs[a].name, s.specs[a].type, s.specs[a].reduction, std::move(bytes[a]));
  s.rows.reset();
  s.carries.assign(na, {});
  s.sorted_others.assign(na, {});
  s.voxels = 0;
  s.finished = 0;
  s.finishing = false;
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
