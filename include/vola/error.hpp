// The library's error family. Every error that comes from outside bytes says which
// file, at which byte offset, and what was wrong; the command-line tool prints what()
// as one line and exits non-zero.
#pragma once

#include <cstdint>
#include <optional>
#include <stdexcept>
#include <string>

#include "vola/version.hpp"

namespace vola {
VOLA_INLINE_NAMESPACE_BEGIN

class Error : public std::runtime_error {
 public:
  explicit Error(const std::string& message) : std::runtime_error(message) {}
};

// Arguments that make no sense (depth 11, mismatched trees, a voxel outside the grid).
class InvalidArgument : public Error {
 public:
  using Error::Error;
};

// The operating system refused (open, map, write).
class IoError : public Error {
 public:
  using Error::Error;
};

// Bytes that are not what the format promises. what() reads
// "<file>: byte <offset>: <cause>".
class FormatError : public Error {
 public:
  FormatError(std::string file, std::optional<std::uint64_t> offset, std::string cause)
      : Error(compose(file, offset, cause)),
        file_(std::move(file)),
        offset_(offset),
        cause_(std::move(cause)) {}

  const std::string& file() const noexcept { return file_; }
  std::optional<std::uint64_t> offset() const noexcept { return offset_; }
  const std::string& cause() const noexcept { return cause_; }

 private:
  static std::string compose(const std::string& file, std::optional<std::uint64_t> offset,
                             const std::string& cause) {
    std::string s = file.empty() ? std::string("<memory>") : file;
    if (offset) s += ": byte " + std::to_string(*offset);
    return s + ": " + cause;
  }
  std::string file_;
  std::optional<std::uint64_t> offset_;
  std::string cause_;
};

VOLA_INLINE_NAMESPACE_END
}  // namespace vola
