// Seeds for fuzz_rosmap_read: map_server maps in the entry point's layout (YAML, a zero
// byte, the PGM): map_saver's trinary maps in binary and text PGM, a 16-bit image, a
// negated map with "- item" lists, quotes and comments, raw and scale modes. Linked into
// fuzz_rosmap_read_replay in place of fuzz_seeds.cpp.
#include <string>

#include "fuzz_seeds.hpp"

namespace vola_fuzz {
namespace {

Seed map_seed(const std::string& name, const std::string& yaml, const std::string& pgm) {
  std::string input = yaml;
  input.push_back('\0');
  input += pgm;
  return {name, std::vector<std::uint8_t>(input.begin(), input.end())};
}

// A 6 x 4 room: walls (0), floor (254), an unknown corner (205).
std::string room_pgm() {
  std::string pgm = "P5\n# CREATOR: map_saver.cpp 0.050 m/pix\n6 4\n255\n";
  const char rows[4][7] = {"######", "#..??#", "#....#", "######"};
  for (const auto& row : rows)
    for (int c = 0; c < 6; ++c) pgm.push_back(static_cast<char>(row[c] == '#' ? 0 : row[c] == '.' ? 254 : 205));
  return pgm;
}

}  // namespace

std::vector<Seed> synthetic_seeds() {
  const std::string yaml =
      "image: map.pgm\nmode: trinary\nresolution: 0.05\norigin: [-10.0, -10.0, 0.0]\n"
      "negate: 0\noccupied_thresh: 0.65\nfree_thresh: 0.196\n";
  std::string wide = "P5\n3 1\n65535\n";
  wide += std::string("\x00\x00\x80\x00\xff\xff", 6);
  return {
      map_seed("trinary", yaml, room_pgm()),
      map_seed("text", "image: 'map.pgm'  # the picture\nresolution: 0.5\norigin:\n  - 1.5\n  - -2\n  - 0\n",
               "P2\n# text\n3 2\n255\n0 254 205\n100 0 254\n"),
      map_seed("wide", "image: map.pgm\nresolution: 1\norigin: [0, 0, 0]\nnegate: 1\n", wide),
      map_seed("raw", "image: map.pgm\nmode: raw\nresolution: 0.1\norigin: [0, 0, 0]\n", "P5\n3 1\n255\n\x64\x00\xff"),
      map_seed("scale", "---\nimage: \"map.pgm\"\nmode: scale\nresolution: 2.0\norigin: [5, 5, 0.0]\n...\n",
               room_pgm()),
  };
}

std::vector<Seed> golden_seeds(const std::filesystem::path&) { return {}; }

}  // namespace vola_fuzz
