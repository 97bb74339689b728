#include "vola/attributes.hpp"

#include "vola/little_endian.hpp"
#include "store_value.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

namespace vola {
VOLA_INLINE_NAMESPACE_BEGIN

namespace {
constexpr std::string_view kTypeNames[] = {"u8", "u16", "u32", "u64", "i8",
                                           "i16", "i32", "i64", "f32", "f64"};
constexpr std::string_view kReductionNames[] = {"last", "mean", "max", "min", "majority"};

template <class T>
void store(std::byte* p, double value) {
  detail::store_as<T>(p, value);
}
}  // namespace


std::string_view name_of(ValueType type) noexcept { return kTypeNames[static_cast<int>(type)]; }
std::string_view name_of(Reduction r) noexcept { return kReductionNames[static_cast<int>(r)]; }

std::optional<ValueType> parse_value_type(std::string_view name) noexcept {
  for (int i = 0; i < 10; ++i)
    if (kTypeNames[i] == name) return static_cast<ValueType>(i);
  return std::nullopt;
}

std::optional<Reduction> parse_reduction(std::string_view name) noexcept {
  for (int i = 0; i < 5; ++i)
    if (kReductionNames[i] == name) return static_cast<Reduction>(i);
  return std::nullopt;
}

AttributeColumn::AttributeColumn(std::string name, ValueType type, Reduction reduction,
                                 std::size_t count)
    : name_(std::move(name)), type_(type), reduction_(reduction), bytes_(count * size_of(type)) {
  if (static_cast<int>(type) > 9) VOLA_THROW(InvalidArgument("attribute " + name_ + ": unknown value type"));
  if (static_cast<int>(reduction) > 4)
    VOLA_THROW(InvalidArgument("attribute " + name_ + ": unknown reduction"));
}

AttributeColumn::AttributeColumn(std::string name, ValueType type, Reduction reduction, std::vector<std::byte> bytes)
    : AttributeColumn(std::move(name), type, reduction) {
  if (bytes.size() % size_of(type) != 0)
    VOLA_THROW(InvalidArgument("attribute " + name_ + ": " + std::to_string(bytes.size()) + " bytes are not whole " +
                               std::string(name_of(type)) + " values"));
  bytes_ = std::move(bytes);
}

double AttributeColumn::get(std::size_t rank) const {
  const std::byte* p = bytes_.data() + rank * size_of(type_);
  switch (type_) {
    case ValueType::u8: return load_le<std::uint8_t>(p);
    case ValueType::u16: return load_le<std::uint16_t>(p);
    case ValueType::u32: return load_le<std::uint32_t>(p);
    case ValueType::u64: return static_cast<double>(load_le<std::uint64_t>(p));
    case ValueType::i8: return load_le<std::int8_t>(p);
    case ValueType::i16: return load_le<std::int16_t>(p);
    case ValueType::i32: return load_le<std::int32_t>(p);
    case ValueType::i64: return static_cast<double>(load_le<std::int64_t>(p));
    case ValueType::f32: return load_le<float>(p);
    case ValueType::f64: return load_le<double>(p);
  }
  return 0.0;
}

void store_value(ValueType type, double value, std::byte* p) noexcept {
  switch (type) {
    case ValueType::u8: return store<std::uint8_t>(p, value);
    case ValueType::u16: return store<std::uint16_t>(p, value);
    case ValueType::u32: return store<std::uint32_t>(p, value);
    case ValueType::u64: return store<std::uint64_t>(p, value);
    case ValueType::i8: return store<std::int8_t>(p, value);
    case ValueType::i16: return store<std::int16_t>(p, value);
    case ValueType::i32: return store<std::int32_t>(p, value);
    case ValueType::i64: return store<std::int64_t>(p, value);
    case ValueType::f32: return store<float>(p, value);
    case ValueType::f64: return store<double>(p, value);
  }
}

void AttributeColumn::set(std::size_t rank, double value) {
  store_value(type_, value, bytes_.data() + rank * size_of(type_));
}

const AttributeColumn* Attributes::find(std::string_view name) const noexcept {
  for (const auto& c : columns_)
    if (c.name() == name) return &c;
  return nullptr;
}

AttributeColumn* Attributes::find(std::string_view name) noexcept {
  for (auto& c : columns_)
    if (c.name() == name) return &c;
  return nullptr;
}

AttributeColumn& Attributes::add(AttributeColumn column) {
  if (!names_.insert(column.name()).second)
    VOLA_THROW(InvalidArgument("attribute '" + column.name() + "' exists already"));
  columns_.push_back(std::move(column));
  return columns_.back();
}

VOLA_INLINE_NAMESPACE_END
}  // namespace vola
