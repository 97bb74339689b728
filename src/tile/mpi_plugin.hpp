// The entry points of libvola_mpi.so, MPI_COMM_WORLD through Open MPI, loaded only by a
// process that mpirun started (src/plugin/plugin.hpp says why it is a plugin):
// communicator.cpp wraps them as a Communicator. Each reports errors through its
// PluginFailure.
#pragma once

#include <cstdint>
#include <span>
#include <vector>

#include "../plugin/plugin.hpp"

namespace vola::tile::plugin {

using vola::plugin::PluginFailure;

struct MpiEntries {
  // Initialises MPI (once per process); `world` is the plugin's own until close.
  void (*open)(void*& world, int& rank, int& size, PluginFailure& failure);
  void (*close)(void* world);  // finalises MPI
  void (*all_gather)(void* world, std::span<const std::uint8_t> mine, std::vector<std::vector<std::uint8_t>>& out,
                     PluginFailure& failure);
  void (*gather)(void* world, int root, std::span<const std::uint64_t> mine,
                 std::vector<std::vector<std::uint64_t>>& out, PluginFailure& failure);
  void (*barrier)(void* world, PluginFailure& failure);
  void (*abort)(void* world, int status);  // ends every rank; does not return
};

using MpiEntriesEntry = const MpiEntries* (*)();
inline constexpr const char* kMpiEntriesSymbol = "vola_plugin_mpi_entries";

}  // namespace vola::tile::plugin
