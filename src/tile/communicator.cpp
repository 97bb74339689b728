#include "vola/tile/communicator.hpp"

#include <cstdlib>

#include "mpi_plugin.hpp"
#include "vola/error.hpp"

namespace vola::tile {

namespace {

class SingleProcess final : public Communicator {
 public:
  int rank() const noexcept override { return 0; }
  int size() const noexcept override { return 1; }
  std::vector<std::vector<std::uint8_t>> all_gather(std::span<const std::uint8_t> mine) override {
    return {std::vector<std::uint8_t>(mine.begin(), mine.end())};
  }
  std::vector<std::vector<std::uint64_t>> gather(int, std::span<const std::uint64_t> mine) override {
    return {std::vector<std::uint64_t>(mine.begin(), mine.end())};
  }
  void barrier() override {}
  [[noreturn]] void abort(int status) override { std::exit(status); }
};

#ifdef VOLA_WITH_MPI
// MPI_COMM_WORLD through libvola_mpi.so.
class MpiWorld final : public Communicator {
 public:
  MpiWorld()
      : mpi_(*reinterpret_cast<plugin::MpiEntriesEntry>(
                 vola::plugin::plugin_symbol("mpi", plugin::kMpiEntriesSymbol, "vola under mpirun"))()) {
    call([&](plugin::PluginFailure& f) { mpi_.open(world_, rank_, size_, f); });
  }
  ~MpiWorld() override { mpi_.close(world_); }
  MpiWorld(const MpiWorld&) = delete;
  MpiWorld& operator=(const MpiWorld&) = delete;

  int rank() const noexcept override { return rank_; }
  int size() const noexcept override { return size_; }
  std::vector<std::vector<std::uint8_t>> all_gather(std::span<const std::uint8_t> mine) override {
    std::vector<std::vector<std::uint8_t>> out;
    call([&](plugin::PluginFailure& f) { mpi_.all_gather(world_, mine, out, f); });
    return out;
  }
  std::vector<std::vector<std::uint64_t>> gather(int root, std::span<const std::uint64_t> mine) override {
    std::vector<std::vector<std::uint64_t>> out;
    call([&](plugin::PluginFailure& f) { mpi_.gather(world_, root, mine, out, f); });
    return out;
  }
  void barrier() override {
    call([&](plugin::PluginFailure& f) { mpi_.barrier(world_, f); });
  }
  [[noreturn]] void abort(int status) override {
    mpi_.abort(world_, status);
    std::exit(status);
  }

 private:
  template <class Call>
  static void call(Call&& c) {
    plugin::PluginFailure failure;
    c(failure);
    vola::plugin::throw_failure(failure);
  }

  const plugin::MpiEntries& mpi_;
  void* world_ = nullptr;
  int rank_ = 0, size_ = 1;
};
#endif

}  // namespace

std::unique_ptr<Communicator> single_process() { return std::make_unique<SingleProcess>(); }

bool launched_by_mpi() noexcept {
  const char* size = std::getenv("OMPI_COMM_WORLD_SIZE");
  if (!size) size = std::getenv("PMI_SIZE");
  if (!size) size = std::getenv("PMIX_SIZE");
  return size != nullptr;
}

#ifdef VOLA_WITH_MPI
bool mpi_available() noexcept { return true; }
#else
bool mpi_available() noexcept { return false; }
#endif

std::unique_ptr<Communicator> world() {
  if (!launched_by_mpi()) return single_process();
#ifdef VOLA_WITH_MPI
  return std::make_unique<MpiWorld>();
#else
  throw InvalidArgument("started by mpirun, but this vola was built without MPI (install libopenmpi-dev and rebuild)");
#endif
}

}  // namespace vola::tile
