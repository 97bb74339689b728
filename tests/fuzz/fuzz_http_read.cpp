// Fuzz entry point of vola view's request handling: the input is what one client sends
// on a connection before closing its side, answered by Server::respond (the same
// request stream, limits, cpp-httplib parser, Host and UTF-8 guards and routes as a
// socket) by a server showing a small tree with attributes, and the same tree as the one
// tile of a tile set (in a temporary folder kept while the process runs), served as
// 127.0.0.1:8080.
// Nothing may crash or throw; every answer starts with an HTTP/1.1 status line of
// 100..599, never 500 (an exception escaping a route).
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <memory>
#include <string>
#include <string_view>
#include <unistd.h>

#include "fuzz_seeds.hpp"
#include "vola/error.hpp"
#include "vola/file.hpp"
#include "vola/viewer/server.hpp"
#include "vola/vola.hpp"

namespace {

using vola_fuzz::check;

// A folder removed when the process ends.
struct TemporaryFolder {
  std::filesystem::path path;
  ~TemporaryFolder() {
    std::error_code ignored;
    std::filesystem::remove_all(path, ignored);
  }
};

// `tree` as tile (0, 0, 0) of a one-tile set, and the set's index (the members
// read_tile_index reads).
std::unique_ptr<vola::viewer::ViewedTileSet> tile_set(const vola::Tree& tree) {
  static const TemporaryFolder folder{std::filesystem::temp_directory_path() /
                                      ("vola_fuzz_http_tiles_" + std::to_string(::getpid()))};
  std::filesystem::create_directories(folder.path);
  vola::write(tree, (folder.path / "tile_0_0_0.vol").string());
  const std::string index = (folder.path / "index.geojson").string();
  std::ofstream(index) << R"({"type": "FeatureCollection", "features": [{"type": "Feature", "geometry": null,
    "properties": {"file": "tile_0_0_0.vol", "tile": [0, 0, 0], "points": 200, "voxels": )"
                       << tree.voxel_count() << R"(, "bytes": 0, "bbox": [0, 10, 0, 74, 33, 5]}}],
    "vola": {"format": "vola-tile-index", "version": 1, "origin": [0, 0, 0], "tile_size": 256, "depth": 4,
      "epsg": null, "crs_wkt": "", "points_in": 200, "points_outside": 0, "overviews": []}})";
  return std::make_unique<vola::viewer::ViewedTileSet>(index);
}

vola::viewer::Server& server() {
  static const std::unique_ptr<vola::viewer::Server> s = [] {
    vola::PointCloud cloud;
    vola::PointAttribute intensity{"intensity", vola::ValueType::u16, vola::Reduction::max, {}};
    for (int i = 0; i < 200; ++i) {
      cloud.xyz.insert(cloud.xyz.end(), {0.37 * i, 10.0 + (i * 7) % 23, 0.5 * (i % 11)});
      cloud.payload.push_back(static_cast<std::uint64_t>(i));
      intensity.values.push_back(i * 100);
    }
    cloud.attributes.push_back(intensity);
    vola::BuildOptions options;
    options.depth = 4;
    options.payload = true;
    const std::string path =
        (std::filesystem::temp_directory_path() / ("vola_fuzz_http_" + std::to_string(::getpid()) + ".vol")).string();
    const vola::Tree tree = vola::build(cloud, options);
    vola::write(tree, path);
    std::vector<std::unique_ptr<vola::viewer::ViewedFile>> files;
    files.push_back(std::make_unique<vola::viewer::ViewedFile>(path));
    std::filesystem::remove(path);
    std::vector<std::unique_ptr<vola::viewer::ViewedTileSet>> sets;
    sets.push_back(tile_set(tree));
    vola::viewer::ServerOptions server_options;
    server_options.port = 8080;
    return std::make_unique<vola::viewer::Server>(std::move(files), std::move(sets), server_options);
  }();
  return *s;
}

// The status of every answer in `out` (pipelined requests get several).
bool statuses_ok(std::string_view out, bool& any_ok) {
  std::size_t at = 0;
  while ((at = out.find("HTTP/1.1 ", at)) != std::string_view::npos) {
    if (at + 12 > out.size()) return false;
    const int code = std::atoi(std::string(out.substr(at + 9, 3)).c_str());
    if (code < 100 || code > 599 || code == 500) return false;
    any_ok |= code == 200;
    at += 12;
  }
  return true;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string answer = server().respond(std::string_view(reinterpret_cast<const char*>(data), size));
  check(answer.empty() || answer.starts_with("HTTP/1.1 "));
  bool any_ok = false;
  check(statuses_ok(answer, any_ok));
  ++(any_ok ? vola_fuzz::stats().parsed : vola_fuzz::stats().refused);
  return 0;
}
