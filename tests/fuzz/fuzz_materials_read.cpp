// Fuzz entry point of the material table reader (audio::parse_material_table, the JSON
// that vola sonify --materials reads): the input is the file's text. Only vola::Error may
// escape (nlohmann's own exceptions must have become FormatErrors); a table that parses
// holds coefficients in [0, 1], one or six per material, ids unique, and ids only with an
// attribute to read them from. The table is then resolved against a small tree with a
// payload and a "classification" column, as sonify does.
#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <string_view>
#include <vector>

#include "fuzz_seeds.hpp"
#include "vola/audio/materials.hpp"
#include "vola/error.hpp"
#include "vola/vola.hpp"

namespace {

using vola_fuzz::check;

void check_material(const vola::audio::Material& m) {
  check(m.bands.size() == 1 || m.bands.size() == vola::audio::kOctaveBands.size());
  for (double c : m.bands) check(c >= 0.0 && c <= 1.0);
}

// Eight points with payload bytes and a "classification" column of ids 0..7.
const vola::Tree& scene() {
  static const vola::Tree tree = [] {
    vola::PointCloud cloud;
    vola::PointAttribute classes{"classification", vola::ValueType::u8, vola::Reduction::majority, {}};
    for (int i = 0; i < 8; ++i) {
      cloud.xyz.insert(cloud.xyz.end(), {double(i), double(i % 3), double(i / 3)});
      cloud.payload.push_back(static_cast<std::uint64_t>(i * 37));
      classes.values.push_back(i);
    }
    cloud.attributes.push_back(classes);
    vola::BuildOptions options;
    options.depth = 3;
    options.payload = true;
    return vola::build(cloud, options);
  }();
  return tree;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string_view text(reinterpret_cast<const char*>(data), size);
  try {
    const vola::audio::MaterialTable table = vola::audio::parse_material_table(text, "fuzz.json");
    check_material(table.fallback);
    std::vector<std::int64_t> ids;
    for (const auto& [id, material] : table.materials) {
      check_material(material);
      ids.push_back(id);
    }
    std::sort(ids.begin(), ids.end());
    check(std::adjacent_find(ids.begin(), ids.end()) == ids.end());
    check(table.source != vola::audio::MaterialSource::scene || table.materials.empty());
    check(table.source != vola::audio::MaterialSource::attribute || !table.attribute.empty());
    ++vola_fuzz::stats().parsed;
    try {
      const vola::audio::VoxelMaterials resolved(table, scene());
      check(!resolved.slots().empty() && resolved.slots().size() <= table.materials.size() + 257);
    } catch (const vola::InvalidArgument&) {
      // the scene lacks the column or the payload the table reads
    }
  } catch (const vola::InvalidArgument&) {
    std::abort();  // the parser reports FormatErrors only
  } catch (const vola::Error&) {
    ++vola_fuzz::stats().refused;
  }
  return 0;
}
