// The viewer's workers: a fixed number of threads serving accepted connections, and a
// bounded queue of connections waiting for one. httplib's own pool queues without
// bound, so a client opening connections faster than they time out would pile up open
// sockets until the process runs out of descriptors. A connection that finds the queue
// full is run at once on the accepting thread with shedding() true, so that the server
// answers it 503 without waiting and closes it.
#pragma once

#include <httplib.h>

#include <condition_variable>
#include <deque>
#include <functional>
#include <mutex>
#include <thread>
#include <vector>

namespace vola::viewer {

class ConnectionQueue final : public httplib::TaskQueue {
 public:
  ConnectionQueue(unsigned workers, unsigned max_waiting);
  ~ConnectionQueue() override;

  void enqueue(std::function<void()> serve) override;
  // Serves what is queued, then joins the workers.
  void shutdown() override;

  // True on a thread running a connection that the queue had no room for.
  static bool shedding() noexcept;

 private:
  void work();

  std::mutex mutex_;
  std::condition_variable ready_;
  std::deque<std::function<void()>> waiting_;
  std::size_t max_waiting_;
  bool stopping_ = false;
  std::vector<std::thread> workers_;
};

}  // namespace vola::viewer
