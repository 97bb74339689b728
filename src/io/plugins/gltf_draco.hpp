#pragma once

#include <optional>
#include <string>
#include <string_view>

namespace vola::io {

// A glTF 2.0 scene (.gltf text or .glb) whose primitives are compressed with
// KHR_draco_mesh_compression, returned as a .glb whose primitives hold plain positions
// and 32-bit indices decoded with libdraco; nullopt when the scene uses no Draco.
//
// Debian 12's Assimp (5.2.4) decodes Draco itself but loses a primitive's indices when
// their accessor is 32-bit (SetDecodedIndexBuffer_Draco returns before it keeps the
// decoded buffer: "GLTF: Invalid accessor without data"), which every Draco mesh of more
// than 65,535 vertices has. Decoding them here gives Assimp a scene it reads whole. Only
// positions and faces are kept (all vola reads of a mesh); node transforms, scenes and
// other primitives are left as they are. Errors name `path` and, for a primitive's Draco
// data, its byte offset in the file.
std::optional<std::string> gltf_with_draco_decoded(const std::string& path, std::string_view file);

}  // namespace vola::io
