// libvola_mpi.so: MPI_COMM_WORLD behind the entry points of mpi_plugin.hpp.
#include <mpi.h>

#include <cstdlib>
#include <limits>
#include <string>

#include "../mpi_plugin.hpp"
#include "vola/error.hpp"

namespace vola::tile {

namespace {

void check(int status, const char* what) {
  if (status != MPI_SUCCESS) throw Error(std::string("MPI: ") + what + " failed");
}

int count_of(std::size_t n, const char* what) {
  if (n > static_cast<std::size_t>(std::numeric_limits<int>::max()))
    throw Error(std::string("MPI: ") + what + ": message too large for one call");
  return static_cast<int>(n);
}

class MpiWorld {
 public:
  MpiWorld() {
    int initialised = 0;
    MPI_Initialized(&initialised);
    if (!initialised) check(MPI_Init(nullptr, nullptr), "MPI_Init");
    MPI_Comm_rank(MPI_COMM_WORLD, &rank_);
    MPI_Comm_size(MPI_COMM_WORLD, &size_);
  }
  ~MpiWorld() {
    int finalised = 0;
    MPI_Finalized(&finalised);
    if (!finalised) MPI_Finalize();
  }
  int rank() const noexcept { return rank_; }
  int size() const noexcept { return size_; }

  std::vector<std::vector<std::uint8_t>> all_gather(std::span<const std::uint8_t> mine) {
    const int n = count_of(mine.size(), "all_gather");
    std::vector<int> counts(size_), offsets(size_);
    check(MPI_Allgather(&n, 1, MPI_INT, counts.data(), 1, MPI_INT, MPI_COMM_WORLD), "MPI_Allgather");
    std::size_t total = 0;
    for (int r = 0; r < size_; ++r) {
      offsets[r] = count_of(total, "all_gather");
      total += static_cast<std::size_t>(counts[r]);
    }
    std::vector<std::uint8_t> all(total);
    check(MPI_Allgatherv(mine.data(), n, MPI_BYTE, all.data(), counts.data(), offsets.data(), MPI_BYTE,
                         MPI_COMM_WORLD),
          "MPI_Allgatherv");
    std::vector<std::vector<std::uint8_t>> out(size_);
    for (int r = 0; r < size_; ++r) out[r].assign(all.begin() + offsets[r], all.begin() + offsets[r] + counts[r]);
    return out;
  }

  std::vector<std::vector<std::uint64_t>> gather(int root, std::span<const std::uint64_t> mine) {
    const int n = count_of(mine.size(), "gather");
    std::vector<int> counts(rank_ == root ? size_ : 0), offsets(rank_ == root ? size_ : 0);
    check(MPI_Gather(&n, 1, MPI_INT, counts.data(), 1, MPI_INT, root, MPI_COMM_WORLD), "MPI_Gather");
    std::vector<std::uint64_t> all;
    if (rank_ == root) {
      std::size_t total = 0;
      for (int r = 0; r < size_; ++r) {
        offsets[r] = count_of(total, "gather");
        total += static_cast<std::size_t>(counts[r]);
      }
      all.resize(total);
    }
    check(MPI_Gatherv(mine.data(), n, MPI_UINT64_T, all.data(), counts.data(), offsets.data(), MPI_UINT64_T, root,
                      MPI_COMM_WORLD),
          "MPI_Gatherv");
    std::vector<std::vector<std::uint64_t>> out;
    if (rank_ != root) return out;
    out.resize(size_);
    for (int r = 0; r < size_; ++r) out[r].assign(all.begin() + offsets[r], all.begin() + offsets[r] + counts[r]);
    return out;
  }

  void barrier() { check(MPI_Barrier(MPI_COMM_WORLD), "MPI_Barrier"); }
  [[noreturn]] void abort(int status) {
    MPI_Abort(MPI_COMM_WORLD, status);
    std::exit(status);
  }

 private:
  int rank_ = 0, size_ = 1;
};

using plugin::PluginFailure;
using vola::plugin::capture_failure;

MpiWorld& as_world(void* world) { return *static_cast<MpiWorld*>(world); }

const plugin::MpiEntries kEntries{
    [](void*& world, int& rank, int& size, PluginFailure& failure) {
      capture_failure(failure, [&] {
        auto* opened = new MpiWorld();
        world = opened;
        rank = opened->rank();
        size = opened->size();
      });
    },
    [](void* world) { delete static_cast<MpiWorld*>(world); },
    [](void* world, std::span<const std::uint8_t> mine, std::vector<std::vector<std::uint8_t>>& out,
       PluginFailure& failure) { capture_failure(failure, [&] { out = as_world(world).all_gather(mine); }); },
    [](void* world, int root, std::span<const std::uint64_t> mine, std::vector<std::vector<std::uint64_t>>& out,
       PluginFailure& failure) { capture_failure(failure, [&] { out = as_world(world).gather(root, mine); }); },
    [](void* world, PluginFailure& failure) { capture_failure(failure, [&] { as_world(world).barrier(); }); },
    [](void* world, int status) { as_world(world).abort(status); },
};

}  // namespace
}  // namespace vola::tile

// The plugin's entry points (src/plugin/plugin.hpp, mpi_plugin.hpp).
extern "C" {
const char* vola_plugin_version() { return vola::plugin::kPluginVersion; }
const vola::tile::plugin::MpiEntries* vola_plugin_mpi_entries() { return &vola::tile::kEntries; }
}
static_assert(std::is_same_v<decltype(&vola_plugin_mpi_entries), vola::tile::plugin::MpiEntriesEntry>);
