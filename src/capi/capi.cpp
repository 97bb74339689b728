// The C API (include/vola/vola.h) over the C++ library. Every entry point runs its body
// through `guarded`, which turns any exception into a status code and this thread's
// last-error message: no exception crosses into C.
#include "vola/vola.h"

#include <bit>
#include <cstring>
#include <new>
#include <string>
#include <vector>

#include "vola/builder.hpp"
#include "vola/error.hpp"
#include "vola/file.hpp"
#include "vola/map/state_map.hpp"
#include "vola/tree.hpp"
#include "capi_guard.hpp"

namespace {

using vola::capi::check_trees_in_use;
using vola::capi::fail;
using vola::capi::guarded;
using vola::capi::require;

using vola::capi::tree_of;

void require_depth(int depth) {
  if (depth < vola::kMinDepth || depth > vola::kMaxDepth)
    throw vola::InvalidArgument("depth " + std::to_string(depth) + " is outside 1..10");
}

// Visits the leaf blocks from the one holding rank `first` on: f(voxel, rank) for every
// voxel of rank >= first until f returns false. Blocks before are skipped by popcount.
template <class F>
void visit_from(const vola::Tree& tree, std::uint64_t first, F&& f) {
  std::uint64_t rank = 0;
  bool going = true;
  tree.for_each_block(tree.depth() - 1, [&](std::size_t, std::uint64_t word, std::uint32_t ox, std::uint32_t oy,
                                             std::uint32_t oz) {
    if (!going) return;
    const auto bits = static_cast<std::uint64_t>(std::popcount(word));
    if (rank + bits <= first) {
      rank += bits;
      return;
    }
    while (word && going) {
      const unsigned b = static_cast<unsigned>(std::countr_zero(word));
      word &= word - 1;
      if (rank >= first) going = f(vola::Voxel{ox + (b & 3u), oy + ((b >> 2) & 3u), oz + (b >> 4)});
      ++rank;
    }
  });
}

}  // namespace

std::vector<const vola::Tree*>& vola::capi::trees_in_use() noexcept {
  thread_local std::vector<const vola::Tree*> trees;
  return trees;
}

std::string& vola::capi::last_error() noexcept {
  thread_local std::string message;
  return message;
}

std::string& vola::capi::last_warnings() noexcept {
  thread_local std::string lines;
  return lines;
}

void vola::capi::set_last_warnings(const std::vector<std::string>& warnings) {
  std::string& lines = last_warnings();
  lines.clear();
  for (const auto& w : warnings) lines += w + '\n';
}

