// The mesh and DEM readers go through third-party libraries that open paths, so their
// fuzz entry points write each input to a scratch file of this process first.
#pragma once

#include <unistd.h>

#include <cstdint>
#include <filesystem>
#include <fstream>
#include <set>
#include <span>
#include <string>
#include <string_view>

namespace vola_fuzz {

// The scratch files this process wrote, removed when it exits (a seed test or a fuzz run
// leaves nothing in the temporary folder).
class ScratchFiles {
 public:
  ScratchFiles() = default;
  ScratchFiles(const ScratchFiles&) = delete;
  ScratchFiles& operator=(const ScratchFiles&) = delete;
  ~ScratchFiles() {
    for (const auto& path : paths_) {
      std::error_code ignored;
      std::filesystem::remove_all(path, ignored);  // a file, or a scratch folder (fuzz_ept_read)
    }
  }
  void add(const std::string& path) { paths_.insert(path); }

 private:
  std::set<std::string> paths_;
};

inline ScratchFiles& scratch_files() {
  static ScratchFiles files;
  return files;
}

// Writes `bytes` to "<tmp>/vola_fuzz_<stem>_<pid>.<extension>" and returns its path (the
// extension is what the libraries pick their parser by); the file goes when the process exits.
inline std::string scratch_file(const std::string& stem, const std::string& extension,
                                std::span<const std::uint8_t> bytes) {
  const std::string path = (std::filesystem::temp_directory_path() /
                            ("vola_fuzz_" + stem + "_" + std::to_string(::getpid()) + "." + extension))
                               .string();
  scratch_files().add(path);
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  out.write(reinterpret_cast<const char*>(bytes.data()), static_cast<std::streamsize>(bytes.size()));
  return path;
}

// "<tmp>/vola_fuzz_<stem>_<pid>", a folder for inputs that are several files (an EPT
// dataset, a ROS map's YAML and image), removed when the process exits; not created here.
inline std::filesystem::path scratch_folder(const std::string& stem) {
  const auto folder = std::filesystem::temp_directory_path() / ("vola_fuzz_" + stem + "_" + std::to_string(::getpid()));
  scratch_files().add(folder.string());
  return folder;
}

// Writes `bytes` to `path`, replacing what was there.
inline void write_scratch(const std::filesystem::path& path, std::string_view bytes) {
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  out.write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
}

}  // namespace vola_fuzz
