#include "vola/viewer/viewed_file.hpp"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <nlohmann/json.hpp>

#include "crs_units.hpp"
#include "json_point.hpp"
#include "vola/analysis/census.hpp"
#include "vola/error.hpp"
#include "vola/map/state_map.hpp"
#include "vola/raycast/ray_caster.hpp"

namespace vola::viewer {

namespace {

const AttributeColumn* find_column(const Tree& tree, const char* name) {
  const AttributeColumn* c = tree.attributes().find(name);
  return c && c->size() == tree.voxel_count() ? c : nullptr;
}

std::uint8_t clamp_byte(double v) noexcept {
  return static_cast<std::uint8_t>(std::clamp(v, 0.0, 255.0));
}

void put_u32(std::string& out, std::size_t at, std::uint32_t v) {
  for (int i = 0; i < 4; ++i) out[at + i] = static_cast<char>((v >> (8 * i)) & 0xffu);
}
void put_u64(std::string& out, std::size_t at, std::uint64_t v) {
  for (int i = 0; i < 8; ++i) out[at + i] = static_cast<char>((v >> (8 * i)) & 0xffu);
}

// The voxels shown: a state map's occupied or free part (copied out of the mapping,
// which is checked after), any other file as mapped.
Tree shown_tree(const std::string& path, FileLayout& layout, MapPart part, bool& state_map) {
  const Tree file = open_mapped(path, &layout);
  state_map = map::is_state_map(file);
  if (!state_map) {
    if (part == MapPart::free)
      throw InvalidArgument(path + ": not a state map (vola map writes one): it has no free voxels to show");
    return file;
  }
  Tree shown = part == MapPart::free ? map::free_tree(file) : map::occupied_tree(file);
  check_mapped(file);
  return shown;
}

}  // namespace

ViewedFile::ViewedFile(const std::string& path, MapPart part)
    : path_(path),
      name_(std::filesystem::path(path).filename().string() + (part == MapPart::free ? " (free)" : "")),
      tree_(shown_tree(path, layout_, part, state_map_)),
      index_(tree_),
      levels_(static_cast<std::size_t>(tree_.depth())) {
  classes_ = find_column(tree_, "classification");
  rgb_ = {find_column(tree_, "red"), find_column(tree_, "green"), find_column(tree_, "blue")};
  if (!rgb_[0] || !rgb_[1] || !rgb_[2]) rgb_ = {};
  if (rgb_[0]) {
    // LAS stores 16-bit colours, most other sources 8-bit: scale by what the file holds.
    double max = 0.0;
    for (const auto* c : rgb_)
      for (std::size_t r = 0; r < c->size(); ++r) max = std::max(max, c->get(r));
    rgb_shift_ = max > 255.0 ? 8 : 0;
  }
  if (!tree_.empty()) {
    voxels_min_ = Voxel{tree_.side(), tree_.side(), tree_.side()};
    tree_.for_each_voxel([&](const Voxel& v) {
      voxels_min_ = Voxel{std::min(voxels_min_.x, v.x), std::min(voxels_min_.y, v.y), std::min(voxels_min_.z, v.z)};
      voxels_max_ = Voxel{std::max(voxels_max_.x, v.x), std::max(voxels_max_.y, v.y), std::max(voxels_max_.z, v.z)};
    });
  }
  if (classes_) {
    class_counts_.assign(256, 0);
    for (std::size_t r = 0; r < classes_->size(); ++r) ++class_counts_[clamp_byte(classes_->get(r))];
  }
}

ViewedFile::~ViewedFile() = default;

void ViewedFile::check_level(int level) const {
  if (level < 0 || level >= tree_.depth())
    throw InvalidArgument(name_ + ": level " + std::to_string(level) + " is outside 0.." +
                          std::to_string(tree_.depth() - 1));
}

nlohmann::json ViewedFile::metadata() const {
  using nlohmann::json;
  const Frame frame = tree_.frame();
  json levels = json::array();
  for (int l = 0; l < tree_.depth(); ++l)
    levels.push_back({{"level", l},
                      {"cells", index_.cell_count(l)},
                      {"side", side_of(l + 1)},
                      {"cell_size", frame.voxel_size * std::pow(4.0, tree_.depth() - 1 - l)}});
  json attributes = json::array();
  for (const auto& c : tree_.attributes().columns())
    attributes.push_back({{"name", c.name()}, {"type", std::string(name_of(c.type()))}});
  json classes = json::array();
  for (std::size_t code = 0; code < class_counts_.size(); ++code)
    if (class_counts_[code])
      classes.push_back({{"code", code},
                         {"name", std::string(analysis::asprs_class_name(static_cast<int>(code)))},
                         {"voxels", class_counts_[code]}});
  return {{"name", name_},
          {"file_bytes", layout_.file_size},
          {"voxels", tree_.voxel_count()},
          {"voxels_min", {voxels_min_.x, voxels_min_.y, voxels_min_.z}},
          {"voxels_max", {voxels_max_.x, voxels_max_.y, voxels_max_.z}},
          {"depth", tree_.depth()},
          {"side", tree_.side()},
          {"levels", levels},
          {"quantization", frame.quantization == Quantization::grid ? "grid" : "toolkit"},
          {"origin", json_point(frame.origin)},
          {"voxel_size", frame.voxel_size},
          {"epsg", layout_.header.epsg},
          {"crs_wkt", tree_.georef().crs_wkt},
          {"units", crs_units(tree_.georef())},
          {"attributes", attributes},
          {"has_classes", classes_ != nullptr},
          {"has_colours", rgb_[0] != nullptr},
          {"classes", classes},
          {"state_map", state_map_}};
}

std::string ViewedFile::cell_batch(int level, std::uint64_t first, std::uint64_t count) const {
  check_level(level);
  if (count > kMaxBatchCells)
    throw InvalidArgument("a batch holds at most " + std::to_string(kMaxBatchCells) + " cells, not " +
                          std::to_string(count));
  const std::uint64_t total = index_.cell_count(level);
  const std::uint64_t n = first < total ? std::min(count, total - first) : 0;
  const std::uint32_t coordinate_bytes = level < 8 ? 2 : 4;  // side 4^(level+1) <= 65536
  const std::uint32_t flags = (classes_ ? kBatchFlagClasses : 0) | (rgb_[0] ? kBatchFlagColours : 0);
  const std::size_t coords_at = kBatchHeaderBytes;
  const std::size_t classes_at = coords_at + n * 3 * coordinate_bytes;
  const std::size_t colours_at = classes_at + (classes_ ? n : 0);
  std::string out(colours_at + (rgb_[0] ? 3 * n : 0), '\0');
  std::memcpy(out.data(), "VOLC", 4);
  put_u32(out, 4, static_cast<std::uint32_t>(level));
  put_u32(out, 8, coordinate_bytes);
  put_u32(out, 12, flags);
  put_u64(out, 16, first);
  put_u64(out, 24, n);
  char* coords = out.data() + coords_at;
  index_.for_each_cell(level, first, n, [&](std::uint64_t i, const Voxel& c) {
    const std::uint32_t xyz[3] = {c.x, c.y, c.z};
    for (int a = 0; a < 3; ++a)
      for (std::uint32_t b = 0; b < coordinate_bytes; ++b) *coords++ = static_cast<char>((xyz[a] >> (8 * b)) & 0xffu);
    if (!classes_ && !rgb_[0]) return;
    const std::uint64_t rank = index_.first_voxel_rank(level, i);
    const std::size_t k = static_cast<std::size_t>(i - first);
    if (classes_) out[classes_at + k] = static_cast<char>(clamp_byte(classes_->get(rank)));
    if (rgb_[0])
      for (int ch = 0; ch < 3; ++ch)
        out[colours_at + 3 * k + ch] =
            static_cast<char>(clamp_byte(std::floor(rgb_[ch]->get(rank)) / (rgb_shift_ ? 256.0 : 1.0)));
  });
  return out;
}

const ViewedFile::LevelView& ViewedFile::level_view(int level) const {
  check_level(level);
  std::lock_guard lock(levels_mutex_);
  auto& view = levels_[static_cast<std::size_t>(level)];
  if (!view) {
    view = std::make_unique<LevelView>();
    view->tree = tree_.level_of_detail(level + 1);
    view->caster = std::make_unique<raycast::RayCaster>(view->tree);
  }
  return *view;
}

nlohmann::json ViewedFile::cell_info(int level, const Voxel& cell) const {
  check_level(level);
  const std::uint32_t side = side_of(level + 1);
  if (cell.x >= side || cell.y >= side || cell.z >= side)
    throw InvalidArgument("cell (" + std::to_string(cell.x) + ", " + std::to_string(cell.y) + ", " +
                          std::to_string(cell.z) + ") is off the level-" + std::to_string(level) + " grid of side " +
                          std::to_string(side));
  const Frame frame = tree_.frame();
  const int below = tree_.depth() - 1 - level;
  const std::uint32_t span = std::uint32_t{1} << (2 * below);  // voxels per cell edge
  const double size = frame.voxel_size * span;
  const Point centre{frame.origin[0] + (cell.x + 0.5) * size, frame.origin[1] + (cell.y + 0.5) * size,
                     frame.origin[2] + (cell.z + 0.5) * size};
  nlohmann::json info = {{"level", level},
                         {"cell", {cell.x, cell.y, cell.z}},
                         {"cell_size", size},
                         {"centre", json_point(centre)},
                         {"voxels_from", {cell.x * span, cell.y * span, cell.z * span}},
                         {"voxels_to", {cell.x * span + span - 1, cell.y * span + span - 1, cell.z * span + span - 1}}};
  const auto cell_rank = level_view(level).tree.rank(cell);
  info["occupied"] = cell_rank.has_value();
  if (!cell_rank) return info;
  // The cell's first voxel in key order speaks for it (the voxel itself at the finest level).
  const std::uint64_t rank = index_.first_voxel_rank(level, *cell_rank);
  const Voxel voxel = index_.cell(tree_.depth() - 1, rank);
  info["voxel"] = {voxel.x, voxel.y, voxel.z};
  info["rank"] = rank;
  info["voxel_centre"] = json_point(tree_.quantizer().center(voxel));
  nlohmann::json attributes = nlohmann::json::object();
  for (const auto& c : tree_.attributes().columns())
    if (rank < c.size()) attributes[c.name()] = c.get(rank);
  info["attributes"] = attributes;
  if (classes_)
    info["class_name"] = std::string(analysis::asprs_class_name(clamp_byte(classes_->get(rank))));
  return info;
}

nlohmann::json ViewedFile::pick(int level, const raycast::Ray& ray) const {
  raycast::check_ray(ray);
  const auto& view = level_view(level);
  const auto hit = view.caster->cast(ray);
  if (!hit) return {{"hit", false}};
  nlohmann::json info = cell_info(level, hit->voxel);
  info["hit"] = true;
  info["t"] = hit->t;
  return info;
}

}  // namespace vola::viewer
