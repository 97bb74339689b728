#include "file_bytes.hpp"

#include <algorithm>
#include <cctype>
#include <filesystem>
#include <fstream>

#include "vola/error.hpp"
#include "vola/io/input.hpp"

namespace vola::io {

// Here rather than beside the format table (input.cpp): the readers that name a format by
// its extension (text_points.cpp) link without every reader (the libFuzzer build).
std::string lower_extension(const std::string& path) {
  std::string ext = std::filesystem::path(path).extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  return ext;
}

std::vector<std::uint8_t> read_file_bytes(const std::string& path) {
  std::ifstream in(path, std::ios::binary | std::ios::ate);
  if (!in) throw IoError(path + ": cannot open");
  const std::streamoff size = in.tellg();
  if (size < 0) throw IoError(path + ": cannot tell its size");
  std::vector<std::uint8_t> bytes(static_cast<std::size_t>(size));
  in.seekg(0);
  in.read(reinterpret_cast<char*>(bytes.data()), size);
  if (in.gcount() != size) throw IoError(path + ": cannot read");
  return bytes;
}

}  // namespace vola::io
