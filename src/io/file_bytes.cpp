#include "file_bytes.hpp"

#include <fstream>

#include "vola/error.hpp"

namespace vola::io {

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
