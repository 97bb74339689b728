// vola render: a shaded image and a depth image of a .vol file through a pinhole camera,
// or an orbit of frames around the look-at point; prints the rays per second.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <functional>
#include <string>
#include <vector>

#include "commands.hpp"
#include "files_read.hpp"
#include "open_voxels.hpp"
#include "output_checks.hpp"
#include "png_writer.hpp"
#include "vola/error.hpp"
#include "vola/file.hpp"
#include "vola/raycast/render.hpp"
#include "vola/raycast/world.hpp"
#include "vola/tile/tile_set.hpp"

namespace vola::cli {

namespace {

struct RenderArgs {
  std::string input, output = "render.png";
  std::vector<double> camera;  // eye x y z, look-at x y z
  std::vector<double> up{0, 0, 1};
  double fov = 60.0;
  std::string size = "512x512";
  unsigned orbit = 0;
  unsigned threads = 0;
  bool grid = false;
  bool quiet = false;
};

// "640x480" -> {640, 480}.
std::array<std::uint32_t, 2> parse_size(const std::string& text) {
  const auto x = text.find('x');
  try {
    if (x != std::string::npos) {
      std::size_t used_w = 0, used_h = 0;
      const unsigned long w = std::stoul(text.substr(0, x), &used_w);
      const unsigned long h = std::stoul(text.substr(x + 1), &used_h);
      if (used_w == x && used_h == text.size() - x - 1 && w >= 1 && h >= 1 && w <= 16384 && h <= 16384)
        return {static_cast<std::uint32_t>(w), static_cast<std::uint32_t>(h)};
    }
  } catch (const std::exception&) {
  }
  throw InvalidArgument("--size must be WIDTHxHEIGHT with each 1..16384, e.g. 640x480 (got '" + text + "')");
}

std::string with_suffix(const std::string& path, const std::string& suffix) {
  const auto dot = path.rfind('.');
  const auto slash = path.find_last_of('/');
  if (dot == std::string::npos || (slash != std::string::npos && dot < slash)) return path + suffix + ".png";
  return path.substr(0, dot) + suffix + path.substr(dot);
}

std::vector<std::uint16_t> depth_image(const raycast::Rendering& r) {
  double near = std::numeric_limits<double>::infinity(), far = 0.0;
  for (const double d : r.depth)
    if (std::isfinite(d)) {
      near = std::min(near, d);
      far = std::max(far, d);
    }
  std::vector<std::uint16_t> out(r.depth.size(), 0);  // misses stay black
  const double span = far > near ? far - near : 1.0;
  for (std::size_t i = 0; i < out.size(); ++i)
    if (std::isfinite(r.depth[i])) out[i] = static_cast<std::uint16_t>(65535.0 - 60000.0 * (r.depth[i] - near) / span);
  return out;
}

void write_images(const RenderArgs& a, const raycast::Rendering& image, const std::string& shaded, std::uint32_t width,
                  std::uint32_t height) {
  const std::string depth = with_suffix(shaded, "_depth");
  refuse_outputs_over_inputs(files_read(a.input), {shaded, depth}, "vola render");
  write_png_rgb8(shaded, width, height, image.rgb);
  write_png_gray16(depth, width, height, depth_image(image));
  if (!a.quiet)
    std::printf("%s, %s: %llu of %llu rays hit\n", shaded.c_str(), depth.c_str(),
                static_cast<unsigned long long>(image.hits), static_cast<unsigned long long>(width) * height);
}

// Renders one frame, or --orbit N frames around the look-at point, with `draw`; writes the
// images and prints the rays per second (then `note()`, when given).
void render_frames(const RenderArgs& a, raycast::PinholeCamera camera, std::uint32_t width, std::uint32_t height,
                   const std::function<raycast::Rendering(const raycast::PinholeCamera&)>& draw,
                   const std::function<std::string()>& note = {}) {
  camera.up = {a.up[0], a.up[1], a.up[2]};
  camera.vertical_fov_degrees = a.fov;
  camera.width = width;
  camera.height = height;
  camera.check();
  const unsigned frames = a.orbit ? a.orbit : 1;
  double seconds = 0.0;
  for (unsigned f = 0; f < frames; ++f) {
    const auto cam = a.orbit ? raycast::orbit(camera, f, frames) : camera;
    const auto start = std::chrono::steady_clock::now();
    const raycast::Rendering image = draw(cam);
    seconds += std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    char frame_suffix[32];
    std::snprintf(frame_suffix, sizeof frame_suffix, "_%04u", f);
    write_images(a, image, a.orbit ? with_suffix(a.output, frame_suffix) : a.output, width, height);
  }
  if (a.quiet) return;
  const std::uint64_t rays = std::uint64_t{width} * height * frames;
  std::printf("%llu rays in %.3f s: %.3f M rays/s, %.2f frames/s%s\n", static_cast<unsigned long long>(rays), seconds,
              seconds > 0 ? static_cast<double>(rays) / seconds / 1e6 : 0.0, seconds > 0 ? frames / seconds : 0.0,
              note ? note().c_str() : "");
}

void run_render(const RenderArgs& a) {
  const auto [width, height] = parse_size(a.size);
  raycast::PinholeCamera camera;  // the default view frames the scene with the image's settings
  camera.up = {a.up[0], a.up[1], a.up[2]};
  camera.vertical_fov_degrees = a.fov;
  camera.width = width;
  camera.height = height;
  if (!a.camera.empty()) {
    camera.eye = {a.camera[0], a.camera[1], a.camera[2]};
    camera.look_at = {a.camera[3], a.camera[4], a.camera[5]};
  }
  if (tile::is_tile_index_path(a.input)) {  // world coordinates; a tile opens when a ray first reaches it
    if (a.grid) throw InvalidArgument("--grid: a tile set has no single voxel grid; give world coordinates");
    const tile::TileSet tiles(a.input);
    if (a.camera.empty()) camera = tile::overview_camera(tiles, camera);
    render_frames(
        a, camera, width, height, [&](const raycast::PinholeCamera& cam) { return tile::render(tiles, cam, a.threads); },
        [&] {
          return "; " + std::to_string(tiles.tiles_opened()) + " of " + std::to_string(tiles.index().tiles.size()) +
                 " tiles opened";
        });
    return;
  }
  const Tree tree = open_voxels(a.input);
  if (a.camera.empty())
    camera = raycast::overview_camera(tree, camera);
  else if (!a.grid) camera = raycast::world_camera_to_grid(tree.frame(), camera);
  const raycast::RayCaster caster(tree);
  render_frames(a, camera, width, height,
                [&](const raycast::PinholeCamera& cam) { return raycast::render(caster, cam, a.threads); });
}

}  // namespace

void add_render(CLI::App& app) {
  auto args = std::make_shared<RenderArgs>();
  auto* cmd = app.add_subcommand("render", "Render a shaded image and a depth image through a pinhole camera");
  cmd->footer(
      "Each pixel casts one ray (hierarchical DDA) and stops at the first occupied voxel.\n"
      "The shaded image lights the face the ray entered, coloured by the voxels' red/green/blue\n"
      "attributes when the file has them; the depth image (16-bit grey, OUT_depth.png) is brighter\n"
      "where nearer, black where the ray hit nothing.\n"
      "Coordinates are world coordinates (the file's frame) unless --grid is given.\n"
      "INPUT may be a tile index (index.geojson from vola tile): rays then cross the tiles in order,\n"
      "each tile mapped when a ray first reaches it; depths are in world units.\n"
      "Examples:\n"
      "  vola render city.vol -o city.png                         (the whole scene, from above a corner)\n"
      "  vola render city.vol --grid --camera 100 -50 80 512 512 0 --size 1280x720 -o view.png\n"
      "  vola render city.vol --grid --camera 0 0 300 512 512 0 --orbit 36 -o orbit.png  (orbit_0000.png ...)\n"
      "  vola render tiles/index.geojson --size 1024x768 -o survey.png");
  cmd->add_option("input", args->input, "Input .vol or tile index (.geojson)")->required()->check(CLI::ExistingFile);
  cmd->add_option("--camera", args->camera, "Eye X Y Z then look-at X Y Z (default: a view of the whole scene)")
      ->expected(6);
  cmd->add_option("--up", args->up, "Up vector X Y Z")->expected(3)->capture_default_str();
  cmd->add_option("--fov", args->fov, "Vertical field of view in degrees")->capture_default_str();
  cmd->add_option("--size", args->size, "Image size WIDTHxHEIGHT")->capture_default_str();
  cmd->add_option("-o,--output", args->output, "Shaded PNG; the depth PNG gets _depth before the extension")
      ->capture_default_str();
  cmd->add_option("--orbit", args->orbit, "Write N frames turning the eye around the look-at point (OUT_0000.png ...)");
  cmd->add_option("--threads", args->threads, "Threads (0 = all cores)")->capture_default_str();
  cmd->add_flag("--grid", args->grid, "--camera is in voxel-grid coordinates, not world coordinates");
  cmd->add_flag("-q,--quiet", args->quiet, "Print nothing on success but warnings (to stderr)");
  cmd->callback([args] { run_render(*args); });
}

}  // namespace vola::cli
