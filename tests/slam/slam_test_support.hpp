// Helpers of the SLAM tests: the shared data folder, scratch folders, small files and
// synthetic sequences.
#pragma once

#include <cstdlib>
#include <string>

#include "test_support.hpp"
#include "vola/slam/fusion.hpp"
#include "vola/slam/sequence.hpp"

namespace vola_slam_test {

namespace fs = vola_test::fs;

// $VOLA_SHARED/data/rgbd.
inline fs::path rgbd_dir() { return vola_test::golden_dir().parent_path() / "data" / "rgbd"; }

// A fresh empty folder under the system temp folder, removed by the destructor.
class ScratchDir {
 public:
  explicit ScratchDir(const std::string& name);
  ~ScratchDir();
  const fs::path& path() const noexcept { return path_; }

 private:
  fs::path path_;
};

void write_text(const fs::path& path, const std::string& text);

// The room sequence: `frames` frames of width x height at `degrees_per_frame`, with
// the Kinect noise model, written into `directory` (the generator's output).
void make_room_sequence(const fs::path& directory, std::size_t frames, std::uint32_t width, std::uint32_t height,
                        double degrees_per_frame, bool noise);

// Fusion at 2 cm voxels, 8 cm truncation, two threads: the small scenes of the unit tests.
inline vola::slam::FusionParams small_scene_params() {
  vola::slam::FusionParams p;
  p.voxel_size = 0.02;
  p.truncation = 0.08;
  p.threads = 2;
  return p;
}

}  // namespace vola_slam_test

// Skips (or fails with CI set) when the shared RGB-D folder is missing.
#define VOLA_REQUIRE_RGBD(dir_var)                                                             \
  const ::vola_test::fs::path dir_var = ::vola_slam_test::rgbd_dir();                          \
  if (!::vola_test::fs::is_directory(dir_var)) {                                               \
    if (std::getenv("CI")) {                                                                   \
      ADD_FAILURE() << "data folder " << dir_var << " is missing (CI is set; set VOLA_SHARED)"; \
      return;                                                                                  \
    }                                                                                          \
    GTEST_SKIP() << "data folder " << dir_var << " is missing; set VOLA_SHARED to run this";    \
  }
