#include "request_stream.hpp"

#include <algorithm>
#include <cstdlib>
#include <cstring>
#include <nlohmann/json.hpp>

namespace vola::viewer {

namespace {

const char* reason_of(int status) {
  switch (status) {
    case 408:
      return "Request Timeout";
    case 413:
      return "Payload Too Large";
    case 431:
      return "Request Header Fields Too Large";
    default:
      return "Bad Request";
  }
}

std::string cause_of(int status, const ServerLimits& limits) {
  switch (status) {
    case 408:
      return "the request did not arrive within " + std::to_string(limits.receive_timeout.count()) + " ms";
    case 413:
      return "the request body is over " + std::to_string(limits.max_body_bytes) + " bytes";
    case 431:
      return "the request line and headers are over " + std::to_string(limits.max_head_bytes) + " bytes";
    default:
      return "bad request";
  }
}

}  // namespace

void RequestStream::begin_request() {
  started_ = Clock::now();
  send_deadline_ = {};
  in_head_ = true;
  line_bytes_ = 0;
  previous_ = '\0';
  head_bytes_ = body_bytes_ = 0;
  refusal_ = 0;
  answered_status_ = 0;
  status_line_.clear();
}

void RequestStream::refuse(int status) {
  if (!refusal_) refusal_ = status;
}

bool RequestStream::refill() {
  const long n = transport_.receive(buffer_.data(), buffer_.size(), receive_deadline());
  if (n < 0) {
    if (transport_.timed_out()) refuse(408);
    failed_ = true;
    return false;
  }
  if (n == 0) {
    at_end_ = true;
    return false;
  }
  begin_ = 0;
  end_ = static_cast<std::size_t>(n);
  return true;
}

std::size_t RequestStream::take(char* ptr, std::size_t size) {
  std::size_t given = 0;
  // The head byte by byte: it ends with an empty line ("\r\n" alone), as httplib reads it.
  while (in_head_ && given < size && has_buffered()) {
    if (head_bytes_ == limits_.max_head_bytes) {
      refuse(431);
      return given;
    }
    const char c = buffer_[begin_++];
    ptr[given++] = c;
    ++head_bytes_;
    if (c == '\n') {
      if (line_bytes_ == 1 && previous_ == '\r') in_head_ = false;
      line_bytes_ = 0;
    } else {
      ++line_bytes_;
    }
    previous_ = c;
  }
  if (in_head_ || given == size || !has_buffered()) return given;
  const std::size_t room = limits_.max_body_bytes - body_bytes_;
  if (room == 0) {
    refuse(413);
    return given;
  }
  const std::size_t k = std::min({size - given, end_ - begin_, room});
  std::memcpy(ptr + given, buffer_.data() + begin_, k);
  begin_ += k;
  body_bytes_ += k;
  return given + k;
}

bool RequestStream::is_readable() const {
  return has_buffered() || (!refusal_ && !at_end_ && transport_.wait_readable(receive_deadline()));
}

ssize_t RequestStream::read(char* ptr, std::size_t size) {
  if (refusal_ || failed_) return -1;
  if (size == 0) return 0;
  if (!has_buffered() && !refill()) return at_end_ ? 0 : -1;
  const std::size_t given = take(ptr, size);
  if (given == 0 && refusal_) return -1;
  return static_cast<ssize_t>(given);
}

ssize_t RequestStream::write(const char* ptr, std::size_t size) {
  // A refused request's answer is send_refusal()'s: what httplib writes for the cut
  // request (a 400, a 413 after reading part of the body) is dropped.
  if (refusal_) return static_cast<ssize_t>(size);
  if (failed_) return -1;
  if (send_deadline_ == Clock::time_point{}) send_deadline_ = Clock::now() + limits_.send_timeout;
  if (!answered_status_ && status_line_.size() < 12) {
    status_line_.append(ptr, std::min(size, 12 - status_line_.size()));
    // "HTTP/1.1 200": the code is bytes 9..11 (the 100 Continue interim answer is not one).
    if (status_line_.size() == 12) {
      const int code = std::atoi(status_line_.c_str() + 9);
      if (code >= 200)
        answered_status_ = code;
      else
        status_line_.clear();
    }
  }
  if (!transport_.send(ptr, size, send_deadline_)) {
    failed_ = true;
    return -1;
  }
  return static_cast<ssize_t>(size);
}

void RequestStream::send_refusal() {
  const std::string body = nlohmann::json{{"error", cause_of(refusal_, limits_)}}.dump();
  const std::string answer = "HTTP/1.1 " + std::to_string(refusal_) + " " + reason_of(refusal_) +
                             "\r\nContent-Type: application/json\r\nContent-Length: " + std::to_string(body.size()) +
                             "\r\nConnection: close\r\n\r\n" + body;
  answered_status_ = refusal_;
  // Short: a client that does not read it is not waited for long.
  transport_.send(answer.data(), answer.size(), Clock::now() + std::chrono::seconds(1));
}

}  // namespace vola::viewer
