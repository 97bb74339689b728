// How strongly each voxel reflects sound: a pressure reflection coefficient in [0, 1]
// (1 = a perfect mirror, 0 = fully absorbing), either one value for every frequency or
// one per octave band (kOctaveBands). It comes from, in this order of use:
//   (a) one scene-wide value,
//   (b) a material table (JSON) mapping a material id to a coefficient, the id read per
//       voxel from an attribute column (e.g. LAS "classification") or the payload byte,
//   (c) the payload byte itself as a coefficient (byte / 255).
//
// The JSON table (every key but "materials" optional):
//   {
//     "attribute": "classification",   // column holding material ids; "payload" = payload byte
//     "default": 0.3,                  // for ids the table does not list
//     "materials": {
//       "2": 0.2,                                  // one coefficient for all frequencies
//       "6": [0.98, 0.97, 0.96, 0.95, 0.93, 0.90]  // 125, 250, 500, 1000, 2000, 4000 Hz
//     }
//   }
#pragma once

#include <array>
#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

#include "vola/tree.hpp"

namespace vola::audio {

// Centre frequencies (Hz) of the octave bands a per-band coefficient lists.
inline constexpr std::array<double, 6> kOctaveBands{125, 250, 500, 1000, 2000, 4000};

// One material: a single coefficient (bands.size() == 1) or one per octave band.
struct Material {
  std::vector<double> bands{0.5};
  bool per_band() const noexcept { return bands.size() > 1; }
  friend bool operator==(const Material&, const Material&) = default;
};

enum class MaterialSource : std::uint8_t {
  scene,           // every voxel: the default material
  attribute,       // table lookup of an attribute column's value
  payload_id,      // table lookup of the voxel payload's low byte
  payload_value,   // the payload's low byte / 255 as the coefficient
};

struct MaterialTable {
  MaterialSource source = MaterialSource::scene;
  std::string attribute;                  // for MaterialSource::attribute
  Material fallback;                      // the scene-wide value, or ids not listed
  std::vector<std::pair<std::int64_t, Material>> materials;  // id -> material, ids unique
};

// A scene-wide coefficient. Throws InvalidArgument outside [0, 1].
MaterialTable scene_material(double coefficient);
// Parses a JSON table; `name` labels errors ("m.json: line 3, column 7: ..." for syntax,
// "m.json: materials.\"6\": ..." for values). Throws FormatError.
MaterialTable parse_material_table(std::string_view json, const std::string& name);
// Reads and parses a file. Throws IoError when it cannot be read.
MaterialTable read_material_table(const std::string& path);

// The table resolved against one tree: every voxel gets a slot; slots with the same
// material share one. Slot 0 is the fallback.
class VoxelMaterials {
 public:
  // Throws InvalidArgument when the tree lacks the attribute column or the payload the
  // table reads.
  VoxelMaterials(const MaterialTable& table, const Tree& tree);

  // The slot of the voxel of `rank` in leaf block `leaf_block` (see Tree::voxel_payload_at_rank).
  std::uint16_t slot(std::uint64_t rank, std::size_t leaf_block) const;
  const std::vector<Material>& slots() const noexcept { return slots_; }

 private:
  std::uint16_t slot_of_id(std::int64_t id) const noexcept;
  std::uint16_t add_slot(const Material& material);

  const Tree* tree_;
  MaterialSource source_;
  const AttributeColumn* column_ = nullptr;
  std::vector<Material> slots_;
  std::vector<std::uint16_t> small_ids_;  // slot per id 0..small_ids_.size()-1
  std::vector<std::pair<std::int64_t, std::uint16_t>> other_ids_;  // sorted by id
};

}  // namespace vola::audio
