#include "column_codec.hpp"

#include <bit>
#include <cmath>
#include <cstring>
#include <optional>

#include "bytes.hpp"
#include "codec.hpp"
#include "vola/error.hpp"

namespace vola {
VOLA_INLINE_NAMESPACE_BEGIN
namespace detail {

namespace {

constexpr std::uint64_t zigzag(std::uint64_t v) noexcept {
  return (v << 1) ^ (std::uint64_t{0} - (v >> 63));
}
constexpr std::uint64_t unzigzag(std::uint64_t u) noexcept { return (u >> 1) ^ (std::uint64_t{0} - (u & 1u)); }

// Value i of a column of `width`-byte values, as an unsigned integer.
std::uint64_t load(const std::byte* bytes, std::size_t i, unsigned width) noexcept {
  std::uint64_t v = 0;
  std::memcpy(&v, bytes + i * width, width);
  return v;
}
// `v` modulo 2^(8 width), as a signed number of that width, sign-extended: the difference
// of two width-byte values is then small when they are close (either way round), and
// zig-zags into `width` bytes.
std::uint64_t sign_extend(std::uint64_t v, unsigned width) noexcept {
  const unsigned shift = 64 - 8 * width;
  return shift ? static_cast<std::uint64_t>(static_cast<std::int64_t>(v << shift) >> shift) : v;
}
void store(std::byte* bytes, std::size_t i, unsigned width, std::uint64_t v) noexcept {
  std::memcpy(bytes + i * width, &v, width);
}

// Byte planes of `values` (each `width` bytes wide): all lowest bytes, then the next ones...
void put_planes(std::span<const std::uint64_t> values, unsigned width, std::uint8_t* out) {
  const std::size_t n = values.size();
  for (unsigned k = 0; k < width; ++k)
    for (std::size_t i = 0; i < n; ++i) out[k * n + i] = static_cast<std::uint8_t>(values[i] >> (8 * k));
}
std::uint64_t get_plane_value(const std::uint8_t* planes, std::size_t n, std::size_t i, unsigned width) noexcept {
  std::uint64_t v = 0;
  for (unsigned k = 0; k < width; ++k) v |= std::uint64_t{planes[k * n + i]} << (8 * k);
  return v;
}

bool is_float(ValueType t) noexcept { return t == ValueType::f32 || t == ValueType::f64; }

// The float as `T` that the integer k stands for at quantum q: what decoding computes.
template <class T>
T dequantize(std::int64_t k, double q) noexcept {
  return static_cast<T>(static_cast<double>(k) * q);
}

// The integer a corner (or any double) is predicted as at quantum q; 0 when out of range.
std::int64_t quantize_base(double value, double q) noexcept {
  const double t = value / q;
  return std::isfinite(t) && std::fabs(t) < 4.0e18 ? std::llround(t) : 0;
}

// The integer k with dequantize(k, q) bit-identical to the value, if there is one.
template <class T>
bool quantize(T value, double q, std::int64_t& k) noexcept {
  const double t = static_cast<double>(value) / q;
  if (!(std::fabs(t) < 9.0e15)) return false;  // NaN and infinities too
  k = std::llround(t);
  const T back = dequantize<T>(k, q);
  return std::memcmp(&back, &value, sizeof(T)) == 0;
}

constexpr double kQuanta[] = {1.0, 0.1, 0.01, 0.001, 1e-4, 1e-5, 1e-6};
constexpr unsigned kPredictPrevious = 3;  // axis value: predict from the previous integer

struct QuantizedPlan {
  double q = 0;
  unsigned axis = kPredictPrevious;
  double estimated_bits = 0;
};

// Residuals of the quantized coding (exceptions get residual 0 and go to `exceptions`).
template <class T>
void quantized_residuals(std::span<const std::byte> bytes, double q, unsigned axis, std::span<const double> corners,
                         std::vector<std::uint64_t>& residuals, std::vector<std::uint64_t>& exceptions) {
  const std::size_t n = bytes.size() / sizeof(T);
  residuals.assign(n, 0);
  exceptions.clear();
  std::int64_t previous = 0;
  for (std::size_t i = 0; i < n; ++i) {
    T v;
    std::memcpy(&v, bytes.data() + i * sizeof(T), sizeof(T));
    std::int64_t k;
    if (!quantize(v, q, k)) {
      exceptions.push_back(i);
      continue;
    }
    const std::int64_t base = axis == kPredictPrevious ? previous : quantize_base(corners[i], q);
    residuals[i] = zigzag(static_cast<std::uint64_t>(k) - static_cast<std::uint64_t>(base));
    previous = k;
  }
}

// The quantum: the coarsest one that at most 1% of the values miss (the grid the data
// lives on: a finer one only spreads the same values over more bits, which zstd's byte
// planes pay for), else the one fewest miss. Then the predictor with the smallest
// estimate: order-0 entropy of the residuals below 4096, the bits of the others and of
// the exceptions.
template <class T>
QuantizedPlan plan_quantized(std::span<const std::byte> bytes, VoxelCorners& corners) {
  std::vector<std::uint64_t> residuals, exceptions;
  const std::size_t n = bytes.size() / sizeof(T);
  double q = kQuanta[0];
  std::size_t fewest = n + 1;
  for (double candidate : kQuanta) {
    quantized_residuals<T>(bytes, candidate, kPredictPrevious, {}, residuals, exceptions);
    if (exceptions.size() < fewest) {
      fewest = exceptions.size();
      q = candidate;
    }
    if (exceptions.size() * 100 <= n) {
      q = candidate;
      break;
    }
  }
  QuantizedPlan best;
  best.q = q;
  best.estimated_bits = HUGE_VAL;
  std::vector<std::uint32_t> counts(4096);
  for (unsigned axis = 0; axis <= kPredictPrevious; ++axis) {
    quantized_residuals<T>(bytes, q, axis, axis < 3 ? corners.along(axis) : std::span<const double>(), residuals,
                           exceptions);
    double bits = 8.0 * static_cast<double>(exceptions.size()) * (sizeof(T) + 8);
    std::fill(counts.begin(), counts.end(), 0u);
    std::size_t small = 0;
    for (std::uint64_t r : residuals) {
      if (r < 4096) {
        ++counts[r];
        ++small;
      } else {
        bits += 12.0 + static_cast<double>(std::bit_width(r));
      }
    }
    for (std::uint32_t count : counts)
      if (count) bits -= count * std::log2(static_cast<double>(count) / static_cast<double>(small));
    if (bits < best.estimated_bits) best = {q, axis, bits};
  }
  return best;
}

template <class T>
std::vector<std::uint8_t> encode_quantized(const AttributeColumn& column, VoxelCorners& corners, int level) {
  const auto bytes = column.bytes();
  const QuantizedPlan plan = plan_quantized<T>(bytes, corners);
  std::vector<std::uint64_t> residuals, exceptions;
  quantized_residuals<T>(bytes, plan.q, plan.axis,
                         plan.axis < 3 ? corners.along(plan.axis) : std::span<const double>(), residuals, exceptions);
  std::uint64_t widest = 0;
  for (std::uint64_t r : residuals) widest |= r;
  const unsigned width = std::max(1u, static_cast<unsigned>((std::bit_width(widest) + 7) / 8));
  const std::size_t n = residuals.size();
  std::vector<std::uint8_t> raw(n * width + exceptions.size() * (8 + sizeof(T)));
  put_planes(residuals, width, raw.data());
  std::uint8_t* at = raw.data() + n * width;
  for (std::uint64_t i : exceptions) {
    std::memcpy(at, &i, 8);
    at += 8;
  }
  for (std::uint64_t i : exceptions) {
    std::memcpy(at, bytes.data() + i * sizeof(T), sizeof(T));
    at += sizeof(T);
  }
  std::vector<std::uint8_t> out;
  ByteWriter w(out);
  w.put(plan.q);
  w.put(static_cast<std::uint8_t>(plan.axis));
  w.put(static_cast<std::uint8_t>(width));
  for (int i = 0; i < 6; ++i) w.put(std::uint8_t{0});
  w.put(static_cast<std::uint64_t>(exceptions.size()));
  w.put_bytes(zstd_compress(raw, level));
  return out;
}

template <class T>
void decode_quantized(ByteReader& r, AttributeColumn& column, VoxelCorners& corners, const std::string& name) {
  const std::uint64_t start = r.offset();
  const auto q = r.get<double>("quantum");
  const auto axis = r.get<std::uint8_t>("predictor axis");
  const auto width = r.get<std::uint8_t>("residual width");
  r.take(6, "reserved");
  const auto exception_count = r.get<std::uint64_t>("exception count");
  if (!(q > 0.0) || !std::isfinite(q)) r.fail_at(start, "the quantum is not a positive finite number");
  if (axis > kPredictPrevious) r.fail_at(start + 8, "unknown predictor " + std::to_string(axis));
  if (width < 1 || width > 8) r.fail_at(start + 9, "residual width " + std::to_string(width) + " is not 1..8");
  const std::size_t n = column.size();
  if (exception_count > n)
    r.fail_at(start + 16, std::to_string(exception_count) + " exceptions for " + std::to_string(n) + " values");
  const std::uint64_t raw_size = n * width + exception_count * (8 + sizeof(T));
  const std::uint64_t frame_at = r.offset();
  const auto frame = r.take(r.remaining(), "quantized values");
  if (raw_size > frame.size() * 8192 + (1u << 20))
    r.fail_at(frame_at, "quantized values claim " + std::to_string(raw_size) + " bytes from " +
                            std::to_string(frame.size()) + " compressed bytes, more than any real data compresses");
  const auto raw = zstd_decompress(frame, raw_size, name, frame_at);
  const std::uint8_t* exceptions = raw.data() + n * width;
  const std::uint8_t* exception_values = exceptions + 8 * exception_count;
  const auto c = axis < 3 ? corners.along(axis) : std::span<const double>();
  std::byte* out = column.bytes().data();
  std::int64_t previous = 0;
  std::uint64_t next_exception = 0, next_exception_rank = n;
  auto load_exception_rank = [&] {
    if (next_exception == exception_count) {
      next_exception_rank = n;
      return;
    }
    std::uint64_t rank;
    std::memcpy(&rank, exceptions + 8 * next_exception, 8);
    if (rank >= n || (next_exception > 0 && rank <= next_exception_rank))
      r.fail_at(frame_at, "exception ranks are not increasing ranks of the column");
    next_exception_rank = rank;
  };
  load_exception_rank();
  for (std::size_t i = 0; i < n; ++i) {
    if (i == next_exception_rank) {
      std::memcpy(out + i * sizeof(T), exception_values + sizeof(T) * next_exception, sizeof(T));
      ++next_exception;
      load_exception_rank();
      continue;
    }
    const std::int64_t base = axis == kPredictPrevious ? previous : quantize_base(c[i], q);
    const std::int64_t k =
        static_cast<std::int64_t>(static_cast<std::uint64_t>(base) + unzigzag(get_plane_value(raw.data(), n, i, width)));
    const T v = dequantize<T>(k, q);
    std::memcpy(out + i * sizeof(T), &v, sizeof(T));
    previous = k;
  }
  if (next_exception != exception_count)
    r.fail_at(frame_at, "exception ranks are not increasing ranks of the column");
}

std::vector<std::uint8_t> encode_delta_planes(const AttributeColumn& column, int level) {
  const unsigned width = static_cast<unsigned>(size_of(column.type()));
  const std::size_t n = column.size();
  std::vector<std::uint64_t> residuals(n);
  std::uint64_t previous = 0;
  for (std::size_t i = 0; i < n; ++i) {
    const std::uint64_t v = load(column.bytes().data(), i, width);
    residuals[i] = zigzag(sign_extend(v - previous, width));
    previous = v;
  }
  std::vector<std::uint8_t> raw(n * width);
  put_planes(residuals, width, raw.data());
  return zstd_compress(raw, level);
}

void decode_delta_planes(std::span<const std::uint8_t> data, AttributeColumn& column, const std::string& name,
                         std::uint64_t offset) {
  const unsigned width = static_cast<unsigned>(size_of(column.type()));
  const std::size_t n = column.size();
  const auto raw = zstd_decompress(data, static_cast<std::uint64_t>(n) * width, name, offset);
  std::uint64_t previous = 0;
  std::byte* out = column.bytes().data();
  for (std::size_t i = 0; i < n; ++i) {
    previous += unzigzag(get_plane_value(raw.data(), n, i, width));
    store(out, i, width, previous);
  }
}

// Encoding 4: each value's step from the previous one minus the partner column's step at
// the same rank (green's step predicted by red's, as LAZ predicts colour channels), then
// as encoding 2.
std::vector<std::uint64_t> partner_residuals(const AttributeColumn& column, const AttributeColumn& partner) {
  const unsigned width = static_cast<unsigned>(size_of(column.type()));
  const std::size_t n = column.size();
  std::vector<std::uint64_t> residuals(n);
  std::uint64_t previous = 0, partner_previous = 0;
  for (std::size_t i = 0; i < n; ++i) {
    const std::uint64_t v = load(column.bytes().data(), i, width);
    const std::uint64_t p = load(partner.bytes().data(), i, width);
    residuals[i] = zigzag(sign_extend((v - previous) - (p - partner_previous), width));
    previous = v;
    partner_previous = p;
  }
  return residuals;
}

// Bytes an order-0 coder would need for the byte planes of the column's residuals
// (steps, minus `partner`'s steps when given): a cheap stand-in for zstd when choosing a
// partner, counted as the residuals come, without keeping them.
double residual_entropy_bytes(const AttributeColumn& column, const AttributeColumn* partner) {
  const unsigned width = static_cast<unsigned>(size_of(column.type()));
  std::vector<std::uint64_t> counts(std::size_t{width} * 256, 0);
  std::uint64_t previous = 0, partner_previous = 0;
  for (std::size_t i = 0; i < column.size(); ++i) {
    const std::uint64_t v = load(column.bytes().data(), i, width);
    std::uint64_t step = v - previous;
    previous = v;
    if (partner) {
      const std::uint64_t p = load(partner->bytes().data(), i, width);
      step -= p - partner_previous;
      partner_previous = p;
    }
    const std::uint64_t r = zigzag(sign_extend(step, width));
    for (unsigned k = 0; k < width; ++k) ++counts[k * 256 + ((r >> (8 * k)) & 0xffu)];
  }
  double bits = 0;
  const double n = static_cast<double>(column.size());
  for (const std::uint64_t c : counts)
    if (c) bits -= static_cast<double>(c) * std::log2(static_cast<double>(c) / n);
  return bits / 8;
}

std::vector<std::uint8_t> compress_planes(std::span<const std::uint64_t> residuals, unsigned width, int level) {
  std::vector<std::uint8_t> raw(residuals.size() * width);
  put_planes(residuals, width, raw.data());
  return zstd_compress(raw, level);
}

// The earlier integer column of the same type whose steps best predict this one's, if
// any predicts them better than nothing (by residual_entropy_bytes).
std::optional<std::uint32_t> choose_partner(const AttributeColumn& column, std::span<const AttributeColumn> earlier) {
  if (is_float(column.type())) return std::nullopt;
  double best = residual_entropy_bytes(column, nullptr);
  std::optional<std::uint32_t> choice;
  for (std::size_t j = 0; j < earlier.size(); ++j) {
    if (earlier[j].type() != column.type() || earlier[j].size() != column.size()) continue;
    const double bytes = residual_entropy_bytes(column, &earlier[j]);
    if (bytes < best) {
      best = bytes;
      choice = static_cast<std::uint32_t>(j);
    }
  }
  return choice;
}

void decode_partner_delta(std::span<const std::uint8_t> data, AttributeColumn& column,
                          std::span<const AttributeColumn> earlier, const std::string& name, std::uint64_t offset) {
  ByteReader r(data, name, offset);
  const auto index = r.get<std::uint32_t>("partner column");
  if (r.get<std::uint32_t>("reserved") != 0) r.fail_at(offset + 4, "reserved bytes of a partner coding are not 0");
  if (index >= earlier.size())
    r.fail_at(offset, "partner column " + std::to_string(index) + " is not one of the " + std::to_string(earlier.size()) +
                          " columns before '" + column.name() + "'");
  const AttributeColumn& partner = earlier[index];
  if (partner.type() != column.type() || partner.size() != column.size())
    r.fail_at(offset, "partner column '" + partner.name() + "' holds " + std::to_string(partner.size()) + " " +
                          std::string(name_of(partner.type())) + " values, not " + std::to_string(column.size()) + " " +
                          std::string(name_of(column.type())) + " like '" + column.name() + "'");
  const unsigned width = static_cast<unsigned>(size_of(column.type()));
  const std::size_t n = column.size();
  const auto raw = zstd_decompress(r.take(r.remaining(), "partner-coded values"), static_cast<std::uint64_t>(n) * width,
                                   name, offset + 8);
  std::uint64_t previous = 0, partner_previous = 0;
  std::byte* out = column.bytes().data();
  const std::byte* from = partner.bytes().data();
  for (std::size_t i = 0; i < n; ++i) {
    const std::uint64_t p = load(from, i, width);
    previous += unzigzag(get_plane_value(raw.data(), n, i, width)) + (p - partner_previous);
    partner_previous = p;
    store(out, i, width, previous);
  }
}

}  // namespace

std::span<const double> VoxelCorners::along(unsigned axis) {
  if (!done_[axis]) {
    auto& c = corners_[axis];
    c.reserve(tree_.voxel_count());
    const double origin = frame_.origin[axis], size = frame_.voxel_size;
    // fma: one rounding, the same on every machine and with any compiler flags.
    tree_.for_each_voxel([&](const Voxel& v) {
      const std::uint32_t i = axis == 0 ? v.x : (axis == 1 ? v.y : v.z);
      c.push_back(std::fma(static_cast<double>(i), size, origin));
    });
    done_[axis] = true;
  }
  return corners_[axis];
}

EncodedColumn encode_column(const AttributeColumn& column, std::span<const AttributeColumn> earlier,
                            VoxelCorners& corners, int level) {
  const auto bytes = column.bytes();
  EncodedColumn best{kEncodingZstd,
                     zstd_compress({reinterpret_cast<const std::uint8_t*>(bytes.data()), bytes.size()}, level)};
  auto consider = [&](std::uint8_t encoding, std::vector<std::uint8_t> data) {
    if (data.size() < best.data.size()) best = {encoding, std::move(data)};
  };
  if (column.size() == 0) return best;
  consider(kEncodingDeltaPlanes, encode_delta_planes(column, level));
  if (const auto partner = choose_partner(column, earlier)) {
    std::vector<std::uint8_t> data(8, 0);
    std::memcpy(data.data(), &*partner, 4);  // little-endian, as every integer in the file
    const auto frame = compress_planes(partner_residuals(column, earlier[*partner]),
                                       static_cast<unsigned>(size_of(column.type())), level);
    data.insert(data.end(), frame.begin(), frame.end());
    consider(kEncodingPartnerDelta, std::move(data));
  }
  if (column.type() == ValueType::f32) consider(kEncodingQuantized, encode_quantized<float>(column, corners, level));
  if (column.type() == ValueType::f64) consider(kEncodingQuantized, encode_quantized<double>(column, corners, level));
  return best;
}

void decode_column(std::uint8_t encoding, std::span<const std::uint8_t> data, AttributeColumn& column,
                   std::span<const AttributeColumn> earlier, VoxelCorners& corners, const std::string& name,
                   std::uint64_t offset) {
  if (encoding == kEncodingDeltaPlanes) return decode_delta_planes(data, column, name, offset);
  if (encoding == kEncodingPartnerDelta) return decode_partner_delta(data, column, earlier, name, offset);
  ByteReader r(data, name, offset);
  if (!is_float(column.type()))
    r.fail("quantized coding (encoding 3) of a column of " + std::string(name_of(column.type())) +
           " values; it is for f32 and f64 columns only");
  if (column.type() == ValueType::f32)
    decode_quantized<float>(r, column, corners, name);
  else
    decode_quantized<double>(r, column, corners, name);
}

}  // namespace detail
VOLA_INLINE_NAMESPACE_END
}  // namespace vola
