#include "connection_queue.hpp"

#include <algorithm>

namespace vola::viewer {

namespace {
thread_local bool shedding_now = false;
}

ConnectionQueue::ConnectionQueue(unsigned workers, unsigned max_waiting) : max_waiting_(max_waiting) {
  for (unsigned i = 0; i < std::max(workers, 1u); ++i) workers_.emplace_back([this] { work(); });
}

ConnectionQueue::~ConnectionQueue() { shutdown(); }

bool ConnectionQueue::shedding() noexcept { return shedding_now; }

void ConnectionQueue::enqueue(std::function<void()> serve) {
  {
    std::lock_guard lock(mutex_);
    if (waiting_.size() < max_waiting_ && !stopping_) {
      waiting_.push_back(std::move(serve));
      ready_.notify_one();
      return;
    }
  }
  shedding_now = true;
  serve();
  shedding_now = false;
}

void ConnectionQueue::shutdown() {
  {
    std::lock_guard lock(mutex_);
    stopping_ = true;
  }
  ready_.notify_all();
  for (auto& t : workers_)
    if (t.joinable()) t.join();
}

void ConnectionQueue::work() {
  for (;;) {
    std::function<void()> serve;
    {
      std::unique_lock lock(mutex_);
      ready_.wait(lock, [this] { return stopping_ || !waiting_.empty(); });
      if (waiting_.empty()) return;  // stopping, and nothing left to serve
      serve = std::move(waiting_.front());
      waiting_.pop_front();
    }
    serve();
  }
}

}  // namespace vola::viewer
