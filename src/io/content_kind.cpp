#include "content_kind.hpp"

#include <cstdio>
#include <cstring>
#include <string_view>

namespace vola::io {

std::optional<std::string> content_kind(std::span<const std::uint8_t> head) {
  const auto starts = [&](std::string_view magic) {
    return head.size() >= magic.size() && std::memcmp(head.data(), magic.data(), magic.size()) == 0;
  };
  struct Signature {
    std::string_view magic;
    const char* kind;
  };
  static constexpr Signature kSignatures[] = {
      {"LASF", "a LAS/LAZ point file"},
      {std::string_view("P\0\0\0", 4), "a .vol file (its 80-byte header)"},
      {"RIFF", "a RIFF file (WAV audio, AVI video)"},
      {"ASTM-E57", "an E57 scan"},
      {std::string_view("PK\x03\x04", 4), "a zip archive (an .npz, a KMZ, an Office document)"},
      {"\x93NUMPY", "a NumPy .npy array"},
      {"\x89PNG", "a PNG image"},
      {std::string_view("II*\0", 4), "a TIFF image"},
      {std::string_view("MM\0*", 4), "a TIFF image"},
      {"\x1f\x8b", "a gzip stream"},
      {"%PDF", "a PDF document"},
      {"\x7f"
       "ELF",
       "an executable (ELF)"},
      {"#binvox", "a binvox voxel grid"},
      {"# Octomap", "an OctoMap file"},
      {" BDV", "an OpenVDB file"},
      {"ply\n", "a PLY file"},
      {"ply\r\n", "a PLY file"},
      {"# .PCD", "a PCD point file"},
      {"glTF", "a binary glTF (.glb)"},
      {"OggS", "an Ogg stream"},
      {"fLaC", "a FLAC audio file"},
      {"\xff\xd8\xff", "a JPEG image"},
      {"GIF8", "a GIF image"},
  };
  for (const Signature& s : kSignatures)
    if (starts(s.magic)) return std::string(s.kind);
  return std::nullopt;
}

std::optional<std::string> content_kind_of_file(const std::string& path) {
  std::FILE* f = std::fopen(path.c_str(), "rb");
  if (!f) return std::nullopt;
  std::uint8_t head[16] = {};
  const std::size_t got = std::fread(head, 1, sizeof head, f);
  std::fclose(f);
  return content_kind(std::span<const std::uint8_t>(head, got));
}

std::string content_kind_note(std::span<const std::uint8_t> head) {
  const auto kind = content_kind(head);
  return kind ? " (its first bytes are those of " + *kind + ")" : "";
}

}  // namespace vola::io
