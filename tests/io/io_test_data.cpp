#include "io_test_data.hpp"

#include <algorithm>
#include <fstream>
#include <sstream>
#include <stdexcept>

namespace vola_io_test {

fs::path data_dir() { return vola_test::golden_dir().parent_path() / "data"; }

std::vector<fs::path> files_ending(const fs::path& folder, const std::string& suffix) {
  std::vector<fs::path> files;
  if (!fs::is_directory(folder)) return files;
  for (const auto& entry : fs::recursive_directory_iterator(folder)) {
    const std::string name = entry.path().filename().string();
    if (entry.is_regular_file() && name.size() >= suffix.size() &&
        name.compare(name.size() - suffix.size(), suffix.size(), suffix) == 0)
      files.push_back(entry.path());
  }
  std::sort(files.begin(), files.end());
  return files;
}

std::string expected_line(const fs::path& data, const std::string& file_name) {
  std::ifstream in(data / "EXPECTED.txt");
  if (!in) throw std::runtime_error("cannot open " + (data / "EXPECTED.txt").string());
  std::string line;
  while (std::getline(in, line)) {
    const auto space = line.find_first_of(" :");
    if (space == std::string::npos) continue;
    const std::string first = line.substr(0, space);
    if (first == file_name || (first.size() > file_name.size() &&
                               first.compare(first.size() - file_name.size() - 1, std::string::npos, "/" + file_name) == 0))
      return line;
  }
  throw std::runtime_error("EXPECTED.txt has no line about " + file_name);
}

std::optional<std::uint64_t> expected_integer(const std::string& line, const std::string& key) {
  const auto at = line.find(key);
  if (at == std::string::npos) return std::nullopt;
  std::istringstream in(line.substr(at + key.size()));
  std::uint64_t v = 0;
  if (!(in >> v)) return std::nullopt;
  return v;
}

std::optional<std::vector<double>> expected_numbers(const std::string& line, const std::string& key) {
  const auto at = line.find(key);
  if (at == std::string::npos) return std::nullopt;
  const auto open = line.find('[', at);
  const auto close = line.find(']', open);
  if (open == std::string::npos || close == std::string::npos) return std::nullopt;
  std::string inside = line.substr(open + 1, close - open - 1);
  std::replace(inside.begin(), inside.end(), ',', ' ');
  std::istringstream in(inside);
  std::vector<double> numbers;
  for (double v; in >> v;) numbers.push_back(v);
  return numbers;
}

PlySample ply_sample() {
  PlySample s;
  s.xyz = {{0.5f, -1.25f, 2.0f}, {1.0f, 0.0f, 0.0f}, {-3.5f, 4.0f, 1e-3f}, {100.0f, -200.0f, 0.25f}, {7.0f, 8.0f, 9.0f}};
  s.rgb = {{255, 0, 10}, {1, 2, 3}, {128, 64, 32}, {0, 0, 0}, {200, 201, 202}};
  s.faces = {{0, 1, 2}, {1, 2, 3, 4}, {4, 3, 2, 1, 0}, {0, 4}};
  return s;
}

Bytes ply_bytes(const PlySample& s, const std::string& encoding, bool int_counts) {
  const bool ascii = encoding == "ascii";
  const bool big = encoding == "binary_big_endian";
  Bytes out;
  put_text(out, "ply\nformat " + encoding + " 1.0\ncomment made by the vola tests\nobj_info nothing to see\n");
  put_text(out, "element edge 2\nproperty list uchar float weights\nproperty int id\n");
  put_text(out, "element vertex " + std::to_string(s.xyz.size()) +
                    "\nproperty float x\nproperty float y\nproperty float quality\nproperty float z\n"
                    "property uchar red\nproperty uchar green\nproperty uchar blue\n");
  put_text(out, "element face " + std::to_string(s.faces.size()) + "\nproperty list " + (int_counts ? "int" : "uchar") +
                    " int vertex_indices\nproperty list uchar float texcoord\nend_header\n");
  // edges: (2 weights, id), (0 weights, id)
  if (ascii) {
    put_text(out, "2 0.5 0.25 7\n0 -8\n");
  } else {
    put<std::uint8_t>(out, 2);
    put<float>(out, 0.5f, big);
    put<float>(out, 0.25f, big);
    put<std::int32_t>(out, 7, big);
    put<std::uint8_t>(out, 0);
    put<std::int32_t>(out, -8, big);
  }
  for (std::size_t i = 0; i < s.xyz.size(); ++i) {
    const float quality = static_cast<float>(i) * 0.5f;
    if (ascii) {
      std::ostringstream line;
      line.precision(9);
      line << s.xyz[i][0] << ' ' << s.xyz[i][1] << ' ' << quality << ' ' << s.xyz[i][2] << ' ' << int{s.rgb[i][0]}
           << ' ' << int{s.rgb[i][1]} << ' ' << int{s.rgb[i][2]} << '\n';
      put_text(out, line.str());
    } else {
      put<float>(out, s.xyz[i][0], big);
      put<float>(out, s.xyz[i][1], big);
      put<float>(out, quality, big);
      put<float>(out, s.xyz[i][2], big);
      for (std::uint8_t c : s.rgb[i]) put<std::uint8_t>(out, c);
    }
  }
  for (std::size_t f = 0; f < s.faces.size(); ++f) {
    const auto& face = s.faces[f];
    if (ascii) {
      std::string line = std::to_string(face.size());
      for (int v : face) {
        line += ' ';
        line += std::to_string(v);
      }
      line += f % 2 ? " 2 0.1 0.2\n" : " 0\n";
      put_text(out, line);
    } else {
      if (int_counts) put<std::int32_t>(out, static_cast<std::int32_t>(face.size()), big);
      else put<std::uint8_t>(out, static_cast<std::uint8_t>(face.size()));
      for (int v : face) put<std::int32_t>(out, v, big);
      if (f % 2) {
        put<std::uint8_t>(out, 2);
        put<float>(out, 0.1f, big);
        put<float>(out, 0.2f, big);
      } else {
        put<std::uint8_t>(out, 0);
      }
    }
  }
  return out;
}

std::vector<std::array<int, 3>> fan_triangles(const std::vector<std::vector<int>>& faces) {
  std::vector<std::array<int, 3>> triangles;
  for (const auto& f : faces)
    for (std::size_t k = 1; k + 1 < f.size(); ++k) triangles.push_back({f[0], f[k], f[k + 1]});
  return triangles;
}

Bytes npy_bytes(const std::string& dtype, const std::vector<std::uint64_t>& shape, bool fortran_order, const Bytes& data) {
  std::string shape_text = "(";
  for (auto d : shape) shape_text += std::to_string(d) + ", ";
  if (shape.size() > 1) shape_text.resize(shape_text.size() - 1);  // "(3, 4," -> numpy writes "(3, 4)"
  if (shape.size() > 1) shape_text.back() = ')';
  else shape_text += ")";
  std::string header = "{'descr': '" + dtype + "', 'fortran_order': " + (fortran_order ? "True" : "False") +
                       ", 'shape': " + shape_text + ", }";
  while ((10 + header.size() + 1) % 64 != 0) header += ' ';
  header += '\n';
  Bytes out = {0x93, 'N', 'U', 'M', 'P', 'Y', 1, 0};
  put<std::uint16_t>(out, static_cast<std::uint16_t>(header.size()));
  put_text(out, header);
  out.insert(out.end(), data.begin(), data.end());
  return out;
}

}  // namespace vola_io_test
