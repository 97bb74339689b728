// A std::ostream onto an OutputFile, for writers that format with <<: the same
// temporary-fsync-rename rule (vola/output_file.hpp), nothing at the final name until
// commit(), and the temporary removed if commit() is never reached.
#pragma once

#include <cerrno>
#include <cstdio>
#include <cstring>
#include <ostream>
#include <streambuf>
#include <string>

#include "vola/error.hpp"
#include "vola/output_file.hpp"

namespace vola {
VOLA_INLINE_NAMESPACE_BEGIN

class OutputStream : public std::ostream {
 public:
  explicit OutputStream(std::string path) : std::ostream(nullptr), file_(std::move(path)), buffer_(file_.stream()) {
    rdbuf(&buffer_);
  }

  // Throws IoError when any write failed (the stream went bad) or the commit fails.
  void commit() {
    flush();
    if (!*this) {
      const int e = errno;
      VOLA_THROW(IoError(file_.path() + ": write failed: " + std::strerror(e)));
    }
    file_.commit();
  }
  const std::string& path() const noexcept { return file_.path(); }

 private:
  // Straight into the FILE*'s own buffer: no second buffer, and a failed write makes
  // the stream bad rather than throwing through the iostream machinery.
  class Buffer : public std::streambuf {
   public:
    explicit Buffer(std::FILE* file) : file_(file) {}

   protected:
    int_type overflow(int_type c) override {
      if (traits_type::eq_int_type(c, traits_type::eof())) return traits_type::not_eof(c);
      return std::fputc(c, file_) == EOF ? traits_type::eof() : c;
    }
    std::streamsize xsputn(const char* s, std::streamsize n) override {
      return static_cast<std::streamsize>(std::fwrite(s, 1, static_cast<std::size_t>(n), file_));
    }

   private:
    std::FILE* file_;
  };
  OutputFile file_;
  Buffer buffer_;
};

VOLA_INLINE_NAMESPACE_END
}  // namespace vola
