#include "vola/io/npy.hpp"

#include <algorithm>
#include <cstring>
#include <fstream>
#include <limits>

#include "file_bytes.hpp"
#include "npy_fields.hpp"
#include "vola/error.hpp"
#include "vola/little_endian.hpp"

namespace vola::io {

namespace {

// The text after `key`'s colon in the header dict, looked up among the dict's own keys
// only: a quoted 'shape' inside a structured dtype's field list is a field name.
std::string_view find_value(std::string_view dict, std::string_view key, const std::string& name,
                            std::uint64_t offset) {
  int depth = 0;
  for (std::size_t i = 0; i < dict.size(); ++i) {
    const char c = dict[i];
    if (c == '\'' || c == '"') {
      std::size_t close = i + 1;  // the closing quote; a backslash escapes the next character
      while (close < dict.size() && dict[close] != c) close += dict[close] == '\\' ? 2 : 1;
      if (close >= dict.size()) break;
      if (depth == 1 && dict.substr(i + 1, close - i - 1) == key) {
        std::size_t at = close + 1;
        while (at < dict.size() && dict[at] == ' ') ++at;
        if (at < dict.size() && dict[at] == ':') {
          std::string_view rest = dict.substr(at + 1);
          while (!rest.empty() && rest.front() == ' ') rest.remove_prefix(1);
          return rest;
        }
      }
      i = close;
    } else if (c == '{' || c == '[' || c == '(') {
      ++depth;
    } else if (c == '}' || c == ']' || c == ')') {
      --depth;
    }
  }
  throw FormatError(name, offset, "npy header has no '" + std::string(key) + "'");
}

}  // namespace

std::uint64_t NpyArray::size() const noexcept {
  std::uint64_t n = 1;
  for (auto s : shape) n *= s;
  return n;
}

std::string NpyArray::dtype() const {
  if (!fields.empty() || kind == 'V') return "records of " + std::to_string(item_size) + " bytes";
  return std::string(big_endian ? ">" : "<") + kind + std::to_string(item_size);
}

double NpyArray::value(std::uint64_t index) const noexcept {
  std::uint64_t at = index;
  if (fortran_order && shape.size() > 1) {
    // C-order index -> Fortran-order storage position.
    std::uint64_t rest = index, position = 0, stride = 1;
    std::vector<std::uint64_t> digits(shape.size());
    for (std::size_t d = shape.size(); d-- > 0;) {
      digits[d] = rest % shape[d];
      rest /= shape[d];
    }
    for (std::size_t d = 0; d < shape.size(); ++d) {
      position += digits[d] * stride;
      stride *= shape[d];
    }
    at = position;
  }
  std::uint8_t raw[8] = {};
  const std::size_t n = static_cast<std::size_t>(item_size) & 15u;
  for (std::size_t b = 0; b < n && b < 8; ++b) raw[b] = data[at * n + (big_endian ? n - 1 - b : b)];
  switch (kind) {
    case 'f':
      if (item_size == 4) { float f; std::memcpy(&f, raw, 4); return f; }
      else { double d; std::memcpy(&d, raw, 8); return d; }
    case 'b': return raw[0] ? 1.0 : 0.0;
    case 'u': {
      std::uint64_t u = 0;
      std::memcpy(&u, raw, item_size);
      return static_cast<double>(u);
    }
    default: {
      std::uint64_t u = 0;
      std::memcpy(&u, raw, item_size);
      const int bits = 8 * item_size;
      if (bits < 64 && (u >> (bits - 1)) & 1u) u |= ~std::uint64_t{0} << bits;  // sign-extend
      return static_cast<double>(static_cast<std::int64_t>(u));
    }
  }
}

namespace {

void parse_plain_dtype(std::string_view descr, const std::string& name, std::uint64_t header_start, NpyArray& a);
void parse_shape_and_order(std::string_view dict, const std::string& name, std::uint64_t header_start, NpyArray& a);

// The header of `bytes` into `a` (everything but the data); returns the data's offset.
std::uint64_t parse_npy_header(std::span<const std::uint8_t> bytes, const std::string& name, NpyArray& a) {
  static const std::uint8_t magic[6] = {0x93, 'N', 'U', 'M', 'P', 'Y'};
  if (bytes.size() < 10 || std::memcmp(bytes.data(), magic, 6) != 0)
    throw FormatError(name, 0, "not a .npy file (no \\x93NUMPY magic)");
  const int major = bytes[6];
  std::uint64_t header_length = 0;
  std::uint64_t header_start = 0;
  if (major == 1) {
    header_length = bytes[8] | (std::uint64_t{bytes[9]} << 8);
    header_start = 10;
  } else if (major == 2 || major == 3) {
    if (bytes.size() < 12) throw FormatError(name, bytes.size(), "npy header is truncated");
    header_length = bytes[8] | (std::uint64_t{bytes[9]} << 8) | (std::uint64_t{bytes[10]} << 16) |
                    (std::uint64_t{bytes[11]} << 24);
    header_start = 12;
  } else {
    throw FormatError(name, 6, "npy format version " + std::to_string(major) + " is not known (1..3)");
  }
  if (header_length > bytes.size() - header_start)
    throw FormatError(name, header_start, "npy header of " + std::to_string(header_length) + " bytes runs past the end");
  const std::string_view dict(reinterpret_cast<const char*>(bytes.data() + header_start), header_length);

  std::string_view descr = find_value(dict, "descr", name, header_start);
  if (!descr.empty() && descr[0] == '[') {  // a structured dtype: records of named fields
    std::uint64_t record_size = 0;
    a.fields = parse_npy_fields(descr, name, header_start, record_size);
    a.kind = 'V';
    a.item_size = static_cast<int>(record_size);
  } else {
    parse_plain_dtype(descr, name, header_start, a);
  }
  parse_shape_and_order(dict, name, header_start, a);
  const std::uint64_t count = a.size();
  const std::uint64_t data_start = header_start + header_length;
  const std::uint64_t available = bytes.size() - data_start;
  if (count > available / static_cast<std::uint64_t>(a.item_size))
    throw FormatError(name, bytes.size(),
                      "npy shape promises " + std::to_string(count) + " values of " + std::to_string(a.item_size) +
                          " bytes but only " + std::to_string(available) + " bytes follow the header (truncated)");
  return data_start;
}

// A simple dtype string ('<f8', '|u1', ...) into `a`.
void parse_plain_dtype(std::string_view descr, const std::string& name, std::uint64_t header_start, NpyArray& a) {
  if (descr.size() < 5 || (descr[0] != '\'' && descr[0] != '"'))
    throw FormatError(name, header_start, "npy descr is neither a dtype string nor a list of fields");
  const char order = descr[1];
  a.kind = descr[2];
  const std::size_t close = descr.find(descr[0], 1);
  if (close == std::string_view::npos) throw FormatError(name, header_start, "npy descr is not terminated");
  const std::string size_text(descr.substr(3, close - 3));
  a.item_size = size_text == "1" ? 1 : size_text == "2" ? 2 : size_text == "4" ? 4 : size_text == "8" ? 8 : 0;
  const bool kind_ok = (a.kind == 'f' && (a.item_size == 4 || a.item_size == 8)) ||
                       ((a.kind == 'i' || a.kind == 'u') && a.item_size > 0) || (a.kind == 'b' && a.item_size == 1);
  if (!kind_ok || (order != '<' && order != '>' && order != '|' && order != '='))
    throw FormatError(name, header_start,
                      "npy dtype " + std::string(descr.substr(0, close + 1)) +
                          " is not supported (float32/64, int8..64, uint8..64, bool)");
  a.big_endian = order == '>';
}

// The shape and the fortran_order flag into `a`; throws when the product overflows.
void parse_shape_and_order(std::string_view dict, const std::string& name, std::uint64_t header_start, NpyArray& a) {
  const std::string_view fortran = find_value(dict, "fortran_order", name, header_start);
  a.fortran_order = fortran.substr(0, 4) == "True";

  std::string_view shape = find_value(dict, "shape", name, header_start);
  if (shape.empty() || shape.front() != '(') throw FormatError(name, header_start, "npy shape is not a tuple");
  const std::size_t end = shape.find(')');
  if (end == std::string_view::npos) throw FormatError(name, header_start, "npy shape is not terminated");
  std::uint64_t count = 1;
  std::uint64_t value = 0;
  bool in_number = false;
  for (std::size_t i = 1; i <= end; ++i) {
    const char c = shape[i];
    if (c >= '0' && c <= '9') {
      if (value > (std::numeric_limits<std::uint64_t>::max() - 9) / 10)
        throw FormatError(name, header_start, "npy shape dimension is too large");
      value = value * 10 + static_cast<std::uint64_t>(c - '0');
      in_number = true;
    } else if (c == ',' || c == ')') {
      if (in_number) {
        a.shape.push_back(value);
        if (value && count > std::numeric_limits<std::uint64_t>::max() / value)
          throw FormatError(name, header_start, "npy shape is too large");
        count *= value;
      }
      value = 0;
      in_number = false;
    } else if (c != ' ' && c != 'L') {
      throw FormatError(name, header_start, std::string("npy shape has an unexpected '") + c + "'");
    }
  }
}

}  // namespace

NpyArray parse_npy(std::span<const std::uint8_t> bytes, const std::string& name) {
  NpyArray a;
  const std::uint64_t start = parse_npy_header(bytes, name, a);
  const auto values = bytes.subspan(start, a.size() * static_cast<std::uint64_t>(a.item_size));
  auto storage = std::make_shared<const std::vector<std::uint8_t>>(values.begin(), values.end());
  a.data = *storage;
  a.storage = std::move(storage);
  return a;
}

NpyArray parse_npy(std::vector<std::uint8_t>&& bytes, const std::string& name) {
  NpyArray a;
  const std::uint64_t start = parse_npy_header(bytes, name, a);
  auto storage = std::make_shared<const std::vector<std::uint8_t>>(std::move(bytes));
  a.data = std::span<const std::uint8_t>(*storage).subspan(start, a.size() * static_cast<std::uint64_t>(a.item_size));
  a.storage = std::move(storage);
  return a;
}

NpyArray read_npy(const std::string& path) { return parse_npy(read_file_bytes(path), path); }

namespace {

// f(T{}) for the array's value type, so that loops over values are compiled per type.
template <class F>
void with_value_type(const NpyArray& a, F&& f) {
  switch (a.kind) {
    case 'f': return a.item_size == 4 ? f(float{}) : f(double{});
    case 'i':
      switch (a.item_size) {
        case 1: return f(std::int8_t{});
        case 2: return f(std::int16_t{});
        case 4: return f(std::int32_t{});
        default: return f(std::int64_t{});
      }
    default:  // 'u' and 'b'
      switch (a.item_size) {
        case 1: return f(std::uint8_t{});
        case 2: return f(std::uint16_t{});
        case 4: return f(std::uint32_t{});
        default: return f(std::uint64_t{});
      }
  }
}

}  // namespace

namespace {

// Refuses `count` points or voxels from a compressed array beyond what its compressed
// bytes justify (NpyArray::compressed_bytes): a 210 KB .npz of ones took gigabytes.
void refuse_inflated(const NpyArray& array, std::uint64_t count, const char* what, const std::string& name) {
  if (!array.compressed_bytes) return;
  const std::uint64_t limit = kNpyValuesAllowance + kNpyValuesPerStoredByte * array.compressed_bytes;
  if (count > limit)
    throw FormatError(name, {},
                      std::to_string(count) + " " + what + " from " + std::to_string(array.compressed_bytes) +
                          " compressed bytes, more than the " + std::to_string(limit) +
                          " vola reads from them (2^25 + 8 per byte); save the array uncompressed "
                          "(numpy.save or numpy.savez) if it is meant");
}

}  // namespace

PointCloud npy_points(const NpyArray& array, const std::string& name, bool payload_columns) {
  if (array.shape.size() != 2 || array.shape[1] < 3)
    throw FormatError(name, {}, "expected an (N, 3) or (N, >3) point array, got shape with " +
                                    std::to_string(array.shape.size()) + " dimensions" +
                                    (array.shape.size() == 2 ? " and " + std::to_string(array.shape[1]) + " columns" : ""));
  const std::uint64_t n = array.shape[0];
  const std::uint64_t columns = array.shape[1];
  // Points are rows. Three rows of more columns than x, y, z and a whole 8-byte payload
  // can hold is a cloud saved with x, y and z as rows (numpy's `points.T`, a common slip):
  // read as rows it would be three points, silently.
  if (n == 3 && columns > 3 + 8)
    throw FormatError(name, {},
                      "the array's shape (" + std::to_string(n) + ", " + std::to_string(columns) + ") reads as " +
                          std::to_string(n) + " points of " + std::to_string(columns) +
                          " columns; points are rows, (N, 3): for " + std::to_string(columns) +
                          " points stored as rows x, y, z, save the transpose (numpy.save(path, points.T))");
  refuse_inflated(array, n, "points", name);
  PointCloud cloud;
  cloud.xyz.resize(3 * n);
  // Element (row i, column c) lies at i * row_step + c * column_step values.
  const std::uint64_t row_step = array.fortran_order ? 1 : columns;
  const std::uint64_t column_step = array.fortran_order ? n : 1;
  with_value_type(array, [&](auto type) {
    using T = decltype(type);
    const std::uint8_t* base = array.data.data();
    const bool boolean = array.kind == 'b';  // a bool byte other than 0 is true, as numpy reads it
    double* out = cloud.xyz.data();
    for (std::uint64_t i = 0; i < n; ++i)
      for (std::uint64_t c = 0; c < 3; ++c) {
        const T v = load_npy_value<T>(base + (i * row_step + c * column_step) * sizeof(T), array.big_endian);
        *out++ = boolean ? static_cast<double>(v != 0) : static_cast<double>(v);
      }
  });
  if (payload_columns && columns > 3) {
    if (columns - 3 > 8) throw FormatError(name, {}, "more than 8 payload columns do not fit a 64-bit payload word");
    cloud.payload.resize(n);
    for (std::uint64_t i = 0; i < n; ++i) {
      std::uint64_t word = 0;
      for (std::uint64_t c = 3; c < columns; ++c) {
        const double v = array.value(i * columns + c);
        if (!(v >= 0 && v <= 255) || v != static_cast<double>(static_cast<int>(v)))
          throw FormatError(name, {}, "row " + std::to_string(i) + " column " + std::to_string(c) + ": payload byte " +
                                          std::to_string(v) + " is not an integer 0..255");
        word |= static_cast<std::uint64_t>(v) << (8 * (c - 3));
      }
      cloud.payload[i] = word;
    }
  }
  return cloud;
}

}  // namespace vola::io

