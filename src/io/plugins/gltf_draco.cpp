#include "gltf_draco.hpp"

#include <algorithm>
#include <array>
#include <cstdint>
#include <cstring>
#include <limits>
#include <map>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include <draco/compression/decode.h>
#include <draco/core/decoder_buffer.h>
#include <draco/mesh/mesh.h>
#include <nlohmann/json.hpp>

#include "vola/error.hpp"
#include "vola/io/mesh.hpp"

namespace vola::io {

namespace {

using nlohmann::json;

const std::string kDraco = "KHR_draco_mesh_compression";
constexpr std::uint32_t kChunkJson = 0x4E4F534Au;  // "JSON"
constexpr std::uint32_t kChunkBin = 0x004E4942u;   // "BIN\0"
constexpr int kFloat = 5126, kUnsignedInt = 5125, kTriangles = 4;

std::uint32_t u32_at(std::string_view bytes, std::size_t at) {
  std::uint32_t v;
  std::memcpy(&v, bytes.data() + at, 4);
  return v;  // glb is little-endian, as every machine vola builds for
}

void append_u32(std::string& out, std::uint32_t v) { out.append(reinterpret_cast<const char*>(&v), 4); }

// The two chunks of a .glb; nullopt when `file` is not one this reader can take apart
// (Assimp then gives its own error).
struct Glb {
  std::string_view json;
  std::optional<std::string_view> bin;
  std::size_t bin_offset = 0;  // of the BIN chunk's data in the file
};

std::optional<Glb> split_glb(std::string_view file) {
  if (file.size() < 20 || u32_at(file, 4) != 2) return std::nullopt;
  const std::size_t length = std::min<std::size_t>(u32_at(file, 8), file.size());
  const std::size_t json_length = u32_at(file, 12);
  if (u32_at(file, 16) != kChunkJson || json_length > length - 20) return std::nullopt;
  Glb glb{file.substr(20, json_length), std::nullopt};
  const std::size_t next = 20 + json_length;
  if (next + 8 <= length && u32_at(file, next + 4) == kChunkBin) {
    const std::size_t bin_length = u32_at(file, next);
    if (bin_length > length - next - 8) return std::nullopt;
    glb.bin = file.substr(next + 8, bin_length);
    glb.bin_offset = next + 8;
  }
  return glb;
}

std::optional<std::string> base64_decoded(std::string_view text) {
  std::array<int, 256> value;
  value.fill(-1);
  const std::string_view alphabet = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
  for (std::size_t i = 0; i < alphabet.size(); ++i)
    value[static_cast<unsigned char>(alphabet[i])] = static_cast<int>(i);
  while (!text.empty() && text.back() == '=') text.remove_suffix(1);
  std::string out;
  out.reserve(text.size() / 4 * 3 + 3);
  std::uint32_t bits = 0;
  int count = 0;
  for (const char c : text) {
    const int v = value[static_cast<unsigned char>(c)];
    if (v < 0) return std::nullopt;
    bits = (bits << 6) | static_cast<std::uint32_t>(v);
    if (++count == 4) {
      out.push_back(static_cast<char>(bits >> 16));
      out.push_back(static_cast<char>(bits >> 8));
      out.push_back(static_cast<char>(bits));
      bits = 0;
      count = 0;
    }
  }
  if (count == 1) return std::nullopt;
  if (count >= 2) out.push_back(static_cast<char>(bits >> (6 * count - 8)));
  if (count == 3) out.push_back(static_cast<char>(bits >> 2));
  return out;
}

// A non-negative integer member of `object`, or `fallback` when absent.
std::uint64_t index_member(const json& object, const char* name, const std::string& path, const std::string& where,
                           std::optional<std::uint64_t> fallback = std::nullopt) {
  const auto it = object.find(name);
  if (it == object.end() && fallback) return *fallback;
  if (it == object.end() || !it->is_number_unsigned())
    throw FormatError(path, std::nullopt, where + ": '" + name + "' is missing or not a non-negative integer");
  return it->get<std::uint64_t>();
}

class DracoDecoding {
 public:
  DracoDecoding(const std::string& path, json& scene, const std::optional<Glb>& glb)
      : path_(path), scene_(scene), glb_(glb) {}

