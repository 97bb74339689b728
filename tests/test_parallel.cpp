// vola::parallel_for, the library's one parallel loop: every index once whatever the
// counts, chunking and threads; a worker's exception reaches the caller unchanged; after
// a throw the other workers stop taking chunks; the thread-count setting is honoured;
// worker threads are kept between calls, and nested, concurrent and forked calls work.
#include <gtest/gtest.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cstring>
#include <memory>
#include <mutex>
#include <set>
#include <thread>
#include <vector>

#include <sys/wait.h>
#include <unistd.h>

#include "parallel_fault.hpp"
#include "vola/error.hpp"
#include "vola/parallel.hpp"

namespace {

using namespace std::chrono_literals;

// Restores the thread-count setting at the end of a test.
struct ThreadCountGuard {
  ~ThreadCountGuard() { vola::set_thread_count(0); }
};

struct Seen {
  std::size_t index, begin, end;
  unsigned worker;
};

// Runs parallel_for and returns every chunk it saw, sorted by index.
std::vector<Seen> chunks_of(std::size_t count, const vola::ParallelOptions& options) {
  std::mutex mutex;
  std::vector<Seen> seen;
  vola::parallel_for(
      count,
      [&](const vola::Chunk& c) {
        const std::lock_guard lock(mutex);
        seen.push_back({c.index, c.begin, c.end, c.worker});
      },
      options);
  std::sort(seen.begin(), seen.end(), [](const Seen& a, const Seen& b) { return a.index < b.index; });
  return seen;
}

// Waits (at most 10 s) until `flag` is set: the calling thread's chunk holds back so
// that a worker thread surely takes one.
void wait_for(const std::atomic<bool>& flag) {
  const auto until = std::chrono::steady_clock::now() + 10s;
  while (!flag && std::chrono::steady_clock::now() < until) std::this_thread::sleep_for(1ms);
}

TEST(ParallelFor, EveryIndexExactlyOnceInChunksOfTheGrain) {
  for (const std::size_t count : {0u, 1u, 2u, 7u, 255u, 256u, 257u, 1000u, 100003u})
    for (const unsigned threads : {1u, 2u, 3u, 8u})
      for (const std::size_t grain : {1u, 7u, 256u}) {
        SCOPED_TRACE(testing::Message() << "count " << count << " threads " << threads << " grain " << grain);
        std::unique_ptr<std::atomic<int>[]> visits(new std::atomic<int>[count]());
        vola::ParallelOptions o;
        o.threads = threads;
        o.grain = grain;
        vola::parallel_for(
            count,
            [&](std::size_t begin, std::size_t end) {
              for (std::size_t i = begin; i < end; ++i) ++visits[i];
            },
            o);
        for (std::size_t i = 0; i < count; ++i) ASSERT_EQ(visits[i], 1) << "index " << i;
        const std::vector<Seen> seen = chunks_of(count, o);
        ASSERT_EQ(seen.size(), (count + grain - 1) / grain);
        for (std::size_t c = 0; c < seen.size(); ++c) {
          EXPECT_EQ(seen[c].index, c);
          EXPECT_EQ(seen[c].begin, c * grain);
          EXPECT_EQ(seen[c].end, std::min(count, (c + 1) * grain));
          EXPECT_LT(seen[c].worker, threads);
        }
      }
}

TEST(ParallelFor, FixedChunkCountsSplitEvenlyAndRunEmptyChunksToo) {
  for (const std::size_t count : {0u, 1u, 5u, 480u, 1000003u})
    for (const std::size_t chunks : {1u, 2u, 3u, 8u, 17u}) {
      SCOPED_TRACE(testing::Message() << "count " << count << " chunks " << chunks);
      vola::ParallelOptions o;
      o.threads = 3;
      o.chunks = chunks;
      const std::vector<Seen> seen = chunks_of(count, o);
      ASSERT_EQ(seen.size(), chunks) << "one call per chunk, empty ones included";
      for (std::size_t c = 0; c < chunks; ++c) {
        EXPECT_EQ(seen[c].index, c);
        EXPECT_EQ(seen[c].begin, count * c / chunks);
        EXPECT_EQ(seen[c].end, count * (c + 1) / chunks);
      }
    }
  // floor(count * c / chunks) without overflow for counts near 2^64.
  const std::size_t huge = ~std::size_t{0} - 5;
  vola::ParallelOptions o;
  o.threads = 2;
  o.chunks = 7;
  const std::vector<Seen> seen = chunks_of(huge, o);
  ASSERT_EQ(seen.size(), 7u);
  EXPECT_EQ(seen.front().begin, 0u);
  EXPECT_EQ(seen.back().end, huge);
  __extension__ using Wide = unsigned __int128;
  for (std::size_t c = 0; c < 7; ++c) {
    EXPECT_EQ(seen[c].begin, static_cast<std::size_t>(Wide{huge} * c / 7));
    if (c > 0) {
      EXPECT_EQ(seen[c].begin, seen[c - 1].end);
    }
  }
}

TEST(ParallelFor, AWorkerRunsOneChunkAtATime) {
  constexpr unsigned kThreads = 4;
  std::atomic<int> busy[kThreads] = {};
  std::atomic<bool> overlap{false}, beyond{false};
  std::mutex mutex;
  std::set<std::thread::id> ids;
  vola::ParallelOptions o;
  o.threads = kThreads;
  vola::parallel_for(
      2000,
      [&](const vola::Chunk& c) {
        if (c.worker >= kThreads) {
          beyond = true;
          return;
        }
        if (busy[c.worker]++ != 0) overlap = true;
        {
          const std::lock_guard lock(mutex);
          ids.insert(std::this_thread::get_id());
        }
        std::this_thread::sleep_for(10us);
        --busy[c.worker];
      },
      o);
  EXPECT_FALSE(beyond);
  EXPECT_FALSE(overlap);
  EXPECT_LE(ids.size(), kThreads);
}

TEST(ParallelFor, AnErrorThrownInAWorkerReachesTheCallerUnchanged) {
  for (const unsigned threads : {2u, 4u}) {
    std::atomic<bool> thrown{false};
    vola::ParallelOptions o;
    o.threads = threads;
    try {
      vola::parallel_for(
          64,
          [&](const vola::Chunk& c) {
            if (c.worker == 0) {
              wait_for(thrown);
              return;
            }
            if (!thrown.exchange(true)) throw vola::FormatError("survey.las", 4096, "point record 12 is truncated");
          },
          o);
      ADD_FAILURE() << "no exception";
    } catch (const vola::FormatError& e) {
      EXPECT_STREQ(e.what(), "survey.las: byte 4096: point record 12 is truncated");
      EXPECT_EQ(e.file(), "survey.las");
      EXPECT_EQ(e.offset(), std::optional<std::uint64_t>(4096));
      EXPECT_EQ(e.cause(), "point record 12 is truncated");
    }
    EXPECT_TRUE(thrown) << "a worker thread threw";
  }
  // The plain vola::Error, through the test hook the stage tests use.
  vola::ParallelOptions o;
  o.threads = 2;
  o.name = "test.stage";
  const auto nothing = [](std::size_t, std::size_t) {};
  vola_test::expect_worker_error_reaches_caller("test.stage", [&] { vola::parallel_for(8, nothing, o); });
}

TEST(ParallelFor, AnErrorOnTheCallingThreadWaitsForTheWorkers) {
  std::atomic<int> running{0};
  std::atomic<bool> started{false};
  vola::ParallelOptions o;
  o.threads = 3;
  EXPECT_THROW(vola::parallel_for(
                   30,
                   [&](const vola::Chunk& c) {
                     if (c.worker == 0) {
                       wait_for(started);  // a worker is inside a chunk
                       throw vola::InvalidArgument("from the caller's own chunk");
                     }
                     ++running;
                     started = true;
                     std::this_thread::sleep_for(20ms);
                     --running;
                   },
                   o),
               vola::InvalidArgument);
  EXPECT_TRUE(started);
  EXPECT_EQ(running, 0) << "every worker was joined before the rethrow";
}

TEST(ParallelFor, AfterAThrowTheOtherWorkersStopTakingChunks) {
  constexpr std::size_t kChunks = 100000;
  std::atomic<std::size_t> ran{0};
  std::atomic<bool> thrown{false};
  vola::ParallelOptions o;
  o.threads = 4;
  EXPECT_THROW(vola::parallel_for(
                   kChunks,
                   [&](const vola::Chunk& c) {
                     if (c.worker != 0 && !thrown.exchange(true)) throw vola::Error("stop");
                     ++ran;
                     std::this_thread::sleep_for(100us);
                   },
                   o),
               vola::Error);
  EXPECT_TRUE(thrown);
  // Without cancellation all 100000 run (10 s of sleeping over 4 threads); with it, only
  // the chunks started before the throw.
  EXPECT_LT(ran.load(), kChunks / 10) << ran.load() << " chunks ran";

  // On one thread the chunks after the throwing one do not run at all.
  std::vector<std::size_t> order;
  o.threads = 1;
  EXPECT_THROW(vola::parallel_for(
                   100,
                   [&](const vola::Chunk& c) {
                     order.push_back(c.index);
                     if (c.index == 5) throw vola::Error("stop");
                   },
                   o),
               vola::Error);
  EXPECT_EQ(order, (std::vector<std::size_t>{0, 1, 2, 3, 4, 5}));
}

TEST(ParallelFor, TheThreadCountIsOneSetting) {
  const ThreadCountGuard restore;
  const unsigned hardware = std::max(1u, std::thread::hardware_concurrency());
  vola::set_thread_count(0);
  EXPECT_EQ(vola::thread_count(), hardware);
  EXPECT_EQ(vola::resolve_thread_count(0), hardware);
  EXPECT_EQ(vola::resolve_thread_count(5), 5u);

  // How many threads ran `chunks` chunks; each chunk waits (at most 10 s) until
  // `expected` chunks have started, which proves that many ran at once.
  const auto threads_used = [](unsigned threads, unsigned chunks, unsigned expected) {
    std::atomic<unsigned> arrived{0};
    std::mutex mutex;
    std::set<std::thread::id> ids;
    unsigned max_worker = 0;
    vola::ParallelOptions o;
    o.threads = threads;
    o.chunks = chunks;
    vola::parallel_for(
        chunks,
        [&](const vola::Chunk& c) {
          {
            const std::lock_guard lock(mutex);
            ids.insert(std::this_thread::get_id());
            max_worker = std::max(max_worker, c.worker);
          }
          ++arrived;
          const auto until = std::chrono::steady_clock::now() + 10s;
          while (arrived < expected && std::chrono::steady_clock::now() < until) std::this_thread::sleep_for(1ms);
        },
        o);
    EXPECT_LT(max_worker, expected) << "worker indices stay below the thread count";
    return ids.size();
  };
  vola::set_thread_count(3);
  EXPECT_EQ(vola::thread_count(), 3u);
  EXPECT_EQ(threads_used(0, 6, 3), 3u);  // 0: the setting
  EXPECT_EQ(threads_used(2, 6, 2), 2u);  // a call's own count wins
  vola::set_thread_count(1);
  EXPECT_EQ(threads_used(0, 6, 1), 1u);  // one thread: the calling one
  std::thread::id caller = std::this_thread::get_id(), ran_on;
  vola::parallel_for(10, [&](std::size_t, std::size_t) { ran_on = std::this_thread::get_id(); });
  EXPECT_EQ(ran_on, caller);
}

TEST(ParallelFor, TheTestHookSeesEveryChunkWithItsStage) {
  static std::atomic<std::size_t> calls{0};
  static std::atomic<bool> wrong_name{false};
  vola::detail::set_parallel_hook([](const char* name, const vola::Chunk&) {
    if (std::strcmp(name, "test.hooked") != 0) wrong_name = true;
    ++calls;
  });
  vola::ParallelOptions o;
  o.threads = 2;
  o.grain = 10;
  o.name = "test.hooked";
  const auto nothing = [](std::size_t, std::size_t) {};
  vola::parallel_for(95, nothing, o);
  vola::detail::set_parallel_hook(nullptr);
  vola::parallel_for(95, nothing, o);
  EXPECT_EQ(calls, 10u);
  EXPECT_FALSE(wrong_name);
}

// The worker threads are kept: two calls in a row see the same worker thread.
TEST(ParallelFor, WorkerThreadsAreKeptBetweenCalls) {
  const auto worker_thread = [] {
    std::atomic<bool> worker_ran{false};
    std::thread::id id;
    vola::ParallelOptions o;
    o.threads = 2;
    o.grain = 1;
    vola::parallel_for(
        8,
        [&](const vola::Chunk& c) {
          if (c.worker == 0) {
            wait_for(worker_ran);
            return;
          }
          id = std::this_thread::get_id();
          worker_ran = true;
        },
        o);
    return id;
  };
  const std::thread::id first = worker_thread();
  EXPECT_NE(first, std::thread::id());
  EXPECT_NE(first, std::this_thread::get_id());
  EXPECT_EQ(worker_thread(), first);
}

// A parallel_for inside a body (the pool is in use) and one on another thread at the
// same time both run every index once, with threads of their own.
TEST(ParallelFor, NestedAndConcurrentCallsRunEveryIndexOnce) {
  vola::ParallelOptions o;
  o.threads = 2;
  o.grain = 3;
  std::vector<std::atomic<int>> hits(40 * 50);
  vola::parallel_for(
      40,
      [&](const vola::Chunk& outer) {
        for (std::size_t i = outer.begin; i < outer.end; ++i)
          vola::parallel_for(
              50,
              [&](std::size_t b, std::size_t e) {
                for (std::size_t j = b; j < e; ++j) ++hits[i * 50 + j];
              },
              o);
      },
      o);
  for (const auto& h : hits) EXPECT_EQ(h.load(), 1);
  std::vector<std::atomic<int>> a(5000), b(5000);
  const auto count_into = [&](std::vector<std::atomic<int>>& into) {
    for (int round = 0; round < 20; ++round)
      vola::parallel_for(
          into.size(),
          [&](std::size_t begin, std::size_t end) {
            for (std::size_t i = begin; i < end; ++i) ++into[i];
          },
          o);
  };
  std::thread other([&] { count_into(b); });
  count_into(a);
  other.join();
  for (std::size_t i = 0; i < a.size(); ++i) {
    EXPECT_EQ(a[i].load(), 20);
    EXPECT_EQ(b[i].load(), 20);
  }
}

// A child forked after the workers started has none of them: its calls must not wait
// for threads that are not there.
TEST(ParallelFor, AForkedChildRunsItsOwnLoops) {
  vola::ParallelOptions o;
  o.threads = 2;
  vola::parallel_for(10, [](std::size_t, std::size_t) {}, o);  // the workers exist
  const pid_t child = ::fork();
  ASSERT_GE(child, 0);
  if (child == 0) {
    std::atomic<std::size_t> sum{0};
    vola::parallel_for(
        1000,
        [&](std::size_t begin, std::size_t end) {
          for (std::size_t i = begin; i < end; ++i) sum += i;
        },
        o);
    ::_exit(sum == 999 * 1000 / 2 ? 0 : 1);
  }
  int status = 0;
  ASSERT_EQ(::waitpid(child, &status, 0), child);
  ASSERT_TRUE(WIFEXITED(status));
  EXPECT_EQ(WEXITSTATUS(status), 0);
}

}  // namespace
