// RGB-D sequences on disk and trajectories in TUM's text format.
//
// TUM RGB-D layout: SEQUENCE_DIR/depth.txt and (optional) rgb.txt list "timestamp path"
// per line (path relative to SEQUENCE_DIR; '#' lines are comments); the optional
// groundtruth.txt lists "timestamp tx ty tz qx qy qz qw" (camera-to-world). RGB frames
// are associated with the depth frame of nearest timestamp within max_difference.
//
// Numbered layout (slambook's ICL-NUIM and Kinect frames): no depth.txt, but depth/
// holding N.png or N.pgm (N = 1, 2, ...), optional color/ or rgb/ with the same
// numbers, and an optional pose.txt of "tx ty tz qx qy qz qw" lines, line i for frame
// i; frame N gets timestamp N.
//
// Either layout may hold intrinsics.txt, one line "fx fy cx cy" (vola rgbd-generate
// writes it), used when the caller gives no intrinsics.
#pragma once

#include <Eigen/Geometry>
#include <optional>
#include <string>
#include <vector>

#include "vola/slam/image.hpp"

namespace vola::slam {

using Pose = Eigen::Isometry3d;  // camera-to-world

struct StampedPose {
  double timestamp = 0.0;
  Pose pose = Pose::Identity();
};

struct SequenceFrame {
  double timestamp = 0.0;
  std::string depth_path;
  std::string rgb_path;  // empty when there is no associated colour frame
};

struct Sequence {
  std::vector<SequenceFrame> frames;
  std::vector<StampedPose> groundtruth;  // empty when the sequence has none
  std::optional<Intrinsics> intrinsics;  // from intrinsics.txt
};

// Reads "fx fy cx cy" (the first non-comment line); errors name the file and line.
Intrinsics read_intrinsics(const std::string& file);
void write_intrinsics(const std::string& file, const Intrinsics& intrinsics);

struct TimedPath {
  double timestamp = 0.0;
  std::string path;
  std::size_t line = 0;  // in the list file (1-based)
};

// One "timestamp path" list. Throws FormatError "<file>: line N: ..." for a line that is
// not a finite timestamp followed by a path, IoError when the file cannot be opened.
std::vector<TimedPath> read_timed_list(const std::string& file);

// "timestamp tx ty tz qx qy qz qw" lines, returned in time order whatever the lines'
// order; the quaternion must have a norm within 1e-3 of 1 after parsing (it is then
// normalised). Errors name the file and line.
std::vector<StampedPose> read_trajectory(const std::string& file);
// Poses without timestamps ("tx ty tz qx qy qz qw"), timestamped 1, 2, ...
std::vector<StampedPose> read_numbered_poses(const std::string& file);
// Writes the TUM format with full double precision; throws IoError.
void write_trajectory(const std::string& file, const std::vector<StampedPose>& poses);

// Reads either layout (see above); throws FormatError/IoError naming what is missing
// (a frame file that a list names but that does not exist: the list's file and line).
Sequence read_sequence(const std::string& directory, double max_difference = 0.02);

// Pairs a[i] with the b of nearest timestamp within max_difference, each b used at
// most once, greedily by increasing time difference (TUM's associate.py): indices
// into a and b, in a's order.
std::vector<std::pair<std::size_t, std::size_t>> associate(const std::vector<double>& a, const std::vector<double>& b,
                                                          double max_difference);

}  // namespace vola::slam
