// Internal: the folders of one `vola tile` run inside its output folder.
//
// A run never writes where the live tile set is. Its tiles and overviews go into a
// fresh generation folder, OUTDIR/.generation-<n>/, and the index it writes last
// (OUTDIR/index.geojson, renamed into place whole) names files in that folder. Until
// that rename the old index and the old generation are untouched, so a run killed at
// any moment leaves the old tile set readable and consistent; after it, the previous
// generation is removed. <n> is one more than the live generation's (1 when there is
// none), so that the same input gives the same bytes in a fresh folder for every thread
// and rank count.
//
// What a killed run leaves behind (a generation the index does not name, spill folders
// of processes that are gone) is removed by the next run in the same folder.
#pragma once

#include <filesystem>
#include <string>
#include <vector>

#include "vola/tile/communicator.hpp"

namespace vola::tile::detail {

// Rank 0's hold on the output folder for a whole run (flock of OUTDIR/.lock, released
// when the process ends, however it ends): two runs into one folder both wrote into the
// same generation, exited 0 and left tiles of either in the set. Every rank learns rank
// 0's answer; a folder another run holds is an IoError naming it.
class OutputLock {
 public:
  OutputLock(const std::filesystem::path& output_dir, Communicator& comm);
  ~OutputLock();
  OutputLock(const OutputLock&) = delete;
  OutputLock& operator=(const OutputLock&) = delete;

 private:
  int fd_ = -1;
};

struct Generation {
  std::filesystem::path output_dir;
  std::string name;  // ".generation-<n>": the prefix of every file the new index names
  // What the live index names, removed once the new one is in place.
  std::string previous_name;                // empty when the live set has no generation
  std::vector<std::string> previous_files;  // relative to output_dir
  std::filesystem::path dir() const { return output_dir / name; }
};

// Every rank: reads the live index (if any) to name the next generation; rank 0 removes
// what no index names (stale generations, including an older run's folder of the same
// name), then all ranks meet, so nobody writes into a folder being removed.
Generation begin_generation(const std::filesystem::path& output_dir, Communicator& comm);

// Rank 0, after the new index is in place: removes every file of the tile set the index
// named before (a previous generation, or tiles of the older layout written straight
// into OUTDIR). Failures are ignored: the new set is complete already.
void retire_previous(const Generation& current);

// Spill folders are named rank-<r>-<host>-<pid>; this removes those of this host whose
// process is gone (killed runs never remove their own).
std::string spill_folder_name(int rank);
void remove_stale_spill(const std::filesystem::path& spill_root);

}  // namespace vola::tile::detail