  // Decodes every Draco primitive into `bin_`, starting at `bin_base`; false when none.
  bool decode_all(std::size_t bin_base) {
    bin_.assign(bin_base, '\0');
    if (!scene_.contains("meshes") || !scene_["meshes"].is_array()) return false;
    json& meshes = scene_["meshes"];
    bool any = false;
    for (std::size_t m = 0; m < meshes.size(); ++m) {
      if (!meshes[m].is_object() || !meshes[m].contains("primitives") || !meshes[m]["primitives"].is_array()) continue;
      json& primitives = meshes[m]["primitives"];
      for (std::size_t p = 0; p < primitives.size(); ++p) {
        json& primitive = primitives[p];
        if (!primitive.is_object() || !primitive.contains("extensions") || !primitive["extensions"].is_object() ||
            !primitive["extensions"].contains(kDraco))
          continue;
        decode_primitive(primitive, "mesh " + std::to_string(m) + " primitive " + std::to_string(p));
        any = true;
      }
    }
    return any;
  }

  std::string take_bin() { return std::move(bin_); }

 private:
  // The bytes of buffer `b`, and where they start in the file (nullopt for a data: URI).
  std::pair<std::string_view, std::optional<std::size_t>> buffer(std::uint64_t b, const std::string& where) {
    const json& buffers = scene_["buffers"];
    if (!buffers.is_array() || b >= buffers.size() || !buffers[b].is_object())
      throw FormatError(
          path_, std::nullopt,
          where + ": its Draco data names buffer " + std::to_string(b) + ", which the scene does not have");
    const json& entry = buffers[b];
    if (!entry.contains("uri")) {
      if (b == 0 && glb_ && glb_->bin) return {*glb_->bin, glb_->bin_offset};
      throw FormatError(path_, std::nullopt,
                        where + ": buffer " + std::to_string(b) + " has no URI and no binary chunk");
    }
    const std::string uri = entry["uri"].is_string() ? entry["uri"].get<std::string>() : std::string();
    const std::size_t comma = uri.find(',');
    if (!uri.starts_with("data:") || comma == std::string::npos || uri.rfind(";base64", comma) == std::string::npos)
      throw FormatError(path_, std::nullopt,
                        where + ": its Draco data lies in another file, '" + uri +
                            "', and vola reads only the file it is given (a glTF with its buffers embedded, such as a "
                            ".glb, holds everything)");
    auto cached = decoded_uris_.find(b);
    if (cached == decoded_uris_.end()) {
      auto bytes = base64_decoded(std::string_view(uri).substr(comma + 1));
      if (!bytes)
        throw FormatError(path_, std::nullopt,
                          where + ": buffer " + std::to_string(b) + "'s data URI is not valid base64");
      cached = decoded_uris_.emplace(b, std::move(*bytes)).first;
    }
    return {cached->second, std::nullopt};
  }

