// PLY (Stanford polygon format): voxel centres as vertices, or the voxels' outer
// surface as a quad mesh. Coordinates are doubles: georeferenced coordinates need more
// than a float's 24 bits.
#include <algorithm>
#include <array>
#include <cstring>
#include <limits>

#include "export_columns.hpp"
#include "vola/output_file.hpp"
#include "vola/error.hpp"
#include "vola/io/export.hpp"
#include "vola/version.hpp"

namespace vola::io {

namespace {

// How one attribute column becomes one PLY property.
struct PlyField {
  const AttributeColumn* column;
  std::string name;
  const char* type;  // PLY type name
  // colour_u8_in_u16: the value as is, as uchar (8-bit colours stored in 16-bit fields,
  // as many LAS files do). Colours that use the 16-bit range stay ushort (copy): cutting
  // them to 8 bits lost what a reader can keep.
  enum class Conversion { copy, colour_u8_in_u16, integer_to_double } conversion;
};

bool is_colour(const AttributeColumn& c) { return c.name() == "red" || c.name() == "green" || c.name() == "blue"; }

// Do the u16 colour columns use the 16-bit range? If none exceeds 255, they hold 8-bit
// colours, written as uchar (what most PLY readers expect of colours).
bool colours_use_16_bits(const Attributes& attributes) {
  for (const auto& c : attributes.columns()) {
    if (!is_colour(c) || c.type() != ValueType::u16) continue;
    const auto bytes = c.bytes();
    for (std::size_t i = 0; i + 1 < bytes.size(); i += 2) {
      std::uint16_t v;
      std::memcpy(&v, bytes.data() + i, 2);
      if (v > 255) return true;
    }
  }
  return false;
}

std::vector<PlyField> ply_fields(const Tree& tree, std::vector<std::string> taken) {
  std::vector<PlyField> fields;
  const auto names = token_names(tree.attributes(), std::move(taken));
  const auto& columns = tree.attributes().columns();
  const bool wide_colours = colours_use_16_bits(tree.attributes());
  for (std::size_t i = 0; i < columns.size(); ++i) {
    const AttributeColumn& c = columns[i];
    PlyField f{&c, names[i], ply_type(c.type()), PlyField::Conversion::copy};
    if (is_colour(c) && c.type() == ValueType::u16 && !wide_colours) {
      f.type = "uchar";
      f.conversion = PlyField::Conversion::colour_u8_in_u16;
    } else if (c.type() == ValueType::u64 || c.type() == ValueType::i64) {
      f.conversion = PlyField::Conversion::integer_to_double;
    }
    fields.push_back(std::move(f));
  }
  return fields;
}

void append_binary(std::string& out, const PlyField& f, std::size_t rank) {
  const std::size_t size = size_of(f.column->type());
  const std::byte* p = f.column->bytes().data() + rank * size;
  switch (f.conversion) {
    case PlyField::Conversion::copy:
      out.append(reinterpret_cast<const char*>(p), size);
      return;
    case PlyField::Conversion::colour_u8_in_u16: {
      std::uint16_t v;
      std::memcpy(&v, p, 2);
      out.push_back(static_cast<char>(v));
      return;
    }
    case PlyField::Conversion::integer_to_double: {
      const double v = f.column->get(rank);
      out.append(reinterpret_cast<const char*>(&v), sizeof v);
      return;
    }
  }
}

void append_text(std::string& out, const PlyField& f, std::size_t rank) {
  switch (f.conversion) {
    case PlyField::Conversion::copy: return append_value(out, *f.column, rank);
    case PlyField::Conversion::colour_u8_in_u16:
      out += std::to_string(static_cast<unsigned>(f.column->get(rank)));
      return;
    case PlyField::Conversion::integer_to_double: return append_number(out, f.column->get(rank));
  }
}

// The attribute fields of the voxel of `rank`, after its coordinates.
void append_fields(std::string& out, const std::vector<PlyField>& fields, std::size_t rank, bool ascii) {
  for (const auto& f : fields) {
    if (ascii) {
      out += ' ';
      append_text(out, f, rank);
    } else {
      append_binary(out, f, rank);
    }
  }
}

void append_point(std::string& out, const Point& p, bool ascii) {
  for (int a = 0; a < 3; ++a) {
    if (ascii) {
      if (a) out += ' ';
      append_number(out, p[a]);
    } else {
      out.append(reinterpret_cast<const char*>(&p[a]), sizeof(double));
    }
  }
}

std::string header_start(const Tree& tree, const PlyOptions& options, const char* content) {
  std::string h = "ply\nformat ";
  h += options.ascii ? "ascii 1.0\n" : "binary_little_endian 1.0\n";
  h += "comment vola " VOLA_VERSION_STRING ": ";
  h += content;
  h += ", voxel size ";
  append_number(h, tree.frame().voxel_size);
  h += '\n';
  return h;
}

class Buffered {
 public:
  explicit Buffered(OutputFile& out) : out_(out) {}
  std::string& text() { return buffer_; }
  void maybe_flush() {
    if (buffer_.size() >= (std::size_t{1} << 16)) flush();
  }
  void flush() {
    out_.write(buffer_);
    buffer_.clear();
  }

