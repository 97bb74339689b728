#include "vola/parallel.hpp"

#include <algorithm>
#include <atomic>
#include <condition_variable>
#include <cstdint>
#include <exception>
#include <mutex>
#include <system_error>
#include <thread>
#include <vector>

#include <unistd.h>

namespace vola {
VOLA_INLINE_NAMESPACE_BEGIN

namespace {

std::atomic<unsigned> g_thread_count{0};
std::atomic<detail::ParallelHook> g_hook{nullptr};

// Where chunk c starts: c * grain, or for a fixed chunk count the even split
// floor(count * c / chunks), computed as q * c + r * c / chunks (count = q * chunks + r)
// so that it cannot overflow for chunks <= 2^32.
struct Split {
  std::size_t count, chunks, grain;
  std::size_t begin(std::size_t c) const noexcept {
    if (grain) return std::min(count, c * grain);  // c * grain < count + grain
    const std::size_t q = count / chunks, r = count % chunks;
    return q * c + r * c / chunks;
  }
};

// Threads kept between calls: starting and joining a thread costs 80-90 us on the
// machines we measured, and a SLAM frame makes about 35 parallel calls (a tenth of a
// 320 x 240 frame's time went to thread starts, and the started thread often found the
// chunks taken). Workers sleep on a condition variable between calls.
//
// One call at a time uses the pool; a call that finds it busy (nested in a body, or
// from another thread) starts its own threads as before, so nothing waits on a worker
// that waits on it. A process forked from one with a pool has no workers: the pool
// remembers its process id and is not used in a child.
class WorkerPool {
 public:
  // Never destroyed: at exit, workers may be asleep in it while other static destructors
  // still run parallel loops; the process ends them.
  static WorkerPool& instance() {
    static WorkerPool* pool = new WorkerPool;
    return *pool;
  }

  // Runs work(1 .. threads - 1) on workers and work(0) on this thread, and returns when
  // all have; false (nothing run) when the pool cannot be used. work must not throw.
  bool run(unsigned threads, const std::function<void(unsigned)>& work) {
    // A flag, not a mutex: a nested call comes from the thread that holds the pool, and
    // try_lock on a mutex the thread owns is undefined.
    bool free = false;
    if (!busy_.compare_exchange_strong(free, true, std::memory_order_acquire)) return false;
    struct Release {
      std::atomic<bool>& flag;
      ~Release() { flag.store(false, std::memory_order_release); }
    } release{busy_};
    if (::getpid() != pid_) return false;
    const unsigned helpers = grow(threads - 1);
    {
      const std::lock_guard lock(mutex_);
      work_ = &work;
      helpers_ = helpers;
      pending_ = helpers;
      ++generation_;
    }
    wake_.notify_all();
    work(0);
    std::unique_lock lock(mutex_);
    done_.wait(lock, [&] { return pending_ == 0; });
    work_ = nullptr;
    return true;
  }

 private:
  WorkerPool() : pid_(::getpid()) {}

  // At least `wanted` workers if the system gives them; how many there are, up to wanted.
  unsigned grow(unsigned wanted) {
    while (workers_.size() < wanted) {
      try {
        workers_.emplace_back(&WorkerPool::serve, this, static_cast<unsigned>(workers_.size() + 1));
      } catch (const std::system_error&) {
        break;  // no more threads to be had: the ones there (and the caller) do the work
      }
    }
    return static_cast<unsigned>(std::min<std::size_t>(wanted, workers_.size()));
  }

  // Worker `index` (1-based) runs its share of every call that wants it.
  void serve(unsigned index) {
    std::uint64_t seen = 0;
    std::unique_lock lock(mutex_);
    for (;;) {
      wake_.wait(lock, [&] { return generation_ != seen; });
      seen = generation_;
      if (index > helpers_) continue;
      const std::function<void(unsigned)>* work = work_;
      lock.unlock();
      (*work)(index);
      lock.lock();
      if (--pending_ == 0) done_.notify_one();
    }
  }

  const pid_t pid_;
  std::atomic<bool> busy_{false};  // set by the call using the pool
  std::mutex mutex_;
  std::condition_variable wake_, done_;
  std::vector<std::thread> workers_;
  const std::function<void(unsigned)>* work_ = nullptr;
  unsigned helpers_ = 0, pending_ = 0;
  std::uint64_t generation_ = 0;
};

void run(std::size_t count, const std::function<void(const Chunk&)>& body, const ParallelOptions& options) {
  const std::size_t grain = std::max<std::size_t>(options.grain, 1);
  const Split split =
      options.chunks ? Split{count, options.chunks, 0} : Split{count, count / grain + (count % grain != 0), grain};
  const std::size_t chunks = split.chunks;
  if (chunks == 0) return;
  const auto threads = static_cast<unsigned>(std::min<std::size_t>(resolve_thread_count(options.threads), chunks));
  const detail::ParallelHook hook = g_hook.load(std::memory_order_acquire);
  const char* name = options.name ? options.name : "";
  auto call = [&](std::size_t c, unsigned worker) {
    const Chunk chunk{c, split.begin(c), split.begin(c + 1), worker};
    if (hook) hook(name, chunk);
    body(chunk);
  };
  if (threads <= 1) {  // on this thread: an exception leaves at once, the later chunks do not run
    for (std::size_t c = 0; c < chunks; ++c) call(c, 0);
    return;
  }
  std::atomic<std::size_t> next{0};
  std::atomic<bool> stop{false};
  std::exception_ptr error;
  std::mutex error_mutex;
  auto work = [&](unsigned worker) noexcept {
    try {
      while (!stop.load(std::memory_order_relaxed)) {
        const std::size_t c = next.fetch_add(1, std::memory_order_relaxed);
        if (c >= chunks) break;
        call(c, worker);
      }
    } catch (...) {
      const std::lock_guard lock(error_mutex);
      if (!error) error = std::current_exception();
      stop.store(true, std::memory_order_relaxed);
    }
  };
  if (!WorkerPool::instance().run(threads, work)) {
    // The pool is busy (a parallel_for inside a body, or one on another thread) or was
    // inherited through fork(): threads of this call's own.
    std::vector<std::thread> pool;
    pool.reserve(threads - 1);
    for (unsigned w = 1; w < threads; ++w) {
      try {
        pool.emplace_back(work, w);
      } catch (const std::system_error&) {
        break;  // no more threads to be had: the ones running (and this one) do the work
      }
    }
    work(0);
    for (std::thread& t : pool) t.join();
  }
  if (error) std::rethrow_exception(error);
}

}  // namespace

void set_thread_count(unsigned threads) noexcept { g_thread_count.store(threads, std::memory_order_relaxed); }

unsigned thread_count() noexcept {
  if (const unsigned n = g_thread_count.load(std::memory_order_relaxed)) return n;
  const unsigned hardware = std::thread::hardware_concurrency();
  return hardware ? hardware : 1;
}

unsigned resolve_thread_count(unsigned requested) noexcept { return requested ? requested : thread_count(); }

void parallel_for(std::size_t count, const std::function<void(const Chunk&)>& body, const ParallelOptions& options) {
  run(count, body, options);
}

void parallel_for(std::size_t count, const std::function<void(std::size_t, std::size_t)>& body,
                  const ParallelOptions& options) {
  const auto range = [&](const Chunk& c) { body(c.begin, c.end); };
  run(count, range, options);
}

namespace detail {
void set_parallel_hook(ParallelHook hook) noexcept { g_hook.store(hook, std::memory_order_release); }
}  // namespace detail

VOLA_INLINE_NAMESPACE_END
}  // namespace vola
