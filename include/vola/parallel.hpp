// The library's one parallel loop. Every parallel stage (ray casting, rendering, SLAM's
// filters and fusion, the auralisation's binning and convolution, tiling and overviews)
// runs its work through parallel_for, so that they all behave alike:
//
//  - an exception thrown by the body on any thread reaches the caller of parallel_for,
//    unchanged (the same type and message: a vola::Error stays that vola::Error);
//  - once a body has thrown, no thread starts another chunk (the chunks already running
//    finish), every thread is done with the call, and only then the first exception is rethrown;
//  - how many threads is one setting, set_thread_count(), unless a call asks for a count.
//
// Chunks are handed out in order from a shared counter (dynamic scheduling); the calling
// thread works too. Which chunk runs on which thread varies from run to run, so a stage
// that wants the same result whatever the threads writes its results per index or per
// chunk and combines per-chunk results in chunk order.
//
// Worker threads are kept between calls (asleep in between); a call that finds them in
// use (a parallel_for inside a body, or one on another thread) starts and joins threads
// of its own. Chunks should still be coarse (a wake-up costs microseconds). The library's
// own implementation is src/parallel (the static library vola_parallel; the core library
// has no threads).
#pragma once

#include <cstddef>
#include <functional>

#include "vola/version.hpp"

namespace vola {
VOLA_INLINE_NAMESPACE_BEGIN

// The thread count every parallel stage uses when its caller asks for 0 threads (the
// default of every `threads` option). 0 = std::thread::hardware_concurrency() (the
// default). Safe to call from any thread; a stage already running keeps its count.
void set_thread_count(unsigned threads) noexcept;
// The setting resolved: at least 1.
unsigned thread_count() noexcept;
// `requested` if it is not 0, else thread_count().
unsigned resolve_thread_count(unsigned requested) noexcept;

struct ParallelOptions {
  unsigned threads = 0;    // at most this many threads, the caller's included (0: thread_count())
  std::size_t grain = 1;   // with chunks = 0: chunks of `grain` indices, [c * grain, (c + 1) * grain)
  std::size_t chunks = 0;  // if not 0: exactly this many chunks, [count * c / chunks, count * (c + 1) / chunks)
                           // (empty ones included, e.g. one partial sum per chunk); at most 2^32
  const char* name = "";   // the stage, e.g. "raycast.cast" (seen only by the test hook below)
};

// What one call of the body gets.
struct Chunk {
  std::size_t index = 0;           // 0 .. chunks - 1
  std::size_t begin = 0, end = 0;  // the indices [begin, end) of [0, count)
  unsigned worker = 0;             // 0 .. threads - 1, 0 = the calling thread; a worker runs
                                   // one chunk at a time (index per-worker scratch with it)
};

// Calls body once for every chunk of [0, count), on up to options.threads threads; returns
// when all have run, or rethrows the first exception a body threw (see above). With one
// thread or one chunk it runs on the calling thread alone.
void parallel_for(std::size_t count, const std::function<void(const Chunk&)>& body,
                  const ParallelOptions& options = {});
// The same for bodies that only need the range.
void parallel_for(std::size_t count, const std::function<void(std::size_t begin, std::size_t end)>& body,
                  const ParallelOptions& options = {});

namespace detail {
// For tests only: called on the chunk's thread right before every body, with the stage's
// name. A hook that throws is treated as the body throwing, which lets a test make a
// worker of any stage fail. nullptr (the default) removes it.
using ParallelHook = void (*)(const char* name, const Chunk& chunk);
void set_parallel_hook(ParallelHook hook) noexcept;
}  // namespace detail

VOLA_INLINE_NAMESPACE_END
}  // namespace vola
