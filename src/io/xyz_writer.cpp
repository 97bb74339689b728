// XYZ text: one voxel centre per line, "x y z [attribute values...]".
#include "export_columns.hpp"
#include "vola/output_file.hpp"
#include "vola/io/export.hpp"

namespace vola::io {

void write_xyz(const Tree& tree, const std::string& path) {
  require_complete_columns(tree);
  OutputFile out(path);
  const auto& columns = tree.attributes().columns();
  std::string line = "# x y z";
  for (const auto& name : token_names(tree.attributes(), {"x", "y", "z"})) line += " " + name;
  line += '\n';
  const Quantizer quantizer = tree.quantizer();
  std::size_t rank = 0;
  tree.for_each_voxel([&](const Voxel& v) {
    const Point p = quantizer.center(v);
    for (int a = 0; a < 3; ++a) {
      if (a) line += ' ';
      append_number(line, p[a]);
    }
    for (const auto& column : columns) {
      line += ' ';
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

}  // namespace vola::io
