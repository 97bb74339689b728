// An output file written through a temporary name and renamed into place by commit(),
// so that a failed export leaves no half-written file; removed if never committed.
#pragma once

#include <cstddef>
#include <cstdio>
#include <string>
#include <string_view>

namespace vola::io {

class OutputFile {
 public:
  explicit OutputFile(std::string path);
  ~OutputFile();
  OutputFile(const OutputFile&) = delete;
  OutputFile& operator=(const OutputFile&) = delete;

  void write(const void* data, std::size_t size);
  void write(std::string_view text) { write(text.data(), text.size()); }
  // The open stream, for libraries that write through a FILE* (libpng).
  std::FILE* stream() noexcept { return file_; }
  // Flushes, closes and renames onto the final path; throws vola::IoError on failure.
  void commit();
  const std::string& path() const noexcept { return path_; }

 private:
  std::string path_;
  std::string temporary_;
  std::FILE* file_ = nullptr;
};

}  // namespace vola::io
