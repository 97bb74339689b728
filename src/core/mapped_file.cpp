#include "mapped_file.hpp"

#include <fcntl.h>
#include <sys/mman.h>
#include <sys/stat.h>
#include <unistd.h>

#include <atomic>
#include <cerrno>
#include <csignal>
#include <cstring>
#include <ctime>
#include <mutex>

#include "vola/error.hpp"

namespace vola {
VOLA_INLINE_NAMESPACE_BEGIN
namespace detail {

namespace {

// The table of live mappings. The SIGBUS handler reads it at any instant on any
// thread, so it is fixed-size and lock-free: a slot's range is written while its
// state is `filling` and read by the handler only once it is `live` (release/acquire).
// 1024 slots hold a tile set's open tiles; beyond them files are read into memory.
enum SlotState : int { kFree = 0, kFilling = 1, kLive = 2, kLost = 3 };
constexpr int kSlots = 1024;
struct Slot {
  std::atomic<int> state{kFree};
  std::atomic<std::uintptr_t> begin{0};
  std::atomic<std::uintptr_t> end{0};
  std::atomic<const MappedFile*> owner{nullptr};
  std::atomic<std::int64_t> next_look_ns{0};  // rewritten_at: when to stat the file again
};
Slot slots[kSlots];
struct sigaction previous_bus_action {};
std::once_flag bus_handler_once;
// How many mappings were ever lost: lets lost_at() answer "none" with one load, so that
// a check per ray or per tile costs nothing.
std::atomic<int> lost_mappings{0};

// Replaces slot s's mapping with zero pages and marks it lost (the SIGBUS handler does
// the same from inside a fault: only atomics and mmap). False when the pages could not be replaced.
bool lose(Slot& s) noexcept {
  const std::uintptr_t begin = s.begin.load(std::memory_order_relaxed);
  const std::uintptr_t end = s.end.load(std::memory_order_relaxed);
  void* zeros =
      ::mmap(reinterpret_cast<void*>(begin), end - begin, PROT_READ, MAP_PRIVATE | MAP_ANONYMOUS | MAP_FIXED, -1, 0);
  if (zeros == MAP_FAILED) return false;
  int live = kLive;
  if (s.state.compare_exchange_strong(live, kLost, std::memory_order_release))
    lost_mappings.fetch_add(1, std::memory_order_release);
  return true;
}

std::int64_t nanoseconds(const struct timespec& t) noexcept {
  return static_cast<std::int64_t>(t.tv_sec) * 1000000000 + t.tv_nsec;
}

// Runs on the faulting thread, inside the fault. Only atomics and mmap(): mmap is not
// on POSIX's list of async-signal-safe functions, but it takes no lock of the C library
// (it is one system call), so it cannot deadlock with the interrupted code; the
// interrupted code is a plain load from the mapping.
void on_bus_error(int signal, siginfo_t* info, void* context) {
  const auto address = reinterpret_cast<std::uintptr_t>(info->si_addr);
  // si_code <= 0: sent by kill() or raise(), not a fault; si_addr means nothing then.
  for (Slot& s : slots) {
    if (info->si_code <= 0) break;
    const int state = s.state.load(std::memory_order_acquire);
    if (state != kLive && state != kLost) continue;
    const std::uintptr_t begin = s.begin.load(std::memory_order_relaxed);
    const std::uintptr_t end = s.end.load(std::memory_order_relaxed);
    if (address < begin || address >= end) continue;
    if (!lose(s)) break;
    return;  // the faulting load is restarted and reads 0
  }
  // Not one of ours: what would have happened without us.
  const struct sigaction& before = previous_bus_action;
  if ((before.sa_flags & SA_SIGINFO) && before.sa_sigaction) return before.sa_sigaction(signal, info, context);
  if (before.sa_handler != SIG_DFL && before.sa_handler != SIG_IGN) return before.sa_handler(signal);
  struct sigaction fallback {};
  fallback.sa_handler = SIG_DFL;
  sigemptyset(&fallback.sa_mask);
  ::sigaction(signal, &fallback, nullptr);
  ::raise(signal);  // blocked no longer (SA_NODEFER): ends the process as SIGBUS would have
}

void install_bus_handler() noexcept {
  std::call_once(bus_handler_once, [] {
    struct sigaction action {};
    action.sa_sigaction = on_bus_error;
    action.sa_flags = SA_SIGINFO | SA_NODEFER;
    sigemptyset(&action.sa_mask);
    // Read first, install second: the handler may run as soon as it is installed.
    ::sigaction(SIGBUS, nullptr, &previous_bus_action);
    ::sigaction(SIGBUS, &action, nullptr);
  });
}

int claim_slot(const void* data, std::size_t size, const MappedFile* owner) noexcept {
  for (int i = 0; i < kSlots; ++i) {
    int expected = kFree;
    if (!slots[i].state.compare_exchange_strong(expected, kFilling, std::memory_order_acquire)) continue;
    slots[i].begin.store(reinterpret_cast<std::uintptr_t>(data), std::memory_order_relaxed);
    slots[i].end.store(reinterpret_cast<std::uintptr_t>(data) + size, std::memory_order_relaxed);
    slots[i].owner.store(owner, std::memory_order_relaxed);
    slots[i].next_look_ns.store(0, std::memory_order_relaxed);
    slots[i].state.store(kLive, std::memory_order_release);
    return i;
  }
  return -1;
}

int open_regular(const std::string& path, struct stat& st) {
  // O_NONBLOCK: opening a FIFO would wait for a writer; it is refused below instead.
  const int fd = ::open(path.c_str(), O_RDONLY | O_CLOEXEC | O_NONBLOCK);
  if (fd < 0) VOLA_THROW(IoError(path + ": cannot open: " + std::strerror(errno)));
  if (::fstat(fd, &st) != 0) {
    const int e = errno;
    ::close(fd);
    VOLA_THROW(IoError(path + ": cannot stat: " + std::strerror(e)));
  }
  if (!S_ISREG(st.st_mode)) {
    ::close(fd);
    VOLA_THROW(IoError(path + ": not a regular file (a FIFO, device or directory): inputs are files"));
  }
  return fd;
}

// Reads up to `size` bytes; a file cut meanwhile gives fewer, never an error.
void read_into(int fd, const std::string& path, std::vector<std::uint8_t>& out, std::size_t size) {
  out.resize(size);
  std::size_t got = 0;
  while (got < size) {
    const ssize_t n = ::pread(fd, out.data() + got, size - got, static_cast<off_t>(got));
    if (n < 0 && errno == EINTR) continue;
    if (n < 0) {
      const int e = errno;
      ::close(fd);
      VOLA_THROW(IoError(path + ": cannot read: " + std::strerror(e)));
    }
    if (n == 0) break;
    got += static_cast<std::size_t>(n);
  }
  out.resize(got);
}

}  // namespace

std::shared_ptr<const MappedFile> MappedFile::load(const std::string& path) {
  struct stat st {};
  const int fd = open_regular(path, st);
  const auto size = static_cast<std::size_t>(st.st_size);
  std::shared_ptr<MappedFile> file(new MappedFile());
  file->path_ = path;
  read_into(fd, path, file->copy_, size);
  ::close(fd);
  file->data_ = file->copy_.data();
  file->size_ = file->copy_.size();
  return file;
}

std::shared_ptr<const MappedFile> MappedFile::open(const std::string& path) {
  struct stat st {};
  const int fd = open_regular(path, st);
  const auto size = static_cast<std::size_t>(st.st_size);
  std::shared_ptr<MappedFile> file(new MappedFile());
  file->path_ = path;
  file->device_ = static_cast<std::uint64_t>(st.st_dev);
  file->inode_ = static_cast<std::uint64_t>(st.st_ino);
  file->file_size_ = static_cast<std::int64_t>(st.st_size);
  file->modified_ns_ = nanoseconds(st.st_mtim);
  if (size == 0) {
    ::close(fd);
    return file;
  }
  void* p = ::mmap(nullptr, size, PROT_READ, MAP_PRIVATE, fd, 0);
  if (p == MAP_FAILED) {
    const int e = errno;
    ::close(fd);
    VOLA_THROW(IoError(path + ": cannot map: " + std::strerror(e)));
  }
  install_bus_handler();
  file->slot_ = claim_slot(p, size, file.get());
  if (file->slot_ < 0) {  // the table is full: a copy cannot be lost
    ::munmap(p, size);
    read_into(fd, path, file->copy_, size);
    ::close(fd);
    file->data_ = file->copy_.data();
    file->size_ = file->copy_.size();
    return file;
  }
  ::close(fd);
  file->data_ = static_cast<const std::uint8_t*>(p);
  file->size_ = size;
  return file;
}

const MappedFile* MappedFile::lost_at(const void* address) noexcept {
  if (lost_mappings.load(std::memory_order_acquire) == 0) return nullptr;
  const auto a = reinterpret_cast<std::uintptr_t>(address);
  for (const Slot& s : slots) {
    if (s.state.load(std::memory_order_acquire) != kLost) continue;
    if (a >= s.begin.load(std::memory_order_relaxed) && a < s.end.load(std::memory_order_relaxed))
      return s.owner.load(std::memory_order_relaxed);
  }
  return nullptr;
}

const MappedFile* MappedFile::rewritten_at(const void* address, bool at_most_every_millisecond) noexcept {
  const auto a = reinterpret_cast<std::uintptr_t>(address);
  const auto holds = [a](const Slot& s) {
    return s.state.load(std::memory_order_acquire) == kLive && a >= s.begin.load(std::memory_order_relaxed) &&
           a < s.end.load(std::memory_order_relaxed);
  };
  // Looked up by a scan of the table; a thread's next look is mostly at the same mapping.
  thread_local int last = 0;
  int at = holds(slots[last]) ? last : -1;
  for (int i = 0; i < kSlots && at < 0; ++i)
    if (holds(slots[i])) at = i;
  if (at < 0) return nullptr;
  last = at;
  Slot& s = slots[at];
  if (at_most_every_millisecond) {
    struct timespec now {};
    ::clock_gettime(CLOCK_MONOTONIC_COARSE, &now);
    std::int64_t next = s.next_look_ns.load(std::memory_order_relaxed);
    if (nanoseconds(now) < next ||
        !s.next_look_ns.compare_exchange_strong(next, nanoseconds(now) + 1000000, std::memory_order_relaxed))
      return nullptr;  // looked at within the last millisecond, or another thread looks now
  }
  const MappedFile* owner = s.owner.load(std::memory_order_relaxed);
  struct stat st {};
  if (::stat(owner->path_.c_str(), &st) != 0 || static_cast<std::uint64_t>(st.st_dev) != owner->device_ ||
      static_cast<std::uint64_t>(st.st_ino) != owner->inode_)
    return nullptr;  // the path names another file now (renamed over it): this one is whole
  if (static_cast<std::int64_t>(st.st_size) == owner->file_size_ && nanoseconds(st.st_mtim) == owner->modified_ns_)
    return nullptr;
  lose(s);
  return owner;
}

MappedFile::~MappedFile() {
  if (slot_ < 0) return;
  // Out of the table first, so that the handler never replaces pages someone else maps next.
  slots[slot_].state.store(kFilling, std::memory_order_relaxed);
  ::munmap(const_cast<std::uint8_t*>(data_), size_);
  slots[slot_].state.store(kFree, std::memory_order_release);
}

}  // namespace detail
VOLA_INLINE_NAMESPACE_END
}  // namespace vola
