#include "files_read.hpp"

#include <filesystem>

#include "vola/error.hpp"
#include "vola/tile/tile_index.hpp"

namespace vola::cli {

std::vector<std::string> files_read(const std::string& path) {
  std::vector<std::string> files{path};
  if (!tile::is_tile_index_path(path)) return files;
  try {
    const tile::TileIndexFile index = tile::read_tile_index(path);
    const std::filesystem::path folder = std::filesystem::path(path).parent_path();
    for (const tile::TileEntry& t : index.tiles) files.push_back((folder / t.file).string());
    for (const tile::OverviewEntry& o : index.overviews) files.push_back((folder / o.file).string());
  } catch (const Error&) {
    // An index that does not read is said when the command opens it.
  }
  return files;
}

}  // namespace vola::cli
