// Fuzz entry point of the .npz reader (src/io/npz.cpp and src/learn/npz.cpp: point files, what vola train and
// the ModelNet tools read): the input is the archive, written to a scratch file of this
// process; its member names are listed, the first members parsed as .npy, and the
// labelled grids read as training does. libzip parses the zip; vola checks each member's
// stated sizes against the archive and inflates no more than they state. Only
// vola::Error may escape; grids that read hold 0/1 cells and labels 0..9, one per grid.
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <span>
#include <string>

#include "fuzz_seeds.hpp"
#include "scratch_file.hpp"
#include "vola/error.hpp"
#include "vola/learn/npz.hpp"

namespace {

using vola_fuzz::check;

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  namespace learn = vola::learn;
  namespace io = vola::io;
  const std::string path = vola_fuzz::scratch_file("npz", "npz", std::span(data, size));
  try {
    const auto names = io::npz_array_names(path);
    for (std::size_t i = 0; i < names.size() && i < 4; ++i) {
      try {
        const vola::io::NpyArray a = io::read_npz_array(path, names[i]);
        check(a.data.size() == a.size() * static_cast<std::uint64_t>(a.item_size));
      } catch (const vola::Error&) {
      }
    }
    // As a point file (vola convert X.npz): the member the reader picks, read as points.
    try {
      const std::string member = io::npz_points_member(path, "");
      const vola::io::Input in = io::npy_input(io::read_npz_array(path, member), path, {});
      check(in.cloud.xyz.size() % 3 == 0);
      for (const auto& a : in.cloud.attributes) check(a.values.size() == in.cloud.size());
    } catch (const vola::Error&) {
    }
    const learn::LabelledGrids grids = learn::read_labelled_grids(path);
    check(grids.side >= 4 && grids.side <= 256);
    check(grids.cells.size() == grids.size() * grids.cells_per_grid());
    for (int label : grids.labels) check(label >= 0 && label <= 9);
    for (std::uint8_t c : grids.cells) check(c <= 1);
    ++vola_fuzz::stats().parsed;
  } catch (const vola::Error&) {
    ++vola_fuzz::stats().refused;
  }
  return 0;
}
