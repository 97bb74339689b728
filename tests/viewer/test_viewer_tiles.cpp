// vola view on a tile set (vola tile's index.geojson): the listing the page chooses
// pieces from equals the index, a piece's cells are its file's voxels, bad set and
// piece ids get 404, and no file outside the index's folder is ever opened, through a
// bad index or a symbolic link; the open pieces stay within their cap.
#include <gtest/gtest.h>

#include <cstring>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <set>

#include "raw_http.hpp"
#include "test_support.hpp"
#include "vola/builder.hpp"
#include "vola/error.hpp"
#include "vola/file.hpp"
#include "vola/tile/tile_grid.hpp"
#include "vola/viewer/server.hpp"
#include "vola/viewer/viewed_tile_set.hpp"

namespace {

namespace fs = std::filesystem;
using nlohmann::json;
using vola::viewer::Server;
using vola::viewer::ViewedTileSet;
using vola_test::body_of;
using vola_test::status_of;
using vola_test::TempDir;

constexpr int kDepth = 2;  // 16 voxels a side per tile
const vola::tile::TileGrid kGrid{{100.0, 200.0, 10.0}, 64.0, kDepth};

using VoxelSet = std::set<std::array<std::uint32_t, 3>>;

// Writes a tree of `voxels` at `path` (folders made), in the frame of tile `t` of level `level`.
void write_piece(const fs::path& path, const VoxelSet& voxels, int level, const vola::tile::TileIndex& t) {
  std::vector<vola::Voxel> list;
  for (const auto& v : voxels) list.push_back({v[0], v[1], v[2]});
  vola::Tree tree = vola::build_from_voxels(list, kDepth);
  const double size = kGrid.tile_size * (level ? 4.0 : 1.0);
  tree.set_frame(vola::Frame{vola::Quantization::grid,
                             {kGrid.origin[0] + t.i * size, kGrid.origin[1] + t.j * size, kGrid.origin[2] + t.k * size},
                             size / 16.0});
  fs::create_directories(path.parent_path());
  vola::write(tree, path.string());
}

// Two tiles and one level-1 overview, with an index as vola tile writes it (the members
// read_tile_index reads), in `dir`.
struct TileFolder {
  TempDir dir;
  fs::path index;
  std::vector<VoxelSet> voxels{{{1, 2, 3}, {15, 15, 15}, {4, 0, 9}}, {{0, 0, 0}, {7, 8, 9}}, {{0, 0, 0}, {1, 0, 0}}};
  json features = json::array();
  json overviews = json::array();

  TileFolder() : index(dir / "tiles" / "index.geojson") {
    add_tile({0, 0, 0}, voxels[0]);
    add_tile({1, 0, 0}, voxels[1]);
    write_piece(dir / "tiles" / "overviews" / "L1" / "tile_0_0_0.vol", voxels[2], 1, {0, 0, 0});
    overviews.push_back({{"level", 1}, {"tile", {0, 0, 0}}, {"file", "overviews/L1/tile_0_0_0.vol"}, {"voxels", 2}});
    write_index();
  }
  void add_tile(const vola::tile::TileIndex& t, const VoxelSet& v) {
    const std::string file = vola::tile::tile_file_name(t);
    write_piece(dir / "tiles" / file, v, 0, t);
    const vola::Box b = kGrid.tile_box(t);
    features.push_back({{"type", "Feature"},
                        {"geometry", nullptr},
                        {"properties",
                         {{"file", file},
                          {"tile", {t.i, t.j, t.k}},
                          {"points", v.size()},
                          {"voxels", v.size()},
                          {"bytes", 0},
                          {"bbox",
                           {b.min[0] + 1, b.min[1] + 2, b.min[2] + 3, b.max[0] - 1, b.max[1] - 2, b.max[2] - 3}}}}});
  }
  void write_index(std::optional<std::uint32_t> epsg = std::nullopt) const {
    const json vola_member = {{"format", "vola-tile-index"},
                              {"version", 1},
                              {"origin", {kGrid.origin[0], kGrid.origin[1], kGrid.origin[2]}},
                              {"tile_size", kGrid.tile_size},
                              {"depth", kDepth},
                              {"epsg", epsg ? json(*epsg) : json(nullptr)},
                              {"crs_wkt", ""},
                              {"points_in", 5},
                              {"points_outside", 0},
                              {"overviews", overviews}};
    std::ofstream(index) << json{{"type", "FeatureCollection"}, {"features", features}, {"vola", vola_member}}.dump();
  }
};

// The server bound to a free port (its Host check then knows the port), answering
// through Server::respond.
struct Served {
  std::unique_ptr<Server> server;
  int port = 0;

