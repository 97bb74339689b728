#include "vola/audio/materials.hpp"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <fstream>
#include <iterator>
#include <map>
#include <nlohmann/json.hpp>
#include <sstream>

#include "vola/error.hpp"

namespace vola::audio {

namespace {

// Ids below this are looked up in a flat array (LAS classes, payload bytes).
constexpr std::int64_t kSmallIds = 65536;

void check_coefficient(double c, const std::string& what) {
  if (!(c >= 0.0 && c <= 1.0)) throw InvalidArgument(what + " must be in [0, 1]");
}

Material parse_material(const nlohmann::json& value, const std::string& name, const std::string& where) {
  auto fail = [&](const std::string& cause) -> FormatError { return FormatError(name, std::nullopt, where + ": " + cause); };
  Material m;
  if (value.is_number()) {
    m.bands = {value.get<double>()};
  } else if (value.is_array()) {
    if (value.size() != kOctaveBands.size())
      throw fail("a per-band coefficient lists " + std::to_string(kOctaveBands.size()) +
                 " values (125, 250, 500, 1000, 2000, 4000 Hz), not " + std::to_string(value.size()));
    m.bands.clear();
    for (const auto& v : value) {
      if (!v.is_number()) throw fail("band coefficients must be numbers");
      m.bands.push_back(v.get<double>());
    }
  } else {
    throw fail("expected a coefficient (number) or an array of 6 band coefficients");
  }
  for (std::size_t i = 0; i < m.bands.size(); ++i)
    if (!(m.bands[i] >= 0.0 && m.bands[i] <= 1.0)) {
      std::ostringstream s;
      s << (m.per_band() ? "band " + std::to_string(i) + " coefficient " : "coefficient ") << m.bands[i]
        << " is not in [0, 1]";
      throw fail(s.str());
    }
  return m;
}

}  // namespace

MaterialTable scene_material(double coefficient) {
  check_coefficient(coefficient, "the reflection coefficient");
  MaterialTable t;
  t.fallback.bands = {coefficient};
  return t;
}

MaterialTable parse_material_table(std::string_view text, const std::string& name) {
  nlohmann::json doc;
  try {
    doc = nlohmann::json::parse(text.begin(), text.end());
  } catch (const nlohmann::json::parse_error& e) {
    // e.what() reads "[json.exception.parse_error.101] parse error at line 3, column 7: ..."
    std::string what = e.what();
    const auto at = what.find("at line");
    throw FormatError(name, e.byte > 0 ? std::optional<std::uint64_t>(e.byte - 1) : std::nullopt,
                      "invalid JSON " + (at == std::string::npos ? what : what.substr(at)));
  } catch (const nlohmann::json::exception& e) {
    // A number beyond the range of doubles ("1e999") is nlohmann's out_of_range, not a
    // parse_error: "[json.exception.out_of_range.406] number overflow parsing '1e999'".
    const std::string what = e.what();
    const auto at = what.find("] ");
    throw FormatError(name, std::nullopt, "invalid JSON: " + (at == std::string::npos ? what : what.substr(at + 2)));
  }
  if (!doc.is_object()) throw FormatError(name, std::nullopt, "the material table must be a JSON object");
  MaterialTable t;
  for (const auto& [key, value] : doc.items()) {
    if (key != "attribute" && key != "default" && key != "materials")
      throw FormatError(name, std::nullopt,
                        "unknown key \"" + key + "\" (expected \"attribute\", \"default\", \"materials\")");
  }
  if (doc.contains("default")) t.fallback = parse_material(doc["default"], name, "default");
  if (doc.contains("attribute")) {
    if (!doc["attribute"].is_string() || doc["attribute"].get<std::string>().empty())
      throw FormatError(name, std::nullopt, "attribute: expected a column name or \"payload\"");
    t.attribute = doc["attribute"].get<std::string>();
    t.source = t.attribute == "payload" ? MaterialSource::payload_id : MaterialSource::attribute;
    if (t.source == MaterialSource::payload_id) t.attribute.clear();
  }
  if (!doc.contains("materials") || !doc["materials"].is_object())
    throw FormatError(name, std::nullopt, "missing \"materials\": an object mapping material ids to coefficients");
  // JSON keeps one member per key, but "2" and "02" (or "0" and "-0") are different keys
  // for the same id: each id may be listed once.
  std::map<std::int64_t, std::string> keys;
  for (const auto& [key, value] : doc["materials"].items()) {
    const std::string where = "materials.\"" + key + "\"";
    std::int64_t id = 0;
    const auto [end, ec] = std::from_chars(key.data(), key.data() + key.size(), id);
    if (ec != std::errc() || end != key.data() + key.size())
      throw FormatError(name, std::nullopt, where + ": a material id must be an integer");
    const auto [previous, added] = keys.emplace(id, key);
    if (!added)
      throw FormatError(name, std::nullopt,
                        where + ": material id " + std::to_string(id) + " is already listed as \"" + previous->second + "\"");
    t.materials.emplace_back(id, parse_material(value, name, where));
  }
  if (t.source == MaterialSource::scene && !t.materials.empty())
    throw FormatError(name, std::nullopt,
                      "\"materials\" lists ids but no \"attribute\" says where a voxel's id is (e.g. \"classification\" or \"payload\")");
  return t;
}

MaterialTable read_material_table(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw IoError("cannot open material table " + path);
  const std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  if (in.bad()) throw IoError("cannot read material table " + path);
  return parse_material_table(text, path);
}

VoxelMaterials::VoxelMaterials(const MaterialTable& table, const Tree& tree) : tree_(&tree), source_(table.source) {
  slots_.push_back(table.fallback);
  switch (source_) {
    case MaterialSource::scene:
      return;
    case MaterialSource::attribute:
      column_ = tree.attributes().find(table.attribute);
      if (!column_) {
        std::string have;
        for (const auto& c : tree.attributes().columns()) have += (have.empty() ? "" : ", ") + c.name();
        throw InvalidArgument("the scene has no attribute \"" + table.attribute + "\" for the material table (it has: " +
                              (have.empty() ? "none" : have) + ")");
      }
      break;
    case MaterialSource::payload_id:
    case MaterialSource::payload_value:
      if (!tree.has_payload()) throw InvalidArgument("the scene has no payload to read materials from");
      break;
  }
  if (source_ == MaterialSource::payload_value) {
    small_ids_.resize(256);
    for (int b = 0; b < 256; ++b) small_ids_[b] = add_slot(Material{{b / 255.0}});
    return;
  }
  for (const auto& [id, material] : table.materials) {
    const std::uint16_t s = add_slot(material);
    if (id >= 0 && id < kSmallIds) {
      if (small_ids_.size() <= static_cast<std::size_t>(id)) small_ids_.resize(static_cast<std::size_t>(id) + 1, 0);
      small_ids_[static_cast<std::size_t>(id)] = s;
    } else {
      other_ids_.emplace_back(id, s);
    }
  }
  std::sort(other_ids_.begin(), other_ids_.end());
}

std::uint16_t VoxelMaterials::add_slot(const Material& material) {
  const auto it = std::find(slots_.begin(), slots_.end(), material);
  if (it != slots_.end()) return static_cast<std::uint16_t>(it - slots_.begin());
  if (slots_.size() >= 65535) throw InvalidArgument("the material table has more than 65534 distinct materials");
  slots_.push_back(material);
  return static_cast<std::uint16_t>(slots_.size() - 1);
}

std::uint16_t VoxelMaterials::slot_of_id(std::int64_t id) const noexcept {
  if (id >= 0 && static_cast<std::uint64_t>(id) < small_ids_.size()) return small_ids_[static_cast<std::size_t>(id)];
  const auto it = std::lower_bound(other_ids_.begin(), other_ids_.end(), std::pair<std::int64_t, std::uint16_t>{id, 0});
  return it != other_ids_.end() && it->first == id ? it->second : 0;
}

std::uint16_t VoxelMaterials::slot(std::uint64_t rank, std::size_t leaf_block) const {
  switch (source_) {
    case MaterialSource::scene:
      return 0;
    case MaterialSource::attribute: {
      const double v = column_->get(static_cast<std::size_t>(rank));
      // Ids are integers; a fractional value (a "mean" column) rounds to the nearest.
      if (!std::isfinite(v) || std::abs(v) > 9e15) return 0;
      return slot_of_id(static_cast<std::int64_t>(std::llround(v)));
    }
    case MaterialSource::payload_id:
    case MaterialSource::payload_value:
      return slot_of_id(static_cast<std::int64_t>(tree_->voxel_payload_at_rank(rank, leaf_block) & 0xffu));
  }
  return 0;
}

}  // namespace vola::audio
