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

// One option of a library call that makes no sense. option() names the member of the
// options struct (e.g. "voxel_size"), so that a front end can name its own spelling of it
// (the CLI's --voxel-size, Python's voxel_size=); what() reads "<option>: <cause>". An
// empty option is a refusal about no one option the caller gave (the cause still names
// options in backticks, `allow_geographic`, for the front end to spell): what() is the cause.
class OptionError : public InvalidArgument {
 public:
  OptionError(std::string option, std::string cause)
      : InvalidArgument(option.empty() ? cause : option + ": " + cause), option_(std::move(option)),
        cause_(std::move(cause)) {}
  const std::string& option() const noexcept { return option_; }
  const std::string& cause() const noexcept { return cause_; }

 private:
  std::string option_;
  std::string cause_;
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
      : Error(compose(file, offset, printable(cause))),
        file_(std::move(file)),
        offset_(offset),
        cause_(printable(cause)) {}

  const std::string& file() const noexcept { return file_; }
  std::optional<std::uint64_t> offset() const noexcept { return offset_; }
  const std::string& cause() const noexcept { return cause_; }

 private:
  // A cause quotes bytes of the file ("unknown keyword '...'"): control characters (an
  // escape sequence would reach the user's terminal) are written as \xNN.
  static std::string printable(const std::string& text) {
    std::string out;
    out.reserve(text.size());
    for (const char ch : text) {
      const auto c = static_cast<unsigned char>(ch);
      if ((c < 0x20 && c != '\n' && c != '\t') || c == 0x7f) {
        static constexpr char kHex[] = "0123456789abcdef";
        out += "\\x";
        out += kHex[c >> 4];
        out += kHex[c & 15];
      } else {
        out += ch;
      }
    }
    return out;
  }
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

// Builds without exceptions (-fno-exceptions, e.g. for a microcontroller): every place
// the library would throw calls the error handler with the error's what() instead. The
// handler must not return (log and reset, longjmp out, or exit); when it does, or when
// none is set, the message goes to stderr and the program aborts. Not thread-safe to
// change while the library runs. With exceptions (the default) the handler is unused:
// errors are thrown as documented. See docs/EMBEDDED.md.
using ErrorHandler = void (*)(const char* message);
// Returns the previous handler (nullptr = the default).
ErrorHandler set_error_handler(ErrorHandler handler) noexcept;

namespace detail {
[[noreturn]] void fail(const Error& error) noexcept;
}  // namespace detail

VOLA_INLINE_NAMESPACE_END
}  // namespace vola

// `VOLA_THROW(FormatError(...))`: throws, or calls the error handler when exceptions
// are off.
#if defined(__cpp_exceptions) || defined(__EXCEPTIONS)
#define VOLA_THROW(...) throw __VA_ARGS__
#else
#define VOLA_THROW(...) ::vola::detail::fail(__VA_ARGS__)
#endif
