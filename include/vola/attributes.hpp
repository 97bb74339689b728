// Per-voxel attribute columns: one value per voxel, indexed by the voxel's rank
// (its position among all voxels in key order), so a column is a plain array that
// the tree's rank directory addresses in O(depth).
#pragma once

#include <cstddef>
#include <cstdint>
#include <cstring>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <unordered_set>
#include <vector>

#include "vola/error.hpp"
#include "vola/version.hpp"

namespace vola {
VOLA_INLINE_NAMESPACE_BEGIN

enum class ValueType : std::uint8_t { u8 = 0, u16, u32, u64, i8, i16, i32, i64, f32, f64 };

// How several points falling in one voxel become that voxel's value. A NaN value is a
// point without a value: mean, max and min skip it (NaN when every value is NaN); last
// takes it if it comes last; majority counts NaN as one value after every number.
enum class Reduction : std::uint8_t { last = 0, mean, max, min, majority };

// Bytes of one value (inline: called per value by columns).
constexpr std::size_t size_of(ValueType type) noexcept {
  switch (type) {
    case ValueType::u8: case ValueType::i8: return 1;
    case ValueType::u16: case ValueType::i16: return 2;
    case ValueType::u32: case ValueType::i32: case ValueType::f32: return 4;
    case ValueType::u64: case ValueType::i64: case ValueType::f64: return 8;
  }
  return 1;
}
// `value` stored at `out` as `type` little-endian bytes: integers rounded to nearest and
// clamped to the type's range (NaN as 0), as every attribute column stores values.
void store_value(ValueType type, double value, std::byte* out) noexcept;
std::string_view name_of(ValueType type) noexcept;
std::string_view name_of(Reduction reduction) noexcept;
std::optional<ValueType> parse_value_type(std::string_view name) noexcept;
std::optional<Reduction> parse_reduction(std::string_view name) noexcept;

class AttributeColumn {
 public:
  AttributeColumn(std::string name, ValueType type, Reduction reduction, std::size_t count = 0);
  // A column over values already stored as `type` little-endian bytes (a whole number
  // of values, else InvalidArgument).
  AttributeColumn(std::string name, ValueType type, Reduction reduction, std::vector<std::byte> bytes);

  const std::string& name() const noexcept { return name_; }
  ValueType type() const noexcept { return type_; }
  Reduction reduction() const noexcept { return reduction_; }
  std::size_t size() const noexcept { return bytes_.size() / size_of(type_); }

  // Value at `rank`, converted to double (exact for every type but 64-bit integers
  // above 2^53).
  double get(std::size_t rank) const;
  // Stores `value` at `rank`, rounded and clamped to the column's type.
  void set(std::size_t rank, double value);

  std::span<const std::byte> bytes() const noexcept { return bytes_; }
  std::span<std::byte> bytes() noexcept { return bytes_; }
  void resize(std::size_t count) { bytes_.assign(count * size_of(type_), std::byte{0}); }

 private:
  std::string name_;
  ValueType type_;
  Reduction reduction_;
  std::vector<std::byte> bytes_;
};

// The columns of one tree; names are unique.
class Attributes {
 public:
  const std::vector<AttributeColumn>& columns() const noexcept { return columns_; }
  std::size_t size() const noexcept { return columns_.size(); }
  bool empty() const noexcept { return columns_.empty(); }
  const AttributeColumn* find(std::string_view name) const noexcept;
  AttributeColumn* find(std::string_view name) noexcept;
  // Adds a column; throws InvalidArgument if the name is taken (a hash lookup: a file of
  // 80,000 columns took seconds with a search per name).
  AttributeColumn& add(AttributeColumn column);
  void clear() noexcept {
    columns_.clear();
    names_.clear();
  }

 private:
  std::vector<AttributeColumn> columns_;
  std::unordered_set<std::string> names_;
};

VOLA_INLINE_NAMESPACE_END
}  // namespace vola
