// An output file that appears whole or not at all. Every writer of vola (the .vol
// writer, exports, images, sounds, CSV, tile sets) goes through it:
//
//   - the bytes go to an unnamed file in the same directory as the final name (Linux's
//     O_TMPFILE), or, on a filesystem without those, to a named temporary
//     (`<path>.<pid>.<n>.part`, created exclusively, so no stranger's file is reused);
//   - commit() flushes and fsyncs it, links the unnamed file as `<path>.<pid>.<n>.part`,
//     closes it and renames it onto the final name, then fsyncs the directory: the old
//     file stays in place, untouched, until the new one is complete on disk, and is then
//     replaced in one step;
//   - on any error, and when the object is destroyed uncommitted (an exception
//     unwinding), the temporary is closed and removed: no partial file is left;
//   - while it exists, the temporary's name sits in a fixed, lock-free table, so that a
//     process killed by SIGINT, SIGTERM or SIGHUP removes it too once
//     remove_temporaries_on_signal() has installed the handlers (the CLI does at start).
//
// What it cannot cover: SIGKILL or power loss in the instant between the link and the
// rename (or at any time on a filesystem without O_TMPFILE) leaves a `.part` file beside
// the old, intact file; more than 64 files written at once are not all in the table.
#pragma once

#include <cstddef>
#include <cstdio>
#include <string>
#include <string_view>

#include "vola/version.hpp"

namespace vola {
VOLA_INLINE_NAMESPACE_BEGIN

class OutputFile {
 public:
  // Creates the temporary; throws IoError naming `path` when it cannot.
  explicit OutputFile(std::string path);
  // Uncommitted: closes and removes the temporary.
  ~OutputFile();
  OutputFile(const OutputFile&) = delete;
  OutputFile& operator=(const OutputFile&) = delete;

  // Throws IoError (with the system's reason, e.g. "File too large") when the write fails.
  void write(const void* data, std::size_t size);
  void write(std::string_view text) { write(text.data(), text.size()); }
  // The open stream, for libraries that write through a FILE* (libpng).
  std::FILE* stream() noexcept { return file_; }
  // The descriptor, for libraries that write by descriptor (libsndfile). Do not mix
  // with write() or stream() on the same file.
  int descriptor() const noexcept;
  // Flushes, fsyncs, closes and renames onto the final path; throws IoError on failure,
  // after removing the temporary. Call once.
  void commit();
  const std::string& path() const noexcept { return path_; }
  // A name the temporary can be written through, for libraries that open files by name
  // (`/proc/self/fd/N` while it is unnamed).
  const std::string& temporary() const noexcept { return temporary_; }

 private:
  void discard() noexcept;
  int give_a_name() noexcept;  // 0, or the errno
  std::string path_;
  std::string temporary_;
  std::FILE* file_ = nullptr;
  int slot_ = -1;        // in the table of live temporaries, or -1
  bool unnamed_ = false;  // an O_TMPFILE file with no name yet
};

// Installs handlers for SIGINT, SIGTERM and SIGHUP that remove every live temporary
// (unlink() only: async-signal-safe) and then end the process by the same signal with
// its default action, so the exit status still says which signal it was. A signal that
// already has a handler of its own (or is ignored) is left alone. Call once, from the
// main thread, before writing; the library never installs them by itself.
void remove_temporaries_on_signal() noexcept;

namespace detail {
// Unlinks every live temporary (async-signal-safe); for handlers and the abort path.
void remove_live_temporaries() noexcept;
}  // namespace detail

VOLA_INLINE_NAMESPACE_END
}  // namespace vola
