#include "vola/filters/dimensions.hpp"

#include <cctype>

namespace vola::filters {

std::string dimension_key(const std::string& name) {
  std::string key;
  // Spaces and bytes outside printable ASCII too: the text and PLY writers turn them into
  // '_' ("echo width" is echo_width in an .xyz header), so either spelling finds the column.
  for (const char c : name)
    if (c != '_' && c > ' ' && c <= '~') key += static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return key;
}

namespace {

// PDAL's names for LAS fields that vola's columns spell otherwise (after dimension_key).
std::string vola_spelling(const std::string& key) {
  if (key == "scanchannel") return "scannerchannel";
  if (key == "infrared") return "nir";
  if (key == "classflags") return "classificationflags";
  return key;
}

}  // namespace

std::optional<Dimension> find_dimension(const PointCloud& cloud, const std::string& name) {
  const std::string key = vola_spelling(dimension_key(name));
  for (std::size_t c = 0; c < cloud.attributes.size(); ++c)
    if (dimension_key(cloud.attributes[c].name) == key) return Dimension{-1, c};
  static constexpr const char* kFlagBits[] = {"synthetic", "keypoint", "withheld", "overlap"};
  for (int bit = 0; bit < 4; ++bit)
    if (key == kFlagBits[bit])
      for (std::size_t c = 0; c < cloud.attributes.size(); ++c)
        if (cloud.attributes[c].name == "classification_flags") return Dimension{-1, c, bit};
  if (key == "x") return Dimension{0, 0};
  if (key == "y") return Dimension{1, 0};
  if (key == "z") return Dimension{2, 0};
  return std::nullopt;
}

std::string dimension_list(const PointCloud& cloud) {
  std::string list = "x, y, z";
  for (const auto& a : cloud.attributes) list += ", " + a.name;
  return list;
}

std::size_t ensure_column(PointCloud& cloud, const std::string& name, ValueType type, Reduction reduction) {
  if (const auto d = find_dimension(cloud, name); d && d->axis < 0 && d->bit < 0) return d->column;
  cloud.attributes.push_back({name, type, reduction, std::vector<double>(cloud.size(), 0.0)});
  return cloud.attributes.size() - 1;
}

}  // namespace vola::filters
