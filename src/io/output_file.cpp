#include "output_file.hpp"

#include <cerrno>
#include <cstring>

#include "vola/error.hpp"

namespace vola::io {

OutputFile::OutputFile(std::string path) : path_(std::move(path)), temporary_(path_ + ".part") {
  file_ = std::fopen(temporary_.c_str(), "wb");
  if (!file_) throw IoError(path_ + ": cannot create: " + std::strerror(errno));
  // Writers emit many small records: a large buffer keeps the system calls few.
  std::setvbuf(file_, nullptr, _IOFBF, std::size_t{1} << 20);
}

OutputFile::~OutputFile() {
  if (!file_) return;
  std::fclose(file_);
  std::remove(temporary_.c_str());
}

void OutputFile::write(const void* data, std::size_t size) {
  if (size != 0 && std::fwrite(data, 1, size, file_) != size)
    throw IoError(path_ + ": write failed: " + std::strerror(errno));
}

void OutputFile::commit() {
  std::FILE* f = file_;
  file_ = nullptr;
  const bool failed = std::ferror(f) != 0;
  if (std::fclose(f) != 0 || failed) {
    const int error = errno;
    std::remove(temporary_.c_str());
    throw IoError(path_ + ": write failed: " + std::strerror(error));
  }
  if (std::rename(temporary_.c_str(), path_.c_str()) != 0) {
    const int error = errno;
    std::remove(temporary_.c_str());
    throw IoError(path_ + ": cannot rename from " + temporary_ + ": " + std::strerror(error));
  }
}

}  // namespace vola::io