  void decode_primitive(json& primitive, const std::string& where) {
    const json& extension = primitive["extensions"][kDraco];
    if (!extension.is_object()) throw FormatError(path_, std::nullopt, where + ": its " + kDraco + " is not an object");
    const std::uint64_t view_index = index_member(extension, "bufferView", path_, where);
    const json& views = scene_["bufferViews"];
    if (!views.is_array() || view_index >= views.size() || !views[view_index].is_object())
      throw FormatError(path_, std::nullopt,
                        where + ": its Draco data names buffer view " + std::to_string(view_index) +
                            ", which the scene does not have");
    const json& view = views[view_index];
    const std::string view_where = where + " (buffer view " + std::to_string(view_index) + ")";
    const std::uint64_t offset = index_member(view, "byteOffset", path_, view_where, 0);
    const std::uint64_t length = index_member(view, "byteLength", path_, view_where);
    const auto [bytes, file_offset] = buffer(index_member(view, "buffer", path_, view_where), where);
    if (offset > bytes.size() || length > bytes.size() - offset)
      throw FormatError(path_, file_offset,
                        view_where + ": bytes " + std::to_string(offset) + " + " + std::to_string(length) +
                            " lie past the end of its buffer's " + std::to_string(bytes.size()));
    const std::optional<std::size_t> at =
        file_offset ? std::optional<std::size_t>(*file_offset + offset) : std::nullopt;

    draco::DecoderBuffer input;
    input.Init(bytes.data() + offset, length);
    draco::Decoder decoder;
    auto decoded = decoder.DecodeMeshFromBuffer(&input);
    if (!decoded.ok()) throw FormatError(path_, at, where + ": Draco: " + decoded.status().error_msg_string());
    const draco::Mesh& mesh = *decoded.value();

    const json& attributes = extension.contains("attributes") ? extension["attributes"] : json();
    if (!attributes.is_object() || !attributes.contains("POSITION"))
      throw FormatError(path_, at, where + ": its Draco attributes do not include POSITION");
    const std::uint64_t position_id = index_member(attributes, "POSITION", path_, where + " (Draco attributes)");
    const draco::PointAttribute* position = position_id <= std::numeric_limits<std::uint32_t>::max()
                                                ? mesh.GetAttributeByUniqueId(static_cast<std::uint32_t>(position_id))
                                                : nullptr;
    if (!position || position->num_components() < 3)
      throw FormatError(
          path_, at,
          where + ": the Draco data has no three-component attribute " + std::to_string(position_id) + " for POSITION");
    faces_ += mesh.num_faces();
    if (faces_ > kMaxMeshTriangles)
      throw InvalidArgument(path_ + ": the scene's Draco meshes hold more than " + std::to_string(kMaxMeshTriangles) +
                            " faces");

    align_bin();
    const std::size_t positions_at = bin_.size();
    std::array<float, 3> low{}, high{};
    const std::uint32_t points = mesh.num_points();
    for (draco::PointIndex i(0); i < points; ++i) {
      std::array<float, 3> xyz;
      if (!position->ConvertValue<float>(position->mapped_index(i), 3, xyz.data()))
        throw FormatError(path_, at,
                          where + ": Draco position " + std::to_string(i.value()) + " cannot be read as numbers");
      for (int k = 0; k < 3; ++k) {
        low[k] = i.value() == 0 ? xyz[k] : std::min(low[k], xyz[k]);
        high[k] = i.value() == 0 ? xyz[k] : std::max(high[k], xyz[k]);
      }
      bin_.append(reinterpret_cast<const char*>(xyz.data()), sizeof xyz);
    }
    const std::size_t indices_at = bin_.size();
    for (draco::FaceIndex f(0); f < mesh.num_faces(); ++f)
      for (int k = 0; k < 3; ++k) {
        const std::uint32_t index = mesh.face(f)[k].value();
        if (index >= points)
          throw FormatError(path_, at,
                            where + ": Draco face " + std::to_string(f.value()) + " names point " +
                                std::to_string(index) + " of " + std::to_string(points));
        append_u32(bin_, index);
      }

    json& views_out = scene_["bufferViews"];
    json& accessors = scene_["accessors"];
    if (!accessors.is_array()) accessors = json::array();
    views_out.push_back({{"buffer", 0}, {"byteOffset", positions_at}, {"byteLength", indices_at - positions_at}});
    accessors.push_back({{"bufferView", views_out.size() - 1},
                         {"componentType", kFloat},
                         {"count", points},
                         {"type", "VEC3"},
                         {"min", json(low)},
                         {"max", json(high)}});
    const std::size_t position_accessor = accessors.size() - 1;
    views_out.push_back({{"buffer", 0}, {"byteOffset", indices_at}, {"byteLength", bin_.size() - indices_at}});
    accessors.push_back({{"bufferView", views_out.size() - 1},
                         {"componentType", kUnsignedInt},
                         {"count", 3 * std::uint64_t{mesh.num_faces()}},
                         {"type", "SCALAR"}});

    // Positions and faces are all a mesh gives vola; the other attributes' accessors
    // have no data outside the Draco stream, and morph targets no base to apply to.
    primitive["attributes"] = {{"POSITION", position_accessor}};
    primitive["indices"] = accessors.size() - 1;
    primitive["mode"] = kTriangles;  // Draco's faces are triangles, also for a strip
    primitive.erase("targets");
    primitive["extensions"].erase(kDraco);
    if (primitive["extensions"].empty()) primitive.erase("extensions");
  }

