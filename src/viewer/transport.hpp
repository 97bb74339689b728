// The bytes of one client connection, with deadlines: a socket, or memory (the fuzzer and
// Server::respond). The request stream (request_stream.hpp) reads and writes through it,
// so one parser with one set of limits serves both.
#pragma once

#include <chrono>
#include <cstddef>
#include <string>
#include <string_view>

namespace vola::viewer {

using Clock = std::chrono::steady_clock;

class Transport {
 public:
  virtual ~Transport() = default;
  // Up to n bytes into p: the count, 0 at the end of the stream, -1 on an error or when
  // `deadline` passes before any byte arrives (timed_out() then says which).
  virtual long receive(char* p, std::size_t n, Clock::time_point deadline) = 0;
  // All n bytes, or false on an error or when `deadline` passes first.
  virtual bool send(const char* p, std::size_t n, Clock::time_point deadline) = 0;
  // True when a byte (or the end of the stream) can be received before `deadline`.
  virtual bool wait_readable(Clock::time_point deadline) = 0;
  virtual bool timed_out() const noexcept = 0;
  virtual void remote_address(std::string& ip, int& port) const = 0;
  virtual void local_address(std::string& ip, int& port) const = 0;
  virtual int socket() const noexcept { return -1; }
};

// An accepted socket; does not close it (the server does). Writes never raise SIGPIPE.
class SocketTransport final : public Transport {
 public:
  explicit SocketTransport(int fd) : fd_(fd) {}
  long receive(char* p, std::size_t n, Clock::time_point deadline) override;
  bool send(const char* p, std::size_t n, Clock::time_point deadline) override;
  bool wait_readable(Clock::time_point deadline) override;
  bool timed_out() const noexcept override { return timed_out_; }
  void remote_address(std::string& ip, int& port) const override;
  void local_address(std::string& ip, int& port) const override;
  int socket() const noexcept override { return fd_; }

 private:
  // poll() for `events` until `deadline`; sets timed_out_ when it passes.
  bool wait(short events, Clock::time_point deadline);
  int fd_;
  bool timed_out_ = false;
};

// A client that sent `input` and then closed its side; what the server sends collects in
// output(). Never times out.
class MemoryTransport final : public Transport {
 public:
  explicit MemoryTransport(std::string_view input) : input_(input) {}
  long receive(char* p, std::size_t n, Clock::time_point deadline) override;
  bool send(const char* p, std::size_t n, Clock::time_point deadline) override;
  bool wait_readable(Clock::time_point) override { return read_ < input_.size(); }
  bool timed_out() const noexcept override { return false; }
  void remote_address(std::string& ip, int& port) const override;
  void local_address(std::string& ip, int& port) const override;
  std::string& output() noexcept { return output_; }

 private:
  std::string_view input_;
  std::size_t read_ = 0;
  std::string output_;
};

}  // namespace vola::viewer
