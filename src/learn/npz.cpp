#include "vola/learn/npz.hpp"

#include <cstdio>

#include "vola/error.hpp"

namespace vola::learn {

namespace {

// A label as the file holds it: integers without a fraction (they were printed as
// "99.000000", and 2^40 as "1099511627776.000000").
std::string label_text(double label) {
  char text[32];
  std::snprintf(text, sizeof text, "%.17g", label);
  return text;
}

}  // namespace

LabelledGrids read_labelled_grids(const std::string& path, const std::string& split_wanted) {
  std::string split = split_wanted;
  if (split.empty()) {
    std::vector<std::string> candidates;
    for (const auto& name : io::npz_array_names(path))
      if (name.starts_with("X_")) candidates.push_back(name.substr(2));
    if (candidates.size() != 1)
      throw FormatError(path, std::nullopt,
                        candidates.empty() ? "no X_<split> array (expected X_<split> grids and y_<split> labels)"
                                           : "several X_<split> arrays: name the split");
    split = candidates.front();
  }
  const std::string x_name = "X_" + split, y_name = "y_" + split;
  const io::NpyArray x = io::read_npz_array(path, x_name);
  const io::NpyArray y = io::read_npz_array(path, y_name);
  const std::string x_where = path + ":" + x_name;
  const std::string y_where = path + ":" + y_name;

  if (x.shape.size() != 4 || x.shape[1] != x.shape[2] || x.shape[2] != x.shape[3] || x.shape[1] < 4 || x.shape[1] > 256) {
    std::string shape;
    for (auto s : x.shape) {
      if (!shape.empty()) shape += ',';
      shape += std::to_string(s);
    }
    throw FormatError(x_where, std::nullopt, "shape (" + shape + "): expected (N, S, S, S) grids with 4 <= S <= 256");
  }
  if (x.kind != 'u' && x.kind != 'i' && x.kind != 'b' && x.kind != 'f')
    throw FormatError(x_where, std::nullopt, "dtype " + x.dtype() + ": expected integer, bool or float 0/1 cells");
  if (y.shape.size() != 1 || y.shape[0] != x.shape[0])
    throw FormatError(y_where, std::nullopt,
                      "expected one label per grid (" + std::to_string(x.shape[0]) + "), shape has " +
                          std::to_string(y.shape.size()) + " dimensions" +
                          (y.shape.empty() ? "" : " and " + std::to_string(y.shape[0]) + " entries"));
  if (y.kind != 'u' && y.kind != 'i') throw FormatError(y_where, std::nullopt, "dtype " + y.dtype() + ": expected integer labels");

  LabelledGrids grids;
  grids.split = split;
  grids.side = static_cast<int>(x.shape[1]);
  grids.labels.resize(y.shape[0]);
  for (std::uint64_t i = 0; i < y.shape[0]; ++i) {
    const double label = y.value(i);
    if (!(label >= 0 && label <= 9))
      throw FormatError(y_where, std::nullopt,
                        "grid " + std::to_string(i) + "'s label is " + label_text(label) + ", not 0..9");
    grids.labels[i] = static_cast<int>(label);
  }
  grids.cells.resize(x.size());
  for (std::uint64_t i = 0; i < grids.cells.size(); ++i) {
    const double v = x.value(i);
    if (v != 0 && v != 1)
      throw FormatError(x_where, std::nullopt,
                        "grid " + std::to_string(i / grids.cells_per_grid()) + " holds " + std::to_string(v) +
                            ": expected 0/1 occupancy");
    grids.cells[i] = static_cast<std::uint8_t>(v);
  }
  return grids;
}

}  // namespace vola::learn
