// ConvertOptions: the checks that need no input, and the translation into the readers'
// and the builder's options.
#include "options.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <optional>

#include "vola/attributes.hpp"
#include "vola/error.hpp"
#include "vola/filters/stages.hpp"
#include "vola/io/column_reduction.hpp"
#include "vola/tree.hpp"

namespace vola {

namespace convert_detail {

namespace {

std::vector<std::string> split(const std::string& text, char separator) {
  std::vector<std::string> parts;
  for (std::size_t start = 0;;) {
    const auto end = text.find(separator, start);
    parts.push_back(text.substr(start, end == std::string::npos ? std::string::npos : end - start));
    if (end == std::string::npos) return parts;
    start = end + 1;
  }
}

}  // namespace

TextAttributeSpec parse_text_attribute(const std::string& spec) {
  const auto fail = [&spec](const std::string& why) { return OptionError("text_attributes", "'" + spec + "': " + why); };
  const auto eq = spec.find('=');
  if (eq == std::string::npos || eq == 0) throw fail("expected NAME=COLUMN[:TYPE[:REDUCTION]]");
  TextAttributeSpec out;
  out.attribute.name = spec.substr(0, eq);
  out.attribute.reduction = io::default_reduction(out.attribute.name);  // as a header's column of that name
  const std::vector<std::string> parts = split(spec.substr(eq + 1), ':');
  if (parts.size() > 3) throw fail("expected NAME=COLUMN[:TYPE[:REDUCTION]]");
  try {
    std::size_t used = 0;
    out.column = std::stoi(parts[0], &used);
    if (used != parts[0].size()) throw std::invalid_argument(parts[0]);
  } catch (const std::exception&) {
    throw fail("column '" + parts[0] + "' is not a number");
  }
  if (out.column < 1) throw fail("columns count from 1");
  if (parts.size() > 1) {
    const auto type = parse_value_type(parts[1]);
    if (!type) throw fail("type '" + parts[1] + "' is not one of u8 u16 u32 u64 i8 i16 i32 i64 f32 f64");
    out.attribute.type = *type;
  }
  if (parts.size() > 2) {
    const auto reduction = parse_reduction(parts[2]);
    if (!reduction) throw fail("reduction '" + parts[2] + "' is not one of last mean max min majority");
    out.attribute.reduction = *reduction;
  }
  return out;
}

Quantization quantization_of(const ConvertOptions& options) {
  if (options.quantization) return *options.quantization;
  return options.voxel_size > 0.0 || options.origin ? Quantization::grid : Quantization::toolkit;
}

BuildOptions build_options(const ConvertOptions& options, std::uint32_t epsg) {
  BuildOptions build;
  build.quantization = quantization_of(options);
  build.depth = options.depth;
  build.voxel_size = options.voxel_size;
  build.origin = options.origin;
  build.bbox = options.bbox;
  build.payload = options.nbits > 0;
  build.epsg = epsg;
  return build;
}

io::TextColumns text_columns(const std::string& input, const ConvertOptions& options) {
  io::TextColumns columns;
  const std::array<int, 3> xyz = options.columns.value_or(std::array<int, 3>{1, 2, 3});
  columns.x = xyz[0] - 1;
  columns.y = xyz[1] - 1;
  columns.z = xyz[2] - 1;
  columns.skip_lines = options.skip_lines;
  // A header line lays the columns out unless the options do: all of them when no column
  // option is given, x, y and z when only payload or attribute columns are. `columns`
  // given, 1 2 3 too, place x, y and z while the header still names the other columns
  // (taken for the default, 1 2 3 was ignored).
  const bool xyz_given = options.columns.has_value();
  columns.from_header = options.payload_columns.empty() && options.text_attributes.empty() && options.nbits == 0;
  columns.xyz_given = xyz_given;  // the header's other columns stay attributes
  columns.named_attributes = options.attributes;
  std::optional<std::array<int, 3>> named;
  if (!xyz_given && !columns.from_header)
    if (const auto header = io::read_text_header(input, options.skip_lines)) named = io::named_xyz_columns(*header);
  if (named) columns.x = (*named)[0], columns.y = (*named)[1], columns.z = (*named)[2];
  if (options.nbits > 0) {
    if (!options.payload_columns.empty()) {
      for (int c : options.payload_columns) columns.payload.push_back(c - 1);
    } else {
      // The reference's xyz2vola: every column after x y z is a payload byte (with a
      // header naming x, y and z: every other column).
      const int n = io::count_text_columns(input, options.skip_lines);
      const int last_xyz = std::max({columns.x, columns.y, columns.z});
      for (int c = named ? 0 : last_xyz + 1; c < n; ++c)
        if (c != columns.x && c != columns.y && c != columns.z) columns.payload.push_back(c);
      // The reference refuses such a file too (a byte past the word overflows); dropping
      // the columns after the eighth would be a silent choice.
      if (columns.payload.size() > 8)
        throw OptionError("nbits", input + " has " + std::to_string(columns.payload.size()) +
                                       " columns besides x, y and z, and a 64-bit payload word holds 8 bytes: name "
                                       "the payload columns (--payload-columns, at most 8)");
    }
  }
  for (const auto& spec : options.text_attributes) {
    TextAttributeSpec parsed = parse_text_attribute(spec);
    columns.attributes.push_back(std::move(parsed.attribute));
    columns.attribute_columns.push_back(parsed.column - 1);
  }
  return columns;
}

}  // namespace convert_detail

void ConvertOptions::check() const {
  if (epsg && !assign_crs.empty())
    throw OptionError("assign_crs", "give the input's CRS once (`assign_crs` or `epsg`, not both)");
  if (nbits < 0 || nbits > 64) throw OptionError("nbits", std::to_string(nbits) + " is outside 0..64");
  if (dense && compress) throw OptionError("compress", "compressed files are sparse (dense and compress together)");
  if (dense && compress_max)
    throw OptionError("compress_max", "compressed files are sparse, not `dense`");
  if (columns)
    for (int c : *columns)
      if (c < 1) throw OptionError("columns", "column numbers count from 1");
  for (int c : payload_columns)
    if (c < 1) throw OptionError("payload_columns", "column numbers count from 1");
  if (payload_columns.size() > 8) throw OptionError("payload_columns", "a payload word holds at most 8 bytes");
  if (skip_lines < 0) throw OptionError("skip_lines", "must be >= 0");
  if (level && (*level < 0 || *level > 30)) throw OptionError("level", std::to_string(*level) + " is outside 0..30");
  if (dem_base && !std::isfinite(*dem_base)) throw OptionError("dem_base", "must be finite");
  for (const auto& spec : text_attributes) convert_detail::parse_text_attribute(spec);
  BuildOptions build = convert_detail::build_options(*this, 2000);
  // Whether the voxels are given a size at all is decided once the input is known: a
  // voxel-grid input maps cell for cell without either.
  if (build.depth == 0 && build.voxel_size <= 0.0) build.depth = kMaxDepth;
  build.check();
  if (!filters.empty()) {
    filters::parse_stages(filters);  // throws OptionError("filters", ...) naming the stage
    if (nbits > 0) throw OptionError("filters", "cannot be combined with payload words (nbits); keep attributes instead");
    if (level) throw OptionError("filters", "cannot be combined with a COPC or EPT level yet");
  }
}

}  // namespace vola
