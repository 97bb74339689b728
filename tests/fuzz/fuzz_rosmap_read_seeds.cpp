// Seeds for fuzz_rosmap_read: map_server maps in the entry point's layout (YAML, a zero
// byte, the image): map_saver's trinary maps in binary and text PGM and in PNG, a 16-bit image, a
// negated map with "- item" lists, quotes and comments, raw and scale modes. Linked into
// fuzz_rosmap_read_replay in place of fuzz_seeds.cpp.
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>

#include <unistd.h>

#include "fuzz_seeds.hpp"
#include "vola/io/png_image.hpp"

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

// The room as an RGB PNG (map_saver --fmt png).
std::string room_png() {
  const std::string pgm = room_pgm();
  const std::string grey = pgm.substr(pgm.size() - 24);
  std::string rgb;
  for (const char v : grey) rgb.append(3, v);
  const auto path =
      std::filesystem::temp_directory_path() / ("vola_seed_rosmap_" + std::to_string(::getpid()) + ".png");
  vola::io::write_png(path.string(), 6, 4, reinterpret_cast<const std::uint8_t*>(rgb.data()), 8,
                      vola::io::PngColour::rgb);
  std::ifstream in(path, std::ios::binary);
  std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  std::filesystem::remove(path);
  return bytes;
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
      map_seed("png", yaml, room_png()),
  };
}

std::vector<Seed> golden_seeds(const std::filesystem::path&) { return {}; }

}  // namespace vola_fuzz
