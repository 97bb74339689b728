// Tree.render and TileSet.render: `vola render`'s shaded and depth images through a pinhole
// camera, as numpy arrays instead of PNG files.
#include "python_support.hpp"

#include <cstdint>
#include <optional>

#include "vola/map/state_map.hpp"
#include "vola/raycast/camera.hpp"
#include "vola/raycast/render.hpp"
#include "vola/raycast/world.hpp"
#include "vola/tile/tile_set.hpp"

namespace vola::python {

namespace {

// The camera the keywords describe, as `vola render` makes it from its flags: up, field of
// view and size, then `eye` and `look_at` (else `overview(settings)`, which frames the scene
// with them), then the orbit frame.
template <class Overview>
vola::raycast::PinholeCamera camera_of(std::optional<std::array<double, 3>> eye, std::optional<std::array<double, 3>> look_at,
                                       std::array<double, 3> up, double fov, std::array<std::int64_t, 2> size,
                                       std::optional<std::array<std::uint32_t, 2>> orbit, Overview&& overview) {
  if (eye.has_value() != look_at.has_value())
    throw vola::InvalidArgument("render: give eye and look_at together (or neither, for the default view)");
  for (const std::int64_t s : size)
    if (s < 1 || s > 16384)
      throw vola::InvalidArgument("render: size must be (width, height) with each 1..16384, got (" +
                                  std::to_string(size[0]) + ", " + std::to_string(size[1]) + ")");
  vola::raycast::PinholeCamera camera;
  camera.up = to_point(up);
  camera.vertical_fov_degrees = fov;
  camera.width = static_cast<std::uint32_t>(size[0]);
  camera.height = static_cast<std::uint32_t>(size[1]);
  if (eye) {
    camera.eye = to_point(*eye);
    camera.look_at = to_point(*look_at);
  } else {
    camera = overview(camera);  // framed with the image's field of view and aspect
  }
  camera.check();
  if (orbit) {
    if ((*orbit)[1] == 0 || (*orbit)[0] >= (*orbit)[1])
      throw vola::InvalidArgument("render: orbit=(frame, frames) needs 0 <= frame < frames");
    camera = vola::raycast::orbit(camera, (*orbit)[0], (*orbit)[1]);
  }
  return camera;
}

py::dict images(vola::raycast::Rendering&& image) {
  const auto h = static_cast<py::ssize_t>(image.height), w = static_cast<py::ssize_t>(image.width);
  py::dict out;
  out["image"] = owning_array(std::move(image.rgb), {h, w, py::ssize_t{3}});
  out["depth"] = owning_array(std::move(image.depth), {h, w});
  out["hits"] = image.hits;
  return out;
}

py::dict render_tree(const Tree& tree, std::optional<std::array<double, 3>> eye, std::optional<std::array<double, 3>> look_at,
                     std::array<double, 3> up, double fov, std::array<std::int64_t, 2> size, bool world,
                     std::optional<std::array<std::uint32_t, 2>> orbit, unsigned threads) {
  // A state map (vola.read, vola.open(..., states=True)) is seen by its occupied voxels, as
  // `vola render` sees the file: rays pass through its free voxels.
  std::optional<Tree> occupied;
  if (vola::map::is_state_map(tree)) occupied = vola::map::occupied_tree(tree);
  const Tree& scene = occupied ? *occupied : tree;
  const vola::Frame frame = tree.frame();
  // A camera given in world coordinates moves to the grid before the orbit turns it, as the CLI does.
  if (eye && look_at && world) {
    vola::raycast::PinholeCamera given;
    given.eye = to_point(*eye);
    given.look_at = to_point(*look_at);
    given = vola::raycast::world_camera_to_grid(frame, given);
    eye = given.eye;
    look_at = given.look_at;
  }
  const auto camera = camera_of(eye, look_at, up, fov, size, orbit, [&](const vola::raycast::PinholeCamera& s) {
    return vola::raycast::overview_camera(scene, s);
  });
  vola::raycast::Rendering image;
  {
    py::gil_scoped_release release;
    const vola::raycast::RayCaster caster(scene);
    image = vola::raycast::render(caster, camera, threads);
    if (world)
      for (double& d : image.depth) d *= frame.voxel_size;
  }
  return images(std::move(image));
}

py::dict render_tiles(const vola::tile::TileSet& tiles, std::optional<std::array<double, 3>> eye,
                      std::optional<std::array<double, 3>> look_at, std::array<double, 3> up, double fov,
                      std::array<std::int64_t, 2> size, std::optional<std::array<std::uint32_t, 2>> orbit, unsigned threads) {
  const auto camera = camera_of(eye, look_at, up, fov, size, orbit, [&](const vola::raycast::PinholeCamera& s) {
    return vola::tile::overview_camera(tiles, s);
  });
  vola::raycast::Rendering image;
  {
    py::gil_scoped_release release;
    image = vola::tile::render(tiles, camera, threads);
  }
  return images(std::move(image));
}

}  // namespace

void bind_render(py::class_<Tree>& tree, py::module_& m) {
  auto tiles = py::reinterpret_borrow<py::class_<vola::tile::TileSet>>(m.attr("TileSet"));
  tree.def("render", &render_tree, py::arg("eye") = py::none(), py::arg("look_at") = py::none(),
           py::arg("up") = std::array<double, 3>{0, 0, 1}, py::arg("fov") = 60.0,
           py::arg("size") = std::array<std::int64_t, 2>{512, 512}, py::arg("world") = true,
           py::arg("orbit") = py::none(), py::arg("threads") = 0u,
           "One ray per pixel to the first occupied voxel (`vola render`). Returns {'image': (H, W, 3) uint8,\n"
           "the entered face lit and coloured by the red/green/blue columns (else light grey), misses black;\n"
           "'depth': (H, W) float64 distance to the entry point (world units, voxels with world=False), inf\n"
           "for a miss; 'hits': rays that hit}. Row 0 is the top of the image.\n"
           "eye, look_at: the camera (world coordinates unless world=False); neither: the CLI's default view\n"
           "of the whole occupied box from above a corner. fov: vertical, degrees; size=(width, height);\n"
           "orbit=(i, n): frame i of `vola render --orbit n` (the eye turned 360*i/n degrees about +z).");
  tiles.def("render", &render_tiles, py::arg("eye") = py::none(), py::arg("look_at") = py::none(),
            py::arg("up") = std::array<double, 3>{0, 0, 1}, py::arg("fov") = 60.0,
            py::arg("size") = std::array<std::int64_t, 2>{512, 512}, py::arg("orbit") = py::none(),
            py::arg("threads") = 0u,
            "Tree.render over the tile set (`vola render index.geojson`): rays cross the tiles in order, each tile\n"
            "mapped when a ray first reaches it; world coordinates, depths in world units. The default view frames\n"
            "every tile's points from the index.");
}

}  // namespace vola::python
