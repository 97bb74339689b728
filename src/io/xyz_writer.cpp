// XYZ text: one voxel centre per line, "x y z [attribute values...]"; CSV the same with
// commas and PDAL's quoted header.
#include "export_columns.hpp"
#include "vola/output_file.hpp"
#include "vola/io/export.hpp"

namespace vola::io {

namespace {

void write_text(const Tree& tree, const std::string& path, bool csv) {
  require_complete_columns(tree);
  OutputFile out(path);
  const auto& columns = tree.attributes().columns();
  const char separator = csv ? ',' : ' ';
  std::string line = text_header(token_names(tree.attributes(), {"x", "y", "z"}), csv);
  const Quantizer quantizer = tree.quantizer();
  std::size_t rank = 0;
  tree.for_each_voxel([&](const Voxel& v) {
    const Point p = quantizer.center(v);
    for (int a = 0; a < 3; ++a) {
      if (a) line += separator;
      append_number(line, p[a]);
    }
    for (const auto& column : columns) {
      line += separator;
      append_value(line, column, rank);
    }
    line += '\n';
    ++rank;
    if (line.size() >= (std::size_t{1} << 16)) {
      out.write(line);
      line.clear();
    }
  });
  out.write(line);
  out.commit();
}

}  // namespace

void write_xyz(const Tree& tree, const std::string& path) { write_text(tree, path, false); }

void write_csv(const Tree& tree, const std::string& path) { write_text(tree, path, true); }

}  // namespace vola::io