 private:
  OutputFile& out_;
  std::string buffer_;
};

PlyReport write_centres(const Tree& tree, OutputFile& out, const PlyOptions& options) {
  const auto fields = ply_fields(tree, {"x", "y", "z"});
  std::string header = header_start(tree, options, "voxel centres");
  header += "element vertex " + std::to_string(tree.voxel_count()) + "\n";
  header += "property double x\nproperty double y\nproperty double z\n";
  for (const auto& f : fields) header += std::string("property ") + f.type + " " + f.name + "\n";
  header += "end_header\n";
  out.write(header);

  const Quantizer quantizer = tree.quantizer();
  Buffered buffer(out);
  std::string& b = buffer.text();
  std::size_t rank = 0;
  tree.for_each_voxel([&](const Voxel& v) {
    append_point(b, quantizer.center(v), options.ascii);
    append_fields(b, fields, rank, options.ascii);
    if (options.ascii) b += '\n';
    ++rank;
    buffer.maybe_flush();
  });
  buffer.flush();
  return {tree.voxel_count(), 0};
}

// ---- Cube surface ----

// The corner offsets of a voxel's six faces, counter-clockwise seen from outside, and
// the neighbour each face touches.
struct CubeFace {
  std::array<int, 3> neighbour;
  std::array<std::array<std::uint32_t, 3>, 4> corners;
};
constexpr std::array<CubeFace, 6> kCubeFaces{{
    {{-1, 0, 0}, {{{0, 0, 0}, {0, 0, 1}, {0, 1, 1}, {0, 1, 0}}}},
    {{1, 0, 0}, {{{1, 0, 0}, {1, 1, 0}, {1, 1, 1}, {1, 0, 1}}}},
    {{0, -1, 0}, {{{0, 0, 0}, {1, 0, 0}, {1, 0, 1}, {0, 0, 1}}}},
    {{0, 1, 0}, {{{0, 1, 0}, {0, 1, 1}, {1, 1, 1}, {1, 1, 0}}}},
    {{0, 0, -1}, {{{0, 0, 0}, {0, 1, 0}, {1, 1, 0}, {1, 0, 0}}}},
    {{0, 0, 1}, {{{0, 0, 1}, {1, 0, 1}, {1, 1, 1}, {0, 1, 1}}}},
}};

// A corner of the (S+1)^3 lattice, S <= 2^20: 21 bits per axis.
constexpr int kCornerBits = 21;
std::uint64_t corner_key(const Voxel& v, const std::array<std::uint32_t, 3>& offset) {
  return std::uint64_t{v.x + offset[0]} | std::uint64_t{v.y + offset[1]} << kCornerBits |
         std::uint64_t{v.z + offset[2]} << (2 * kCornerBits);
}

// Calls f(voxel, rank, face) for every voxel side no occupied voxel covers.
template <class F>
void for_each_surface_face(const Tree& tree, F&& f) {
  const std::int64_t side = tree.side();
  std::size_t rank = 0;
  tree.for_each_voxel([&](const Voxel& v) {
    for (const CubeFace& face : kCubeFaces) {
      const std::int64_t n[3] = {std::int64_t{v.x} + face.neighbour[0], std::int64_t{v.y} + face.neighbour[1],
                                 std::int64_t{v.z} + face.neighbour[2]};
      const bool inside = n[0] >= 0 && n[0] < side && n[1] >= 0 && n[1] < side && n[2] >= 0 && n[2] < side;
      if (!inside || !tree.contains(static_cast<std::uint32_t>(n[0]), static_cast<std::uint32_t>(n[1]),
                                    static_cast<std::uint32_t>(n[2])))
        f(v, rank, face);
    }
    ++rank;
  });
}

PlyReport write_cubes(const Tree& tree, OutputFile& out, const PlyOptions& options) {
  // Pass 1: the corners in use, sorted, so that a corner's vertex index is its rank.
  std::vector<std::uint64_t> corners;
  std::uint64_t faces = 0;
  for_each_surface_face(tree, [&](const Voxel& v, std::size_t, const CubeFace& face) {
    for (const auto& offset : face.corners) corners.push_back(corner_key(v, offset));
    ++faces;
  });
  std::sort(corners.begin(), corners.end());
  corners.erase(std::unique(corners.begin(), corners.end()), corners.end());

  if (corners.size() > std::numeric_limits<std::uint32_t>::max())
    throw InvalidArgument("the surface has " + std::to_string(corners.size()) + " corners, more than PLY's 32-bit indices reach");
  const bool wide = corners.size() > static_cast<std::size_t>(std::numeric_limits<std::int32_t>::max());
  const auto fields = ply_fields(tree, {"vertex_indices"});
  std::string header = header_start(tree, options, "outer surface of the voxels");
  header += "element vertex " + std::to_string(corners.size()) + "\n";
  header += "property double x\nproperty double y\nproperty double z\n";
  header += "element face " + std::to_string(faces) + "\n";
  header += wide ? "property list uchar uint vertex_indices\n" : "property list uchar int vertex_indices\n";
  for (const auto& f : fields) header += std::string("property ") + f.type + " " + f.name + "\n";
  header += "end_header\n";
  out.write(header);

  Buffered buffer(out);
  std::string& b = buffer.text();
  const Frame frame = tree.frame();
  constexpr std::uint64_t mask = (std::uint64_t{1} << kCornerBits) - 1;
  for (const std::uint64_t key : corners) {
    const std::uint64_t c[3] = {key & mask, (key >> kCornerBits) & mask, key >> (2 * kCornerBits)};
    Point p;
    for (int a = 0; a < 3; ++a) p[a] = frame.origin[a] + static_cast<double>(c[a]) * frame.voxel_size;
    append_point(b, p, options.ascii);
    if (options.ascii) b += '\n';
    buffer.maybe_flush();
  }
  // Pass 2: the faces, in the same order as pass 1 found them.
  for_each_surface_face(tree, [&](const Voxel& v, std::size_t rank, const CubeFace& face) {
    if (options.ascii) b += '4';
    else b += static_cast<char>(4);
    for (const auto& offset : face.corners) {
      const auto index = static_cast<std::uint32_t>(
          std::lower_bound(corners.begin(), corners.end(), corner_key(v, offset)) - corners.begin());
      if (options.ascii) {
        b += ' ';
        b += std::to_string(index);
      } else {
        b.append(reinterpret_cast<const char*>(&index), sizeof index);
      }
    }
    append_fields(b, fields, rank, options.ascii);
    if (options.ascii) b += '\n';
    buffer.maybe_flush();
  });
  buffer.flush();
  return {corners.size(), faces};
}

}  // namespace

PlyReport write_ply(const Tree& tree, const std::string& path, const PlyOptions& options) {
  require_complete_columns(tree);
  OutputFile out(path);
  const PlyReport report = options.cubes ? write_cubes(tree, out, options) : write_centres(tree, out, options);
  out.commit();
  return report;
}

}  // namespace vola::io
