#include "vola/io/file_checks.hpp"

#include <fcntl.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <filesystem>
#include <system_error>

#include "vola/error.hpp"

namespace vola::io {

void refuse_output_over_input(const std::string& input, const std::string& output, const std::string& advice) {
  std::error_code error;
  if (std::filesystem::equivalent(input, output, error))
    throw InvalidArgument(output + " is the input: " + advice);
}

void refuse_non_regular_input(const std::string& path) {
  namespace fs = std::filesystem;
  std::error_code error;
  const fs::file_status status = fs::status(path, error);
  if (error || !fs::exists(status) || fs::is_regular_file(status)) return;
  const char* kind = fs::is_directory(status) ? "a directory" : fs::is_fifo(status) ? "a FIFO" : "a device or socket";
  throw InvalidArgument(path + ": not a regular file (" + kind + "): inputs are files");
}

void refuse_unopenable_input(const std::string& path) {
  // O_NONBLOCK: a FIFO (refused above) does not wait for a writer here either.
  const int fd = ::open(path.c_str(), O_RDONLY | O_CLOEXEC | O_NONBLOCK);
  if (fd < 0) {
    const int error = errno;
    throw IoError(path + ": cannot open: " + std::strerror(error));
  }
  ::close(fd);
}

}  // namespace vola::io
