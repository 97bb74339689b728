// Fuzz entry point of the RGB-D readers of src/slam (what vola rgbd-fuse and the SLAM
// tools read): the first byte picks the reader (modulo 6), the rest is the file, written
// to a scratch file of this process:
//   0 depth image (16-bit grey PNG or 16-bit PGM, read_depth)   1 colour PNG (read_rgb_png)
//   2 "timestamp path" list (depth.txt, rgb.txt)                 3 TUM trajectory
//   4 numbered poses (pose.txt)                                  5 intrinsics.txt
// Only vola::Error may escape; images must hold width x height samples, poses finite
// rotations, intrinsics non-zero focal lengths.
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <span>
#include <string>

#include "fuzz_seeds.hpp"
#include "scratch_file.hpp"
#include "vola/error.hpp"
#include "vola/slam/image.hpp"
#include "vola/slam/sequence.hpp"

namespace {

using vola_fuzz::check;

void check_poses(const std::vector<vola::slam::StampedPose>& poses) {
  for (const auto& p : poses) {
    check(std::isfinite(p.timestamp) && p.pose.matrix().allFinite());
    check(std::abs(p.pose.linear().determinant() - 1.0) < 1e-6);
  }
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  if (size == 0) return 0;
  const std::span<const std::uint8_t> file(data + 1, size - 1);
  namespace slam = vola::slam;
  try {
    switch (data[0] % 6) {
      case 0: {
        const auto depth = slam::read_depth(vola_fuzz::scratch_file("depth", "png", file), 1000.0);
        check(depth.width > 0 && depth.height > 0 && depth.metres.size() == std::size_t{depth.width} * depth.height);
        for (float m : depth.metres) check(std::isfinite(m) && m >= 0.0f);
        break;
      }
      case 1: {
        const auto rgb = slam::read_rgb_png(vola_fuzz::scratch_file("rgb", "png", file));
        check(rgb.rgb.size() == std::size_t{rgb.width} * rgb.height * 3);
        break;
      }
      case 2:
        for (const auto& t : slam::read_timed_list(vola_fuzz::scratch_file("list", "txt", file)))
          check(std::isfinite(t.timestamp) && !t.path.empty());
        break;
      case 3: check_poses(slam::read_trajectory(vola_fuzz::scratch_file("trajectory", "txt", file))); break;
      case 4: check_poses(slam::read_numbered_poses(vola_fuzz::scratch_file("poses", "txt", file))); break;
      default: {
        const auto k = slam::read_intrinsics(vola_fuzz::scratch_file("intrinsics", "txt", file));
        k.check();  // an InvalidArgument here aborts below
        break;
      }
    }
  } catch (const vola::InvalidArgument&) {
    std::abort();  // the readers report FormatErrors and IoErrors only
  } catch (const vola::Error&) {
    ++vola_fuzz::stats().refused;
    return 0;
  }
  ++vola_fuzz::stats().parsed;
  return 0;
}