  void align_bin() { bin_.append((4 - bin_.size() % 4) % 4, '\0'); }

  const std::string& path_;
  json& scene_;
  const std::optional<Glb>& glb_;
  std::map<std::uint64_t, std::string> decoded_uris_;
  std::string bin_;
  std::uint64_t faces_ = 0;
};

void drop_extension_name(json& scene, const char* list) {
  if (!scene.contains(list) || !scene[list].is_array()) return;
  json& names = scene[list];
  names.erase(std::remove(names.begin(), names.end(), json(kDraco)), names.end());
  if (names.empty()) scene.erase(list);
}

}  // namespace

std::optional<std::string> gltf_with_draco_decoded(const std::string& path, std::string_view file) try {
  if (file.find(kDraco) == std::string_view::npos) return std::nullopt;  // the name is in the JSON of every such scene
  std::optional<Glb> glb;
  std::string_view text = file;
  if (file.starts_with("glTF")) {
    glb = split_glb(file);
    if (!glb) return std::nullopt;
    text = glb->json;
  }
  json scene = json::parse(text, nullptr, /*allow_exceptions=*/false);
  if (scene.is_discarded() || !scene.is_object()) return std::nullopt;  // Assimp says what is wrong

  // The new binary chunk is buffer 0: the .glb's own chunk followed by the decoded data,
  // or a new buffer placed first (every buffer view's buffer index moves up by one).
  const bool keeps_bin = glb && glb->bin && scene.contains("buffers") && scene["buffers"].is_array() &&
                         !scene["buffers"].empty() && scene["buffers"][0].is_object() &&
                         !scene["buffers"][0].contains("uri");
  DracoDecoding decoding(path, scene, glb);
  const std::size_t base = keeps_bin ? (glb->bin->size() + 3) / 4 * 4 : 0;
  if (!scene.contains("bufferViews") || !scene["bufferViews"].is_array()) return std::nullopt;
  const std::size_t original_views = scene["bufferViews"].size();
  if (!decoding.decode_all(base)) return std::nullopt;
  std::string bin = decoding.take_bin();
  if (keeps_bin) {
    std::memcpy(bin.data(), glb->bin->data(), glb->bin->size());
  } else {
    if (!scene.contains("buffers") || !scene["buffers"].is_array()) scene["buffers"] = json::array();
    scene["buffers"].insert(scene["buffers"].begin(), json::object());
    json& views = scene["bufferViews"];
    for (std::size_t v = 0; v < original_views; ++v)
      if (views[v].is_object() && views[v].contains("buffer") && views[v]["buffer"].is_number_unsigned())
        views[v]["buffer"] = views[v]["buffer"].get<std::uint64_t>() + 1;
  }
  bin.append((4 - bin.size() % 4) % 4, '\0');
  scene["buffers"][0]["byteLength"] = bin.size();
  drop_extension_name(scene, "extensionsRequired");
  drop_extension_name(scene, "extensionsUsed");

  std::string json_text = scene.dump();
  json_text.append((4 - json_text.size() % 4) % 4, ' ');
  const std::uint64_t total = 12 + 8 + json_text.size() + 8 + bin.size();
  if (total > std::numeric_limits<std::uint32_t>::max())
    throw InvalidArgument(path + ": the scene's Draco meshes decode to more than the 4 GiB a .glb can hold");
  std::string out;
  out.reserve(total);
  out.append("glTF");
  append_u32(out, 2);
  append_u32(out, static_cast<std::uint32_t>(total));
  append_u32(out, static_cast<std::uint32_t>(json_text.size()));
  append_u32(out, kChunkJson);
  out.append(json_text);
  append_u32(out, static_cast<std::uint32_t>(bin.size()));
  append_u32(out, kChunkBin);
  out.append(bin);
  return out;
} catch (const nlohmann::json::exception& wrong) {
  // A member of an unexpected JSON type that the checks above did not foresee.
  throw FormatError(path, std::nullopt, std::string("the glTF's Draco primitives: ") + wrong.what());
}

}  // namespace vola::io
