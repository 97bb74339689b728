// Structured (record) NumPy arrays: the descr list of a record dtype, and records as
// points (vola/io/npy.hpp).
#include <algorithm>
#include <cstring>
#include <limits>
#include <unordered_set>

#include "column_names.hpp"
#include "npy_fields.hpp"
#include "vola/error.hpp"
#include "vola/io/npy.hpp"
#include "vola/little_endian.hpp"

namespace vola::io {

namespace {

// Reads numpy's repr of a descr list: [('name', '<f8'), ('rgb', '|u1', (3,)), ...].
class DescrReader {
 public:
  DescrReader(std::string_view text, const std::string& name, std::uint64_t offset)
      : text_(text), name_(name), offset_(offset) {}

  void expect(char c) {
    skip_space();
    if (at_ >= text_.size() || text_[at_] != c) fail(std::string("expected '") + c + "'");
    ++at_;
  }
  bool next_is(char c) {
    skip_space();
    return at_ < text_.size() && text_[at_] == c;
  }
  std::string quoted() {
    skip_space();
    if (at_ >= text_.size() || (text_[at_] != '\'' && text_[at_] != '"')) fail("expected a quoted string");
    const char quote = text_[at_++];
    std::string s;  // Python's repr escapes quotes and backslashes in a name with a backslash
    while (at_ < text_.size() && text_[at_] != quote) {
      if (text_[at_] == '\\' && at_ + 1 < text_.size()) ++at_;
      s.push_back(text_[at_++]);
    }
    if (at_ >= text_.size()) fail("a string is not terminated");
    ++at_;
    return s;
  }
  std::uint64_t number() {
    skip_space();
    std::uint64_t v = 0;
    const std::size_t start = at_;
    while (at_ < text_.size() && text_[at_] >= '0' && text_[at_] <= '9') {
      if (v > (std::numeric_limits<std::uint32_t>::max() - 9) / 10) fail("a subarray dimension is too large");
      v = v * 10 + static_cast<std::uint64_t>(text_[at_++] - '0');
    }
    if (at_ == start) fail("expected a number");
    return v;
  }
  [[noreturn]] void fail(const std::string& cause) const {
    throw FormatError(name_, offset_, "npy structured descr: " + cause + " at character " + std::to_string(at_));
  }

