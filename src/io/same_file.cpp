#include "vola/io/same_file.hpp"

#include <filesystem>
#include <system_error>

#include "vola/error.hpp"

namespace vola::io {

void refuse_output_over_input(const std::string& input, const std::string& output, const std::string& advice) {
  std::error_code error;
  if (std::filesystem::equivalent(input, output, error))
    throw InvalidArgument(output + " is the input: " + advice);
}

}  // namespace vola::io
