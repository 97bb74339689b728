#include "vola/output_file.hpp"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <atomic>
#include <cerrno>
#include <csignal>
#include <cstdlib>
#include <cstring>

#include "vola/error.hpp"

namespace vola {
VOLA_INLINE_NAMESPACE_BEGIN

namespace {

// The table of live temporaries. A signal handler may read it at any instant on any
// thread, so it is fixed-size and lock-free: a slot's path is written while its state
// is `filling` and only read by the handler once the state is `live` (release/acquire).
enum TemporaryState : int { kTemporaryFree = 0, kTemporaryFilling = 1, kTemporaryLive = 2 };
constexpr int kTemporarySlots = 64;
constexpr std::size_t kPathBytes = 4096;
struct TemporarySlot {
  std::atomic<int> state{kTemporaryFree};
  char path[kPathBytes];
};
TemporarySlot temporaries[kTemporarySlots];
std::atomic<unsigned> counter{0};

int claim_slot(const std::string& path) noexcept {
  if (path.size() >= kPathBytes) return -1;
  for (int i = 0; i < kTemporarySlots; ++i) {
    int expected = kTemporaryFree;
    if (!temporaries[i].state.compare_exchange_strong(expected, kTemporaryFilling, std::memory_order_acquire)) continue;
    std::memcpy(temporaries[i].path, path.c_str(), path.size() + 1);
    temporaries[i].state.store(kTemporaryLive, std::memory_order_release);
    return i;
  }
  return -1;  // full: this temporary is still removed on errors, just not on signals
}

void release_slot(int i) noexcept {
  if (i < 0) return;
  temporaries[i].state.store(kTemporaryFilling, std::memory_order_relaxed);  // the handler skips it from now on
  temporaries[i].state.store(kTemporaryFree, std::memory_order_release);
}

std::string directory_of(const std::string& path) {
  const auto slash = path.find_last_of('/');
  if (slash == std::string::npos) return ".";
  return slash == 0 ? "/" : path.substr(0, slash);
}

// The rename is only durable once the directory entry is: failures here are not
// reported, since the new file is already in place and the old one gone.
void sync_directory(const std::string& path) noexcept {
  const int fd = ::open(directory_of(path).c_str(), O_RDONLY | O_DIRECTORY | O_CLOEXEC);
  if (fd < 0) return;
  ::fsync(fd);
  ::close(fd);
}

std::string next_temporary_name(const std::string& path) {
  return path + "." + std::to_string(::getpid()) + "." + std::to_string(counter.fetch_add(1)) + ".part";
}

void on_signal(int signal) {
  detail::remove_live_temporaries();
  struct sigaction action {};
  action.sa_handler = SIG_DFL;
  sigemptyset(&action.sa_mask);
  ::sigaction(signal, &action, nullptr);
  // Blocked while this handler runs: delivered, with the default action, on return.
  ::raise(signal);
}

// What an existing output path is, when it is not a regular file vola may replace.
const char* kind_of(mode_t mode) {
  if (S_ISDIR(mode)) return "a directory";
  if (S_ISCHR(mode)) return "a character device";
  if (S_ISBLK(mode)) return "a block device";
  if (S_ISFIFO(mode)) return "a FIFO";
  if (S_ISSOCK(mode)) return "a socket";
  return "not a regular file";
}

// The name the finished file is renamed onto. The rename replaces whatever has the name,
// so: a symbolic link is followed (its target is written, the link stays); a device, a
// FIFO or a directory is refused (renaming a file onto /dev/null would replace the
// device itself, and a reader of a FIFO would never see the bytes); so is a file without
// its owner's write permission, which root's rename would replace all the same.
// Empty with `why` set when the path cannot be written.
std::string final_path(const std::string& path, std::string& why) {
  if (path.empty()) {
    why = "the output file name is empty";
    return {};
  }
  struct stat link {};
  if (::lstat(path.c_str(), &link) != 0) return path;  // a new file
  std::string target = path;
  if (S_ISLNK(link.st_mode)) {
    char* resolved = ::realpath(path.c_str(), nullptr);
    if (!resolved) {
      why = path + ": is a symbolic link to a file that cannot be reached (" + std::strerror(errno) + ")";
      return {};
    }
    target = resolved;
    std::free(resolved);
  }
  struct stat st {};
  if (::stat(target.c_str(), &st) != 0) return target;  // gone meanwhile: a new file
  if (!S_ISREG(st.st_mode)) {
    why = path + ": is " + kind_of(st.st_mode) +
          ": vola writes regular files (a finished file is renamed onto the name, which would replace it)";
    return {};
  }
  if (!(st.st_mode & S_IWUSR)) {
    why = path + ": is read-only: vola does not replace it (make it writable, or write another name)";
    return {};
  }
  return target;
}

}  // namespace

namespace detail {
void remove_live_temporaries() noexcept {
  for (TemporarySlot& s : temporaries)
    if (s.state.load(std::memory_order_acquire) == kTemporaryLive) ::unlink(s.path);
}
}  // namespace detail

void remove_temporaries_on_signal() noexcept {
  for (const int signal : {SIGINT, SIGTERM, SIGHUP}) {
    struct sigaction old {};
    if (::sigaction(signal, nullptr, &old) != 0 || old.sa_handler != SIG_DFL) continue;
    struct sigaction action {};
    action.sa_handler = on_signal;
    sigemptyset(&action.sa_mask);
    ::sigaction(signal, &action, nullptr);
  }
}

OutputFile::OutputFile(std::string path) {
  std::string why;
  path_ = final_path(path, why);
  if (path_.empty()) {
    path_ = std::move(path);
    VOLA_THROW(IoError(why));
  }
  // An unnamed file first (Linux's O_TMPFILE): until commit() it has no name, so not even
  // SIGKILL or a power cut can leave it behind. Filesystems without it get a named one.
  int fd = ::open(directory_of(path_).c_str(), O_TMPFILE | O_WRONLY | O_CLOEXEC, 0666);
  if (fd >= 0) {
    unnamed_ = true;
    temporary_ = "/proc/self/fd/" + std::to_string(fd);
  } else {
    temporary_ = next_temporary_name(path_);
    // Registered before it exists: a signal between open() and the table would leave it.
    slot_ = claim_slot(temporary_);
    fd = ::open(temporary_.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC, 0666);
    if (fd < 0) {
      const int e = errno;
      release_slot(slot_);
      slot_ = -1;
      // The temporary's name is ours, not the user's: say what they can act on.
      const std::string folder = directory_of(path_);
      struct stat place {};
      if (::stat(folder.c_str(), &place) != 0 || !S_ISDIR(place.st_mode))
        VOLA_THROW(IoError(path_ + ": cannot create it: the folder " + folder + " does not exist"));
      VOLA_THROW(IoError(path_ + ": cannot create it (nor a temporary beside it in " + folder +
                         "): " + std::strerror(e)));
    }
  }
  // A replaced file keeps its permissions (the temporary has the umask's).
  struct stat old {};
  if (::stat(path_.c_str(), &old) == 0 && S_ISREG(old.st_mode)) ::fchmod(fd, old.st_mode & 07777);
  file_ = ::fdopen(fd, "wb");
  if (!file_) {
    const int e = errno;
    ::close(fd);
    discard();
    VOLA_THROW(IoError(path_ + ": cannot open " + temporary_ + ": " + std::strerror(e)));
  }
  // Writers emit many small records: a large buffer keeps the system calls few.
  std::setvbuf(file_, nullptr, _IOFBF, std::size_t{1} << 20);
}

OutputFile::~OutputFile() { discard(); }

void OutputFile::discard() noexcept {
  if (file_) std::fclose(file_);
  file_ = nullptr;
  if (!temporary_.empty() && !unnamed_) ::unlink(temporary_.c_str());
  unnamed_ = false;
  release_slot(slot_);
  slot_ = -1;
  temporary_.clear();
}

// The unnamed file, whole and synced, gets a name of its own beside the final one (rename()
// then replaces that atomically; linkat() cannot replace). The name lives for the instant
// between the two calls, and is in the table for the signal handlers meanwhile.
int OutputFile::give_a_name() noexcept {
  const std::string name = next_temporary_name(path_);
  slot_ = claim_slot(name);
  if (::linkat(AT_FDCWD, temporary_.c_str(), AT_FDCWD, name.c_str(), AT_SYMLINK_FOLLOW) != 0 &&
      ::linkat(::fileno(file_), "", AT_FDCWD, name.c_str(), AT_EMPTY_PATH) != 0) {
    const int e = errno;
    release_slot(slot_);
    slot_ = -1;
    return e;
  }
  unnamed_ = false;
  temporary_ = name;
  return 0;
}

int OutputFile::descriptor() const noexcept { return file_ ? ::fileno(file_) : -1; }

void OutputFile::write(const void* data, std::size_t size) {
  if (!file_) VOLA_THROW(IoError(path_ + ": write after a failed write or commit"));
  if (size != 0 && std::fwrite(data, 1, size, file_) != size) {
    const int e = errno;
    discard();
    VOLA_THROW(IoError(path_ + ": write failed: " + std::strerror(e)));
  }
}

void OutputFile::commit() {
  int e = 0;
  if (!file_) e = EBADF;
  else if (std::fflush(file_) != 0 || std::ferror(file_)) e = errno ? errno : EIO;
  else if (::fsync(::fileno(file_)) != 0) e = errno;
  else if (unnamed_) e = give_a_name();
  if (file_ && std::fclose(file_) != 0 && e == 0) e = errno;
  file_ = nullptr;
  if (e != 0) {
    discard();
    VOLA_THROW(IoError(path_ + ": write failed: " + std::strerror(e)));
  }
  if (std::rename(temporary_.c_str(), path_.c_str()) != 0) {
    e = errno;
    discard();
    VOLA_THROW(IoError(path_ + ": cannot replace it with the file written: " + std::strerror(e)));
  }
  release_slot(slot_);
  slot_ = -1;
  temporary_.clear();
  sync_directory(path_);
}

VOLA_INLINE_NAMESPACE_END
}  // namespace vola
