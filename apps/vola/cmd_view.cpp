// vola view: a local web page showing .vol files and tile sets in 3D (src/viewer).
#include <cstdio>
#include <memory>
#include <string>
#include <vector>

#include "commands.hpp"
#include "vola/tile/tile_index.hpp"
#include "vola/viewer/server.hpp"
#include "vola/viewer/viewed_file.hpp"

namespace vola::cli {

namespace {

struct ViewArgs {
  std::vector<std::string> files;
  bool free = false;
  viewer::ServerOptions server;
};

std::string url_host(const std::string& host) { return host.find(':') != std::string::npos ? "[" + host + "]" : host; }

void run_view(const ViewArgs& a) {
  std::vector<std::unique_ptr<viewer::ViewedFile>> files;
  std::vector<std::unique_ptr<viewer::ViewedTileSet>> tile_sets;
  std::uint64_t voxels = 0;
  for (const auto& path : a.files) {
    if (tile::is_tile_index_path(path)) {
      tile_sets.push_back(std::make_unique<viewer::ViewedTileSet>(path));
      for (const auto& t : tile_sets.back()->index().tiles) voxels += t.voxels;
      continue;
    }
    files.push_back(std::make_unique<viewer::ViewedFile>(path));
    voxels += files.back()->tree().voxel_count();
    // A state map's free voxels as a layer of their own, with its own toggle on the page.
    if (a.free && files.back()->is_state_map()) {
      files.push_back(std::make_unique<viewer::ViewedFile>(path, viewer::MapPart::free));
      voxels += files.back()->tree().voxel_count();
    }
  }
  const std::size_t sets = tile_sets.size();
  viewer::Server server(std::move(files), std::move(tile_sets), a.server);
  const int port = server.bind();
  const std::size_t plain = a.files.size() - sets;
  std::printf("vola view: %zu file%s, %zu tile set%s, %llu voxels shown\n", plain, plain == 1 ? "" : "s", sets,
              sets == 1 ? "" : "s", static_cast<unsigned long long>(voxels));
  std::printf("open http://%s:%d/ in a browser (Ctrl-C stops)\n", url_host(a.server.host).c_str(), port);
  std::fflush(stdout);
  server.listen();
}

}  // namespace

void add_view(CLI::App& app) {
  auto args = std::make_shared<ViewArgs>();
  auto* cmd = app.add_subcommand("view", kViewSummary);
  cmd->footer(
      "The page streams each file level by level, coarse first, and draws voxels as cubes:\n"
      "orbit (left drag), pan (right drag), zoom (wheel); the detail slider picks the level;\n"
      "colour by height, ASPRS classification, stored RGB or file; a slicing plane hides\n"
      "what lies above it; a click reports the voxel (grid and CRS coordinates, attributes).\n"
      "Several files share one scene in world coordinates (two surveys: change at a glance).\n"
      "A state map (vola map) shows its occupied voxels; --free adds its free voxels as a second\n"
      "layer, \"NAME (free)\", with a toggle of its own.\n"
      "A tile index (vola tile's index.geojson) streams as Potree does: the overviews far from\n"
      "the camera, finer ones and then the tiles near it and in view, within a budget of cells\n"
      "(2 million); pieces no longer needed are freed once the page holds 4 million cells (the\n"
      "URL's ?budget=N&cache=N changes both), and the server keeps at most 64 tile files open.\n"
      "Clicks pick voxels in .vol files, not in tile sets.\n"
      "A scale bar in the CRS's unit (metre, foot, US survey foot; \"units\" when no CRS is\n"
      "known) and a north arrow (the grid's +y; none without a CRS) sit in the corners.\n"
      "The page needs no network: three.js is compiled into this binary.\n\n"
      "Examples:\n"
      "  vola view scan.vol\n"
      "  vola view survey2019.vol survey2024.vol --port 8080\n"
      "  vola view map.vol --free\n"
      "  vola view tiles/index.geojson\n"
      "  vola view scan.vol --host 0.0.0.0 --port 8080 --allow-host mybox.local");
  cmd->add_option("files", args->files, ".vol files and tile indexes (index.geojson) to show")->required()->check(CLI::ExistingFile);
  cmd->add_flag("--free", args->free, "Also show the free voxels of state maps (vola map), as a layer of their own");
  cmd->add_option("--port", args->server.port, "Port to listen on (default 0: a free one, printed)")
      ->check(CLI::Range(0, 65535));
  cmd->add_option("--host", args->server.host,
                  "Address to listen on (default 127.0.0.1: this machine only; 0.0.0.0 or a LAN address\n"
                  "shows the files to the network, to anyone who can reach it)")
      ->capture_default_str();
  cmd->add_option("--allow-host", args->server.host_names,
                  "A name clients may use in the URL besides localhost, 127.0.0.1, [::1] and --host\n"
                  "(e.g. this machine's name with --host 0.0.0.0); other names get 403");
  cmd->callback([args] { run_view(*args); });
}

}  // namespace vola::cli
