// Plugins: parts of vola built as shared objects and loaded on first use, because the
// libraries they link cost every program start-up time (mapping and relocating them)
// although few runs need them: libvola_gdal.so (elevation rasters), libvola_assimp.so
// (meshes), libvola_proj.so (coordinate reference systems), libvola_mpi.so (vola tile
// under mpirun), libvola_octomap.so (OctoMap .bt/.ot maps), libvola_opencv.so (ORB
// features for vola fuse), libvola_openvdb.so (OpenVDB .vdb maps, with TBB, Blosc and
// Boost behind it). Internal: a plugin is built
// with the same compiler and library as its loader, so C++ types cross the boundary;
// errors cross as a PluginFailure, not as exceptions.
#pragma once

#include <cstdint>
#include <new>
#include <optional>
#include <string>

#include "vola/error.hpp"
#include "vola/version.hpp"

namespace vola::plugin {

// What went wrong inside a plugin, to be thrown again on the loader's side.
struct PluginFailure {
  enum class Kind { none, format, invalid_argument, io, out_of_memory, other };
  Kind kind = Kind::none;
  std::string file;                     // format errors
  std::optional<std::uint64_t> offset;  // format errors
  std::string message;                  // the cause (format errors) or what()
};

// A plugin from another version of vola, or built against another revision of this
// contract, is refused: the types of its entry points may differ. Bump the revision
// when they change.
inline constexpr const char* kVersionSymbol = "vola_plugin_version";
inline constexpr const char* kPluginVersion = VOLA_VERSION_STRING "/plugin-abi-1";
using VersionEntry = const char* (*)();

// Plugin side: runs `body`, turning what it throws into `failure`.
template <class Body>
void capture_failure(PluginFailure& failure, Body&& body) noexcept {
  using Kind = PluginFailure::Kind;
  try {
    body();
  } catch (const FormatError& e) {
    failure = {Kind::format, e.file(), e.offset(), e.cause()};
  } catch (const InvalidArgument& e) {
    failure = {Kind::invalid_argument, {}, {}, e.what()};
  } catch (const IoError& e) {
    failure = {Kind::io, {}, {}, e.what()};
  } catch (const std::bad_alloc&) {
    failure = {Kind::out_of_memory, {}, {}, "out of memory"};
  } catch (const std::exception& e) {
    failure = {Kind::other, {}, {}, e.what()};
  } catch (...) {
    failure = {Kind::other, {}, {}, "unknown error"};
  }
}

// Loader side: throws what the plugin caught, as the same kind of error.
inline void throw_failure(const PluginFailure& failure) {
  using Kind = PluginFailure::Kind;
  switch (failure.kind) {
    case Kind::none:
      return;
    case Kind::format:
      throw FormatError(failure.file, failure.offset, failure.message);
    case Kind::invalid_argument:
      throw InvalidArgument(failure.message);
    case Kind::io:
      throw IoError(failure.message);
    case Kind::out_of_memory:
      throw std::bad_alloc();
    case Kind::other:
      throw Error(failure.message);
  }
}

// The address of `symbol` in libvola_<name>.so, loading the plugin on first use (thread
// safe). Searched in $VOLA_PLUGIN_DIR, next to the program or library the loader is
// linked into (and its ../lib/vola), the build tree, then the install prefix. Throws
// IoError saying what needed it (`purpose`, e.g. "a.tif: reading it"), the plugin and
// every folder searched.
void* plugin_symbol(const char* name, const char* symbol, const std::string& purpose);

}  // namespace vola::plugin
