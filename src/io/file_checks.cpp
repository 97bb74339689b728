#include "vola/io/file_checks.hpp"

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

}  // namespace vola::io