 private:
  void skip_space() {
    while (at_ < text_.size() && (text_[at_] == ' ' || text_[at_] == '\n')) ++at_;
  }
  std::string_view text_;
  const std::string& name_;
  std::uint64_t offset_;
  std::size_t at_ = 0;
};

// A field's dtype string: byte order, kind, size ('<f8', '|u1', '|V4', '|S10', '<U3').
NpyField field_type(const std::string& dtype, DescrReader& in, const std::string& field) {
  NpyField f;
  if (dtype.size() < 3 || (dtype[0] != '<' && dtype[0] != '>' && dtype[0] != '|' && dtype[0] != '='))
    in.fail("field '" + field + "' has dtype '" + dtype + "'");
  f.big_endian = dtype[0] == '>';
  f.kind = dtype[1];
  std::uint64_t size = 0;
  for (std::size_t i = 2; i < dtype.size(); ++i) {
    if (dtype[i] < '0' || dtype[i] > '9' || size > (1u << 24))
      in.fail("field '" + field + "' has dtype '" + dtype + "'");
    size = size * 10 + static_cast<std::uint64_t>(dtype[i] - '0');
  }
  const bool numeric = (f.kind == 'f' && (size == 4 || size == 8)) ||
                       ((f.kind == 'i' || f.kind == 'u') && (size == 1 || size == 2 || size == 4 || size == 8)) ||
                       (f.kind == 'b' && size == 1);
  const bool skipped = f.kind == 'V' || f.kind == 'S' || f.kind == 'a' || f.kind == 'U';
  if (!numeric && !skipped)
    in.fail("field '" + field + "' has dtype '" + dtype +
            "' (vola reads float32/64, int8..64, uint8..64 and bool fields; padding, bytes and text are skipped)");
  f.item_size = static_cast<int>(f.kind == 'U' ? 4 * size : size);
  f.name = field;
  return f;
}

double field_value(const NpyField& f, const std::uint8_t* record) noexcept {
  const std::uint8_t* p = record + f.offset;
  switch (f.kind) {
    case 'f':
      return f.item_size == 4 ? static_cast<double>(load_npy_value<float>(p, f.big_endian))
                              : load_npy_value<double>(p, f.big_endian);
    case 'b':
      return *p ? 1.0 : 0.0;
    case 'u':
      switch (f.item_size) {
        case 1:
          return *p;
        case 2:
          return load_npy_value<std::uint16_t>(p, f.big_endian);
        case 4:
          return load_npy_value<std::uint32_t>(p, f.big_endian);
        default:
          return static_cast<double>(load_npy_value<std::uint64_t>(p, f.big_endian));
      }
    default:
      switch (f.item_size) {
        case 1:
          return static_cast<std::int8_t>(*p);
        case 2:
          return load_npy_value<std::int16_t>(p, f.big_endian);
        case 4:
          return load_npy_value<std::int32_t>(p, f.big_endian);
        default:
          return static_cast<double>(load_npy_value<std::int64_t>(p, f.big_endian));
      }
  }
}

ValueType value_type_of(const NpyField& f) {
  if (f.kind == 'f') return f.item_size == 4 ? ValueType::f32 : ValueType::f64;
  if (f.kind == 'b') return ValueType::u8;
  static constexpr ValueType kUnsigned[] = {ValueType::u8, ValueType::u16, ValueType::u32, ValueType::u64};
  static constexpr ValueType kSigned[] = {ValueType::i8, ValueType::i16, ValueType::i32, ValueType::i64};
  const int at = f.item_size == 1 ? 0 : f.item_size == 2 ? 1 : f.item_size == 4 ? 2 : 3;
  return f.kind == 'u' ? kUnsigned[at] : kSigned[at];
}

bool is_numeric(const NpyField& f) { return f.kind == 'f' || f.kind == 'i' || f.kind == 'u' || f.kind == 'b'; }

std::string lower(std::string s) {
  for (char& c : s) c = static_cast<char>(c >= 'A' && c <= 'Z' ? c - 'A' + 'a' : c);
  return s;
}

}  // namespace

std::vector<NpyField> parse_npy_fields(std::string_view descr, const std::string& name, std::uint64_t offset,
                                       std::uint64_t& record_size) {
  DescrReader in(descr, name, offset);
  std::vector<NpyField> fields;
  std::uint64_t at = 0;
  in.expect('[');
  while (!in.next_is(']')) {
    in.expect('(');
    if (in.next_is('(')) in.fail("a field with a title is not read");
    const std::string field = in.quoted();
    in.expect(',');
    if (in.next_is('[')) in.fail("field '" + field + "' is itself a structure (nested records are not read)");
    NpyField type = field_type(in.quoted(), in, field);
    std::uint64_t elements = 1;
    bool subarray = false;
    if (in.next_is(',')) {  // a subarray: ('rgb', '|u1', (3,)) or (2, 2)
      in.expect(',');
      in.expect('(');
      subarray = true;
      while (!in.next_is(')')) {
        elements *= in.number();
        if (elements > (1u << 16)) in.fail("field '" + field + "' has over 65536 elements");
        if (in.next_is(',')) in.expect(',');
      }
      in.expect(')');
    }
    in.expect(')');
    if (in.next_is(',')) in.expect(',');
    if (!is_numeric(type)) {  // bytes vola skips: the whole subarray at once
      at += static_cast<std::uint64_t>(type.item_size) * elements;
    } else {
      for (std::uint64_t e = 0; e < elements; ++e) {
        NpyField f = type;
        f.offset = at;
        if (subarray) f.name = field + "_" + std::to_string(e);
        at += static_cast<std::uint64_t>(f.item_size);
        fields.push_back(std::move(f));
      }
    }
    if (at > (std::uint64_t{1} << 30)) in.fail("records of over 1 GiB");
    if (fields.size() > (1u << 16)) in.fail("more than 65536 fields");
  }
  in.expect(']');
  if (at == 0) in.fail("records of no bytes");
  record_size = at;
  return fields;
}

PointCloud npy_record_points(const NpyArray& array, const std::string& name) {
  const NpyField* axis[3] = {nullptr, nullptr, nullptr};
  for (const NpyField& f : array.fields)
    for (int a = 0; a < 3; ++a)
      if (!axis[a] && lower(f.name) == std::string(1, static_cast<char>('x' + a))) axis[a] = &f;
  if (!axis[0] || !axis[1] || !axis[2]) {
    std::string names;
    for (const NpyField& f : array.fields) names += (names.empty() ? "" : ", ") + f.name;
    throw FormatError(name, {},
                      "a structured array needs numeric fields x, y and z (in any case); its fields are " +
                          (names.empty() ? std::string("none") : names));
  }
  const std::uint64_t n = array.size();
  const auto record = static_cast<std::uint64_t>(array.item_size);
  PointCloud cloud;
  cloud.xyz.resize(3 * n);
  for (std::uint64_t i = 0; i < n; ++i)
    for (int a = 0; a < 3; ++a)
      cloud.xyz[3 * i + static_cast<std::uint64_t>(a)] = field_value(*axis[a], array.data.data() + i * record);
  std::unordered_set<std::string> taken = {"x", "y", "z"};
  for (const NpyField& f : array.fields) {
    if (&f == axis[0] || &f == axis[1] || &f == axis[2]) continue;
    const std::string column = point_column_name(f.name);
    if (!taken.insert(column).second) continue;  // a second field of one name stays unread
    PointAttribute attribute{column, value_type_of(f), point_column_reduction(column, f.name), {}};
    attribute.values.resize(n);
    for (std::uint64_t i = 0; i < n; ++i) attribute.values[i] = field_value(f, array.data.data() + i * record);
    cloud.attributes.push_back(std::move(attribute));
  }
  return cloud;
}

}  // namespace vola::io
