// One connection as cpp-httplib's parser sees it, with the limits httplib lacks: its own
// parser keeps reading a header line until a newline, however long, reads any number of
// header lines, and waits on each read afresh, so a client could make it hold memory
// and a thread without end. This stream counts every byte it hands over (the head up to
// its blank line, then the body) and times the whole request; past a limit it hands over
// no more and records a refusal (408, 413 or 431), which the connection loop answers in
// place of whatever the parser makes of the cut request.
#pragma once

#include <httplib.h>

#include <array>
#include <cstddef>
#include <string>

#include "transport.hpp"
#include "vola/viewer/server.hpp"

namespace vola::viewer {

class RequestStream final : public httplib::Stream {
 public:
  RequestStream(Transport& transport, const ServerLimits& limits) : transport_(transport), limits_(limits) {}

  // Starts counting and timing a new request on the connection (bytes already buffered
  // belong to it: pipelining).
  void begin_request();
  bool has_buffered() const noexcept { return begin_ < end_; }
  bool at_end() const noexcept { return at_end_; }
  // 0, or the status the request is refused with (its answer not yet sent).
  int refusal() const noexcept { return refusal_; }
  // The status line's code of the answer written for this request (0 before one).
  int answered_status() const noexcept { return answered_status_; }
  bool failed() const noexcept { return failed_; }
  // Sends the refusal's answer (with Connection: close).
  void send_refusal();

  bool is_readable() const override;
  bool is_writable() const override { return !failed_; }
  ssize_t read(char* ptr, std::size_t size) override;
  ssize_t write(const char* ptr, std::size_t size) override;
  void get_remote_ip_and_port(std::string& ip, int& port) const override { transport_.remote_address(ip, port); }
  void get_local_ip_and_port(std::string& ip, int& port) const override { transport_.local_address(ip, port); }
  int socket() const override { return transport_.socket(); }

 private:
  bool refill();
  // Hands over up to `size` buffered bytes within the head and body limits.
  std::size_t take(char* ptr, std::size_t size);
  void refuse(int status);
  Clock::time_point receive_deadline() const noexcept { return started_ + limits_.receive_timeout; }

  Transport& transport_;
  const ServerLimits& limits_;
  std::array<char, 4096> buffer_{};
  std::size_t begin_ = 0, end_ = 0;
  bool at_end_ = false;
  bool failed_ = false;
  Clock::time_point started_{};
  Clock::time_point send_deadline_{};
  bool in_head_ = true;
  std::size_t line_bytes_ = 0;  // bytes of the current head line before its '\n'
  char previous_ = '\0';
  std::size_t head_bytes_ = 0, body_bytes_ = 0;
  int refusal_ = 0;
  int answered_status_ = 0;
  std::string status_line_;  // the first bytes written, until the status code is known
};

}  // namespace vola::viewer
