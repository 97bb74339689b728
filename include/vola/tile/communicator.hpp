// How the processes of one tiling run talk to each other. One process needs nothing;
// under mpirun every rank reads its share of the input and the ranks exchange voxel
// keys by message (no shared memory is assumed, only an output folder all ranks see).
#pragma once

#include <cstdint>
#include <memory>
#include <span>
#include <vector>

namespace vola::tile {

class Communicator {
 public:
  virtual ~Communicator() = default;
  virtual int rank() const noexcept = 0;
  virtual int size() const noexcept = 0;
  // Every rank's bytes, in rank order, on every rank.
  virtual std::vector<std::vector<std::uint8_t>> all_gather(std::span<const std::uint8_t> mine) = 0;
  // Every rank's words, in rank order, on `root`; the others get nothing back.
  virtual std::vector<std::vector<std::uint64_t>> gather(int root, std::span<const std::uint64_t> mine) = 0;
  virtual void barrier() = 0;
  // Ends every rank of the run (one rank's error must not leave the others waiting).
  [[noreturn]] virtual void abort(int status) = 0;
};

std::unique_ptr<Communicator> single_process();

// True when this process was started by mpirun / mpiexec (Open MPI or a PMI launcher).
bool launched_by_mpi() noexcept;
// Whether this build can talk MPI.
bool mpi_available() noexcept;
// MPI_COMM_WORLD (initialising MPI; finalised when the communicator is destroyed) when
// launched by mpirun and built with MPI; single_process() when not launched by mpirun;
// throws InvalidArgument when launched by mpirun without MPI in this build.
std::unique_ptr<Communicator> world();

}  // namespace vola::tile
