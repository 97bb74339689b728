// Makes a worker thread of one parallel stage throw, through vola::parallel_for's test
// hook (vola::detail::set_parallel_hook), for stages whose bodies cannot be made to fail
// from outside. The fault is thrown on a worker other than the calling thread: the
// calling thread's first chunk of the stage waits (at most 10 s) until a worker has
// thrown, so the stage must run with 2 or more threads and 2 or more chunks.
#pragma once

#include <gtest/gtest.h>

#include <atomic>
#include <chrono>
#include <string>
#include <thread>
#include <typeinfo>

#include "vola/error.hpp"
#include "vola/parallel.hpp"

namespace vola_test {

class WorkerFault {
 public:
  explicit WorkerFault(std::string stage) {
    state().stage = std::move(stage);
    state().chunks = 0;
    state().thrown = false;
    state().waited = false;
    vola::detail::set_parallel_hook(&hook);
  }
  ~WorkerFault() { vola::detail::set_parallel_hook(nullptr); }
  WorkerFault(const WorkerFault&) = delete;
  WorkerFault& operator=(const WorkerFault&) = delete;

  static std::string message(const std::string& stage) { return "injected fault in a worker of " + stage; }
  bool thrown() const { return state().thrown; }         // a worker thread threw
  std::size_t chunks() const { return state().chunks; }  // chunks of the stage that started

 private:
  struct State {
    std::string stage;
    std::atomic<std::size_t> chunks{0};
    std::atomic<bool> thrown{false}, waited{false};
  };
  static State& state() {
    static State s;
    return s;
  }
  static void hook(const char* name, const vola::Chunk& chunk) {
    State& s = state();
    if (s.stage != name) return;
    ++s.chunks;
    if (chunk.worker != 0) {
      if (!s.thrown.exchange(true)) throw vola::Error(message(s.stage));
      return;
    }
    if (s.waited.exchange(true)) return;
    const auto until = std::chrono::steady_clock::now() + std::chrono::seconds(10);
    while (!s.thrown && std::chrono::steady_clock::now() < until)
      std::this_thread::sleep_for(std::chrono::milliseconds(1));
  }
};

// Runs `run` with a fault in a worker of `stage` and expects the caller to get exactly
// that vola::Error (the type vola::Error itself, the same message).
template <class F>
void expect_worker_error_reaches_caller(const std::string& stage, F&& run) {
  SCOPED_TRACE("stage " + stage);
  WorkerFault fault(stage);
  try {
    run();
    ADD_FAILURE() << "no exception reached the caller";
  } catch (const vola::Error& e) {
    EXPECT_EQ(std::string(e.what()), WorkerFault::message(stage));
    EXPECT_TRUE(typeid(e) == typeid(vola::Error)) << typeid(e).name();
  } catch (const std::exception& e) {
    ADD_FAILURE() << "not a vola::Error: " << typeid(e).name() << ": " << e.what();
  }
  EXPECT_TRUE(fault.thrown()) << "no worker thread ran a chunk of the stage (" << fault.chunks() << " chunks)";
}

}  // namespace vola_test
