// A tile set (vola tile's index.geojson) as `vola view` serves it: the list of its
// pieces, the tiles and the overviews of every level, with their world boxes, so that
// the page can choose which to load by distance; and each piece's cells, through a
// ViewedFile opened when first asked for.
//
// Memory stays bounded whatever the set's size: at most max_open pieces are open at
// once, the least recently used closed first (a request that holds one keeps it alive
// until it is done). Only files the index lists are opened, and only when the path,
// symbolic links resolved, lies inside the index's folder.
#pragma once

#include <cstddef>
#include <cstdint>
#include <list>
#include <memory>
#include <mutex>
#include <string>
#include <utility>
#include <vector>

#include <nlohmann/json_fwd.hpp>

#include "vola/frame.hpp"
#include "vola/tile/tile_index.hpp"
#include "vola/viewer/viewed_file.hpp"

namespace vola::viewer {

// One file of a tile set: a tile (level 0) or an overview (level >= 1, voxels 4^level
// times the tiles').
struct TilePiece {
  int level = 0;
  tile::TileIndex tile;  // on the level's grid (tile size times 4^level)
  std::string file;      // relative to the index's folder
  std::uint64_t voxels = 0;
  Box box;               // the world box the piece's grid covers
  Box points;            // the box of its points: the tile's bbox, an overview's tiles' together
};

class ViewedTileSet {
 public:
  static constexpr std::size_t kDefaultMaxOpen = 64;

  // Reads the index (FormatError / IoError); opens no piece yet. InvalidArgument when
  // max_open is 0.
  explicit ViewedTileSet(const std::string& index_path, std::size_t max_open = kDefaultMaxOpen);
  ~ViewedTileSet();
  ViewedTileSet(const ViewedTileSet&) = delete;
  ViewedTileSet& operator=(const ViewedTileSet&) = delete;

  // The index's folder's base name: what the server shows of where the set lives.
  const std::string& name() const noexcept { return name_; }
  const tile::TileIndexFile& index() const noexcept { return index_; }
  // Tiles first, in the index's order, then overviews by level.
  const std::vector<TilePiece>& pieces() const noexcept { return pieces_; }

  // Grid, CRS and its unit, attributes, the points' bounds, the overview levels and
  // every piece (id = position in pieces(), level, tile, file, voxels, box, its points'
  // box, origin and voxel size of its grid): what the page needs to choose pieces.
  nlohmann::json metadata() const;
  // Piece `id`, opened if it is not (InvalidArgument for an id out of range; IoError
  // for a file outside the index's folder; FormatError / IoError for a bad file).
  std::shared_ptr<const ViewedFile> piece(std::size_t id) const;
  std::size_t pieces_open() const;

 private:
  std::string folder_;  // canonical
  std::string name_;
  tile::TileIndexFile index_;
  std::vector<TilePiece> pieces_;
  std::size_t max_open_;
  mutable std::mutex mutex_;
  // Most recently used first.
  mutable std::list<std::pair<std::size_t, std::shared_ptr<const ViewedFile>>> open_;
};

}  // namespace vola::viewer
