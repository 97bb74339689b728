#include "slam_test_support.hpp"

#include <fstream>
#include <random>

#include "vola/slam/sequence_generator.hpp"

namespace vola_slam_test {

ScratchDir::ScratchDir(const std::string& name) {
  std::random_device device;
  path_ = fs::temp_directory_path() / ("vola_slam_" + name + "_" + std::to_string(device()));
  fs::remove_all(path_);
  fs::create_directories(path_);
}

ScratchDir::~ScratchDir() {
  std::error_code ec;
  fs::remove_all(path_, ec);
}

void write_text(const fs::path& path, const std::string& text) {
  std::ofstream out(path, std::ios::binary);
  out << text;
}

void make_room_sequence(const fs::path& directory, std::size_t frames, std::uint32_t width, std::uint32_t height,
                        double degrees_per_frame, bool noise) {
  static const vola::Tree scene = vola::slam::room_scene(0.01);
  vola::slam::GeneratorOptions options;
  options.width = width;
  options.height = height;
  const double f = 525.0 * width / 640.0;
  options.intrinsics = {f, f, (width - 1) / 2.0, (height - 1) / 2.0};
  options.noise.enabled = noise;
  vola::slam::generate_sequence(scene, vola::slam::room_trajectory(frames, degrees_per_frame), options,
                                directory.string());
}

}  // namespace vola_slam_test
