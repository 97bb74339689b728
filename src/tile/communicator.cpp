#include "vola/tile/communicator.hpp"

#include <cstdlib>

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

}  // namespace

std::unique_ptr<Communicator> single_process() { return std::make_unique<SingleProcess>(); }

bool launched_by_mpi() noexcept {
  const char* size = std::getenv("OMPI_COMM_WORLD_SIZE");
  if (!size) size = std::getenv("PMI_SIZE");
  if (!size) size = std::getenv("PMIX_SIZE");
  return size != nullptr;
}

#ifdef VOLA_WITH_MPI
std::unique_ptr<Communicator> mpi_world();  // mpi_communicator.cpp
bool mpi_available() noexcept { return true; }
#else
bool mpi_available() noexcept { return false; }
#endif

std::unique_ptr<Communicator> world() {
  if (!launched_by_mpi()) return single_process();
#ifdef VOLA_WITH_MPI
  return mpi_world();
#else
  throw InvalidArgument("started by mpirun, but this vola was built without MPI (install libopenmpi-dev and rebuild)");
#endif
}

}  // namespace vola::tile
