// What GDAL writers need around them: option lists freed on scope exit, and a folder of
// GDAL's in-memory file system that a writer fills and the caller empties (GDAL never
// opens a path of the user's; the bytes reach it through vola's temporary file).
#pragma once

#include <cpl_string.h>
#include <cpl_vsi.h>

#include <atomic>
#include <string>
#include <unistd.h>

namespace vola::io {

class Options {
 public:
  Options& set(const char* key, const char* value) {
    list_ = CSLSetNameValue(list_, key, value);
    return *this;
  }
  char** get() const noexcept { return list_; }
  Options() = default;
  Options(const Options&) = delete;
  Options& operator=(const Options&) = delete;
  ~Options() { CSLDestroy(list_); }

 private:
  char** list_ = nullptr;
};

// A folder of /vsimem/ for one write, removed with what GDAL left in it.
class MemoryFolder {
 public:
  MemoryFolder() {
    static std::atomic<unsigned long long> next{0};
    path_ = "/vsimem/vola_" + std::to_string(static_cast<long long>(::getpid())) + "_" +
            std::to_string(next.fetch_add(1));
    VSIMkdir(path_.c_str(), 0700);
  }
  ~MemoryFolder() { VSIRmdirRecursive(path_.c_str()); }
  MemoryFolder(const MemoryFolder&) = delete;
  MemoryFolder& operator=(const MemoryFolder&) = delete;
  const std::string& path() const noexcept { return path_; }

 private:
  std::string path_;
};

}  // namespace vola::io