namespace vola::io {

VoxelGrid npy_grid(const NpyArray& array, const std::string& name) {
  if (array.shape.size() != 3)
    throw FormatError(name, {}, "an occupancy grid is a 3-D array, this one has " + std::to_string(array.shape.size()) +
                                    " dimensions");
  VoxelGrid grid;
  for (std::size_t a = 0; a < 3; ++a) {
    if (array.shape[a] > std::numeric_limits<std::uint32_t>::max())
      throw FormatError(name, {}, "grid dimension " + std::to_string(array.shape[a]) + " does not fit 32 bits");
    grid.dims[a] = static_cast<std::uint32_t>(array.shape[a]);
  }
  const std::uint64_t nx = array.shape[0], ny = array.shape[1], nz = array.shape[2];
  const auto item = static_cast<std::size_t>(array.item_size);
  // A float is zero when every bit but the sign is: mask the sign in its most
  // significant byte. Integers and bools are zero when every byte is.
  const std::size_t top = array.big_endian ? 0 : item - 1;
  const std::uint8_t top_mask = array.kind == 'f' ? 0x7F : 0xFF;
  const std::uint64_t count = array.size();
  const auto occupied_at = [&](std::uint64_t s) {
    const std::uint8_t* value = array.data.data() + s * item;
    bool occupied = (value[top] & top_mask) != 0;
    for (std::size_t b = 0; b < item && !occupied; ++b) occupied = b != top && value[b] != 0;
    return occupied;
  };
  if (array.compressed_bytes) {  // counted first: 12 bytes a voxel from a deflated byte of cells
    std::uint64_t occupied = 0;
    for (std::uint64_t s = 0; s < count; ++s) occupied += occupied_at(s);
    refuse_inflated(array, occupied, "occupied cells", name);
    grid.voxels.reserve(static_cast<std::size_t>(occupied));
  }
  for (std::uint64_t s = 0; s < count; ++s) {
    if (!occupied_at(s)) continue;
    // Storage position -> (x, y, z): C order runs the last index fastest, Fortran the first.
    const Voxel v = array.fortran_order
                        ? Voxel{static_cast<std::uint32_t>(s % nx), static_cast<std::uint32_t>(s / nx % ny),
                                static_cast<std::uint32_t>(s / (nx * ny))}
                        : Voxel{static_cast<std::uint32_t>(s / (ny * nz)), static_cast<std::uint32_t>(s / nz % ny),
                                static_cast<std::uint32_t>(s % nz)};
    grid.voxels.push_back(v);
  }
  return grid;
}

Input npy_input(const NpyArray& array, const std::string& name, const InputOptions& options) {
  Input in;
  in.format = "npy";
  if (array.kind == 'V') {
    in.cloud = npy_record_points(array, name);
  } else if (array.shape.size() == 3) {
    in.grid = npy_grid(array, name);
  } else if (array.shape.size() == 2) {
    in.cloud = npy_points(array, name, options.payload);
  } else {
    std::string shape;
    for (auto d : array.shape) shape += (shape.empty() ? "" : ", ") + std::to_string(d);
    throw FormatError(name, {},
                      "an array of shape (" + shape + ") is neither points (N, 3+) nor one occupancy grid (X, Y, Z)" +
                          (array.shape.size() > 3 ? "; for a stack of grids, pick one first, e.g. numpy.save('one.npy', "
                                                    "a[i]) (or a[i, 0] for (N, 1, X, Y, Z))"
                                                  : ""));
  }
  return in;
}

}  // namespace vola::io
