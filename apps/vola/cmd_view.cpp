// vola view: a local web page showing .vol files in 3D (src/viewer).
#include <cstdio>
#include <memory>
#include <string>
#include <vector>

#include "commands.hpp"
#include "vola/viewer/server.hpp"
#include "vola/viewer/viewed_file.hpp"

namespace vola::cli {

namespace {

struct ViewArgs {
  std::vector<std::string> files;
  int port = 0;
};

void run_view(const ViewArgs& a) {
  std::vector<std::unique_ptr<viewer::ViewedFile>> files;
  std::uint64_t voxels = 0;
  for (const auto& path : a.files) {
    files.push_back(std::make_unique<viewer::ViewedFile>(path));
    voxels += files.back()->tree().voxel_count();
  }
  viewer::Server server(std::move(files));
  const int port = server.bind(a.port);
  std::printf("vola view: %zu file%s, %llu voxels\n", a.files.size(), a.files.size() == 1 ? "" : "s",
              static_cast<unsigned long long>(voxels));
  std::printf("open http://127.0.0.1:%d/ in a browser (loopback only; Ctrl-C stops)\n", port);
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
      "The page needs no network: three.js is compiled into this binary.\n\n"
      "Examples:\n"
      "  vola view scan.vol\n"
      "  vola view survey2019.vol survey2024.vol --port 8080");
  cmd->add_option("files", args->files, ".vol files to show")->required()->check(CLI::ExistingFile);
  cmd->add_option("--port", args->port, "Port on 127.0.0.1 (default 0: a free one, printed)")
      ->check(CLI::Range(0, 65535));
  cmd->callback([args] { run_view(*args); });
}

}  // namespace vola::cli