extern "C" {

const char* vola_last_error(void) { return vola::capi::last_error().c_str(); }

const char* vola_last_warnings(void) { return vola::capi::last_warnings().c_str(); }

const char* vola_status_string(vola_status status) {
  switch (status) {
    case VOLA_OK: return "ok";
    case VOLA_ERROR_INVALID_ARGUMENT: return "invalid argument";
    case VOLA_ERROR_FORMAT: return "format error";
    case VOLA_ERROR_IO: return "io error";
    case VOLA_ERROR_OUT_OF_MEMORY: return "out of memory";
    case VOLA_ERROR_INTERNAL: return "internal error";
  }
  return "unknown status";
}

const char* vola_version(void) { return VOLA_C_VERSION; }

vola_status vola_open(const char* path, int mode, vola_tree** out) {
  return guarded([&] {
    require(path != nullptr && out != nullptr, "vola_open: path and out must not be NULL");
    require((mode & ~(VOLA_OPEN_MAPPED | VOLA_OPEN_STATES)) == 0,
            "vola_open: mode is not VOLA_OPEN_READ or VOLA_OPEN_MAPPED, or-ed with VOLA_OPEN_STATES or not");
    vola::Tree tree = (mode & VOLA_OPEN_MAPPED) ? vola::open_mapped(path) : vola::read(path);
    if (!(mode & VOLA_OPEN_STATES) && vola::map::is_state_map(tree)) {
#ifdef VOLA_C_HAS_MAP
      vola::Tree occupied = vola::map::occupied_tree(tree);
      vola::check_mapped(tree);  // the copy was read from the mapping: the file was whole meanwhile
      tree = std::move(occupied);
#else
      throw vola::InvalidArgument(std::string(path) + " is a state map (vola map): open it with VOLA_OPEN_STATES, "
                                  "this library was built without the map module that gives its occupied voxels");
#endif
    }
    *out = new vola_tree{std::move(tree)};
  });
}

vola_status vola_build_from_points(const double* xyz, size_t count, const vola_build_options* options,
                                   vola_tree** out, uint64_t* dropped) {
  return guarded([&] {
    require(options != nullptr && out != nullptr, "vola_build_from_points: options and out must not be NULL");
    require(xyz != nullptr || count == 0, "vola_build_from_points: xyz is NULL");
    require(count <= SIZE_MAX / (3 * sizeof(double)), "vola_build_from_points: count is too large");
    require(options->quantization == VOLA_QUANTIZE_TOOLKIT || options->quantization == VOLA_QUANTIZE_GRID,
            "vola_build_from_points: quantization is neither toolkit nor grid");
    vola::BuildOptions build;
    build.quantization =
        options->quantization == VOLA_QUANTIZE_TOOLKIT ? vola::Quantization::toolkit : vola::Quantization::grid;
    build.depth = options->depth;
    build.voxel_size = options->voxel_size;
    if (options->epsg) build.epsg = options->epsg;
    build.check();
    vola::PointCloud cloud;
    cloud.xyz.assign(xyz, xyz + 3 * count);
    vola::BuildReport report;
    auto* handle = new vola_tree{vola::build(cloud, build, &report)};
    handle->tree.georef().epsg = build.epsg;
    *out = handle;
    if (dropped) *dropped = report.points_outside;
  });
}

vola_status vola_build_from_voxels(const uint32_t* xyz, size_t count, int depth, vola_tree** out) {
  return guarded([&] {
    require(out != nullptr, "vola_build_from_voxels: out is NULL");
    require(xyz != nullptr || count == 0, "vola_build_from_voxels: xyz is NULL");
    require(count <= SIZE_MAX / (3 * sizeof(uint32_t)), "vola_build_from_voxels: count is too large");
    require_depth(depth);
    std::vector<vola::Voxel> voxels(count);
    for (size_t i = 0; i < count; ++i) voxels[i] = vola::Voxel{xyz[3 * i], xyz[3 * i + 1], xyz[3 * i + 2]};
    *out = new vola_tree{vola::build_from_voxels(voxels, depth)};
  });
}

vola_status vola_level_of_detail(const vola_tree* tree, int depth, vola_tree** out) {
  return guarded([&] {
    const vola::Tree& t = tree_of(tree);
    require(out != nullptr, "vola_level_of_detail: out is NULL");
    if (depth < 1 || depth > t.depth())
      throw vola::InvalidArgument("vola_level_of_detail: depth " + std::to_string(depth) + " is outside 1.." +
                                  std::to_string(t.depth()));
    vola::Tree coarse = t.level_of_detail(depth);
    check_trees_in_use();
    *out = new vola_tree{std::move(coarse)};
  });
}

void vola_tree_free(vola_tree* tree) { delete tree; }

vola_status vola_write(const vola_tree* tree, const char* path, int flags) {
  return guarded([&] {
    const vola::Tree& t = tree_of(tree);
    require(path != nullptr, "vola_write: path is NULL");
    require((flags & ~(VOLA_WRITE_DENSE | VOLA_WRITE_COMPRESS | VOLA_WRITE_COMPRESS_MAX)) == 0,
            "vola_write: unknown flags");
    require(!((flags & VOLA_WRITE_DENSE) && (flags & (VOLA_WRITE_COMPRESS | VOLA_WRITE_COMPRESS_MAX))),
            "vola_write: compressed files are sparse (VOLA_WRITE_DENSE and VOLA_WRITE_COMPRESS together)");
    vola::WriteOptions options;
    options.layout = (flags & VOLA_WRITE_DENSE) ? vola::Layout::dense : vola::Layout::sparse;
    options.compress = (flags & (VOLA_WRITE_COMPRESS | VOLA_WRITE_COMPRESS_MAX)) != 0;
    options.mix_occupancy_models = (flags & VOLA_WRITE_COMPRESS_MAX) != 0;
    vola::write(t, path, options);
  });
}

vola_status vola_get_info(const vola_tree* tree, vola_info* out) {
  return guarded([&] {
    const vola::Tree& t = tree_of(tree);
    require(out != nullptr, "vola_get_info: out is NULL");
    const vola::Frame frame = t.frame();
    vola_info info{};
    info.depth = t.depth();
    info.side = t.side();
    info.voxel_count = t.voxel_count();
    info.mapped = t.is_mapped() ? 1 : 0;
    info.quantization = frame.quantization == vola::Quantization::grid ? VOLA_QUANTIZE_GRID : VOLA_QUANTIZE_TOOLKIT;
    for (int i = 0; i < 3; ++i) info.origin[i] = frame.origin[i];
    info.voxel_size = frame.voxel_size;
    info.epsg = t.georef().epsg;
    info.attribute_count = t.attributes().size();
    check_trees_in_use();
    *out = info;
  });
}

vola_status vola_contains(const vola_tree* tree, uint32_t x, uint32_t y, uint32_t z, int* out) {
  return guarded([&] {
    const vola::Tree& t = tree_of(tree);
    require(out != nullptr, "vola_contains: out is NULL");
    const int inside = t.contains(x, y, z) ? 1 : 0;
    check_trees_in_use();
    *out = inside;
  });
}

vola_status vola_contains_many(const vola_tree* tree, const uint32_t* xyz, size_t count, uint8_t* out) {
  return guarded([&] {
    const vola::Tree& t = tree_of(tree);
    require((xyz != nullptr && out != nullptr) || count == 0, "vola_contains_many: xyz and out must not be NULL");
    for (size_t i = 0; i < count; ++i) out[i] = t.contains(xyz[3 * i], xyz[3 * i + 1], xyz[3 * i + 2]) ? 1 : 0;
  });
}

vola_status vola_rank(const vola_tree* tree, uint32_t x, uint32_t y, uint32_t z, uint64_t* out) {
  return guarded([&] {
    const vola::Tree& t = tree_of(tree);
    require(out != nullptr, "vola_rank: out is NULL");
    const auto rank = t.rank(vola::Voxel{x, y, z});
    if (!rank)
      throw vola::InvalidArgument("vola_rank: voxel (" + std::to_string(x) + ", " + std::to_string(y) + ", " +
                                  std::to_string(z) + ") is not occupied");
    check_trees_in_use();
    *out = *rank;
  });
}

vola_status vola_for_each_voxel(const vola_tree* tree, vola_voxel_callback callback, void* user, uint64_t* visited) {
  return guarded([&] {
    const vola::Tree& t = tree_of(tree);
    require(callback != nullptr, "vola_for_each_voxel: callback is NULL");
    std::uint64_t count = 0;
    visit_from(t, 0, [&](const vola::Voxel& v) {
      ++count;
      return callback(v.x, v.y, v.z, user) == 0;
    });
    check_trees_in_use();
    if (visited) *visited = count;
  });
}

vola_status vola_copy_voxels(const vola_tree* tree, uint64_t first, uint32_t* xyz, size_t capacity, size_t* written) {
  return guarded([&] {
    const vola::Tree& t = tree_of(tree);
    require(written != nullptr, "vola_copy_voxels: written is NULL");
    require(xyz != nullptr || capacity == 0, "vola_copy_voxels: xyz is NULL");
    size_t n = 0;
    if (capacity > 0 && first < t.voxel_count()) {
      visit_from(t, first, [&](const vola::Voxel& v) {
        xyz[3 * n] = v.x;
        xyz[3 * n + 1] = v.y;
        xyz[3 * n + 2] = v.z;
        return ++n < capacity;
      });
    }
    check_trees_in_use();
    *written = n;
  });
}

vola_status vola_attribute_name(const vola_tree* tree, size_t index, const char** out) {
  return guarded([&] {
    const vola::Tree& t = tree_of(tree);
    require(out != nullptr, "vola_attribute_name: out is NULL");
    if (index >= t.attributes().size())
      throw vola::InvalidArgument("vola_attribute_name: index " + std::to_string(index) + " but the tree has " +
                                  std::to_string(t.attributes().size()) + " attribute columns");
    *out = t.attributes().columns()[index].name().c_str();
  });
}

vola_status vola_attribute_value(const vola_tree* tree, const char* name, uint64_t rank, double* out) {
  return guarded([&] {
    const vola::Tree& t = tree_of(tree);
    require(name != nullptr && out != nullptr, "vola_attribute_value: name and out must not be NULL");
    const vola::AttributeColumn* column = t.attributes().find(name);
    if (!column) throw vola::InvalidArgument(std::string("vola_attribute_value: no attribute column '") + name + "'");
    if (rank >= column->size())
      throw vola::InvalidArgument("vola_attribute_value: rank " + std::to_string(rank) + " but the column has " +
                                  std::to_string(column->size()) + " values");
    const double value = column->get(static_cast<std::size_t>(rank));
    check_trees_in_use();
    *out = value;
  });
}

}  // extern "C"