  explicit Served(std::vector<std::unique_ptr<ViewedTileSet>> sets)
      : server(std::make_unique<Server>(std::vector<std::unique_ptr<vola::viewer::ViewedFile>>{}, std::move(sets))),
        port(server->bind()) {}
  std::string get(const std::string& target) const {
    return server->respond("GET " + target + " HTTP/1.1\r\nHost: localhost:" + std::to_string(port) +
                           "\r\nConnection: close\r\n\r\n");
  }
};

Served serve(const fs::path& index) {
  std::vector<std::unique_ptr<ViewedTileSet>> sets;
  sets.push_back(std::make_unique<ViewedTileSet>(index.string()));
  return Served(std::move(sets));
}

// The cells of a batch answer's body.
VoxelSet batch_cells(const std::string& body) {
  EXPECT_EQ(body.compare(0, 4, "VOLC"), 0);
  std::uint32_t width = 0;
  std::uint64_t n = 0;
  std::memcpy(&width, body.data() + 8, 4);
  std::memcpy(&n, body.data() + 24, 8);
  EXPECT_EQ(width, 2u);
  VoxelSet out;
  for (std::uint64_t k = 0; k < n; ++k) {
    std::array<std::uint32_t, 3> v{};
    for (int a = 0; a < 3; ++a) {
      std::uint16_t c = 0;
      std::memcpy(&c, body.data() + vola::viewer::kBatchHeaderBytes + 6 * k + 2 * a, 2);
      v[a] = c;
    }
    out.insert(v);
  }
  return out;
}

TEST(ViewerTiles, TheListingIsTheIndex) {
  const TileFolder folder;
  const Served server = serve(folder.index);
  const std::string answer = server.get("/api/tilesets");
  ASSERT_EQ(status_of(answer), 200) << answer;
  const json sets = json::parse(body_of(answer));
  ASSERT_EQ(sets.size(), 1u);
  const json& s = sets[0];
  EXPECT_EQ(s["name"], "tiles");  // the folder's base name, not where it lives
  EXPECT_EQ(body_of(answer).find(folder.dir.path().string()), std::string::npos);
  EXPECT_EQ(s["depth"], kDepth);
  EXPECT_EQ(s["tile_size"], 64.0);
  EXPECT_EQ(s["units"]["unit"], "units");  // no CRS: no unit claimed
  EXPECT_EQ(s["units"]["north"], false);
  EXPECT_EQ(s["overview_levels"], 1);
  EXPECT_EQ(s["points_min"], json({101.0, 202.0, 13.0}));
  EXPECT_EQ(s["points_max"], json({227.0, 262.0, 71.0}));
  const json& pieces = s["pieces"];
  ASSERT_EQ(pieces.size(), 3u);
  const std::vector<std::pair<std::string, int>> expected{
      {"tile_0_0_0.vol", 0}, {"tile_1_0_0.vol", 0}, {"overviews/L1/tile_0_0_0.vol", 1}};
  for (std::size_t p = 0; p < pieces.size(); ++p) {
    SCOPED_TRACE(p);
    EXPECT_EQ(pieces[p]["id"], p);
    EXPECT_EQ(pieces[p]["file"], expected[p].first);
    EXPECT_EQ(pieces[p]["level"], expected[p].second);
    EXPECT_EQ(pieces[p]["voxels"], folder.voxels[p].size());
  }
  EXPECT_EQ(pieces[1]["tile"], json({1, 0, 0}));
  EXPECT_EQ(pieces[1]["min"], json({164.0, 200.0, 10.0}));
  EXPECT_EQ(pieces[1]["max"], json({228.0, 264.0, 74.0}));
  EXPECT_EQ(pieces[1]["voxel_size"], 4.0);
  EXPECT_EQ(pieces[1]["points_min"], json({165.0, 202.0, 13.0}));
  EXPECT_EQ(pieces[1]["points_max"], json({227.0, 262.0, 71.0}));
  EXPECT_EQ(pieces[2]["max"], json({356.0, 456.0, 266.0}));  // 4 tiles a side
  EXPECT_EQ(pieces[2]["points_min"], s["points_min"]);      // the points of both tiles
  EXPECT_EQ(pieces[2]["points_max"], s["points_max"]);
  EXPECT_EQ(pieces[2]["voxel_size"], 16.0);
}

TEST(ViewerTiles, UnitsComeFromTheIndexsCrs) {
  TileFolder folder;
  folder.write_index(2994);  // Autzen's: NAD83(HARN) / Oregon GIC Lambert (ft)
  const ViewedTileSet set(folder.index.string());
  EXPECT_EQ(set.metadata()["units"]["unit"], "foot");
  EXPECT_EQ(set.metadata()["units"]["north"], true);
  folder.write_index(32610);
  EXPECT_EQ(ViewedTileSet(folder.index.string()).metadata()["units"]["unit"], "metre");
}

TEST(ViewerTiles, APiecesCellsAreItsFilesVoxels) {
  const TileFolder folder;
  const Served server = serve(folder.index);
  for (std::size_t p = 0; p < 3; ++p) {
    SCOPED_TRACE(p);
    const std::string answer =
        server.get("/api/tilesets/0/pieces/" + std::to_string(p) + "/cells?level=1&first=0&count=100");
    ASSERT_EQ(status_of(answer), 200) << answer;
    EXPECT_EQ(batch_cells(body_of(answer)), folder.voxels[p]);
  }
  // Level 0 holds the voxels' coarse cells.
  const std::string coarse = server.get("/api/tilesets/0/pieces/0/cells?level=0&first=0&count=100");
  EXPECT_EQ(batch_cells(body_of(coarse)), (VoxelSet{{0, 0, 0}, {3, 3, 3}, {1, 0, 2}}));
}

TEST(ViewerTiles, BadSetAndPieceIdsAreRefused) {
  const TileFolder folder;
  const Served server = serve(folder.index);
  for (const auto& [target, status] : std::vector<std::pair<std::string, int>>{
           {"/api/tilesets/1/pieces/0/cells?level=0&first=0&count=1", 404},
           {"/api/tilesets/0/pieces/3/cells?level=0&first=0&count=1", 404},
           {"/api/tilesets/0/pieces/99999999999999999999999/cells?level=0&first=0&count=1", 404},
           {"/api/tilesets/0/pieces/-1/cells?level=0&first=0&count=1", 404},
           {"/api/tilesets/0/pieces/..%2F..%2Fetc/cells?level=0&first=0&count=1", 404},
           {"/api/tilesets/0/pieces/0/cells?level=2&first=0&count=1", 400},
           {"/api/tilesets/0/pieces/0/cells?level=0&first=0&count=99999999", 400},
           {"/api/tilesets/0/pieces/0/cells?level=0&first=0", 400}}) {
    SCOPED_TRACE(target);
    const std::string answer = server.get(target);
    EXPECT_EQ(status_of(answer), status) << answer;
    EXPECT_TRUE(json::parse(body_of(answer))["error"].is_string());
  }
  // A viewer of a tile set alone has no files: it says so (not "files 0..18446744073709551615").
  const std::string no_file = server.get("/api/files/0/cells?level=0&first=0&count=1");
  EXPECT_EQ(status_of(no_file), 404) << no_file;
  EXPECT_EQ(json::parse(body_of(no_file))["error"], "no file 0 (this viewer serves no files)");
  EXPECT_NE(server.get("/api/tilesets/0/pieces/3/cells?level=0&first=0&count=1").find("it has pieces 0..2"),
            std::string::npos);
}

TEST(ViewerTiles, NoFileOutsideTheIndexsFolderIsOpened) {
  TileFolder folder;
  // An index naming a file out of its folder is refused when read.
  folder.features[1]["properties"]["file"] = "../outside.vol";
  folder.write_index();
  EXPECT_THROW(ViewedTileSet(folder.index.string()), vola::FormatError);
  folder.features[1]["properties"]["file"] = "/etc/passwd";
  folder.write_index();
  EXPECT_THROW(ViewedTileSet(folder.index.string()), vola::FormatError);
  folder.features[1]["properties"]["file"] = "tile_1_0_0.vol";
  folder.overviews[0]["level"] = 1000;  // 4^1000: no grid
  folder.write_index();
  EXPECT_THROW(ViewedTileSet(folder.index.string()), vola::FormatError);
  folder.overviews[0]["level"] = 1;

  // A tile that is a symbolic link to a file outside: served never, named only as the index names it.
  write_piece(folder.dir / "outside.vol", folder.voxels[1], 0, {1, 0, 0});
  fs::remove(folder.dir / "tiles" / "tile_1_0_0.vol");
  fs::create_symlink(folder.dir / "outside.vol", folder.dir / "tiles" / "tile_1_0_0.vol");
  folder.features[1]["properties"]["file"] = "tile_1_0_0.vol";
  folder.write_index();
  std::vector<std::unique_ptr<ViewedTileSet>> sets;
  sets.push_back(std::make_unique<ViewedTileSet>(folder.index.string()));
  const ViewedTileSet& set = *sets.back();
  const Served server(std::move(sets));
  const std::string answer = server.get("/api/tilesets/0/pieces/1/cells?level=0&first=0&count=1");
  EXPECT_EQ(status_of(answer), 400) << answer;
  EXPECT_NE(body_of(answer).find("outside the index's folder"), std::string::npos) << answer;
  EXPECT_EQ(body_of(answer).find(folder.dir.path().string()), std::string::npos) << answer;
  EXPECT_EQ(set.pieces_open(), 0u);
  // A missing tile: an error naming it as the index does.
  fs::remove(folder.dir / "tiles" / "tile_0_0_0.vol");
  const std::string missing = server.get("/api/tilesets/0/pieces/0/cells?level=0&first=0&count=1");
  EXPECT_EQ(status_of(missing), 400) << missing;
  EXPECT_EQ(body_of(missing).find(folder.dir.path().string()), std::string::npos) << missing;
  EXPECT_EQ(set.pieces_open(), 0u);
}

TEST(ViewerTiles, OpenPiecesStayWithinTheirCap) {
  const TileFolder folder;
  std::vector<std::unique_ptr<ViewedTileSet>> sets;
  sets.push_back(std::make_unique<ViewedTileSet>(folder.index.string(), 2));
  const ViewedTileSet& set = *sets.back();
  const Served server(std::move(sets));
  EXPECT_EQ(set.pieces_open(), 0u);  // opening the set opens no piece
  for (int round = 0; round < 2; ++round)
    for (std::size_t p = 0; p < 3; ++p) {
      const std::string answer =
          server.get("/api/tilesets/0/pieces/" + std::to_string(p) + "/cells?level=1&first=0&count=100");
      ASSERT_EQ(status_of(answer), 200) << answer;
      EXPECT_EQ(batch_cells(body_of(answer)), folder.voxels[p]);  // reopened after being closed: the same cells
      EXPECT_LE(set.pieces_open(), 2u);
    }
  EXPECT_EQ(set.pieces_open(), 2u);
  EXPECT_THROW(ViewedTileSet(folder.index.string(), 0), vola::InvalidArgument);
}

}  // namespace
