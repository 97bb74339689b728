// A raw HTTP client for the viewer's server tests: bytes out exactly as given (no
// library fixing up a hostile request), bytes back until the server closes.
#pragma once

#include <arpa/inet.h>
#include <netinet/in.h>
#include <poll.h>
#include <sys/socket.h>
#include <unistd.h>

#include <chrono>
#include <cstdlib>
#include <string>
#include <string_view>

namespace vola_test {

// A connected socket to 127.0.0.1:port, closed on destruction.
class RawConnection {
 public:
  explicit RawConnection(int port) : fd_(::socket(AF_INET, SOCK_STREAM, 0)) {
    sockaddr_in a{};
    a.sin_family = AF_INET;
    a.sin_port = htons(static_cast<std::uint16_t>(port));
    a.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
    connected_ = fd_ >= 0 && ::connect(fd_, reinterpret_cast<sockaddr*>(&a), sizeof a) == 0;
  }
  ~RawConnection() {
    if (fd_ >= 0) ::close(fd_);
  }
  RawConnection(const RawConnection&) = delete;
  RawConnection& operator=(const RawConnection&) = delete;

  bool connected() const noexcept { return connected_; }
  // Sends what it can (the server may close first: no SIGPIPE, no failure).
  void send(std::string_view bytes) {
    while (!bytes.empty()) {
      const ssize_t n = ::send(fd_, bytes.data(), bytes.size(), MSG_NOSIGNAL);
      if (n <= 0) return;
      bytes.remove_prefix(static_cast<std::size_t>(n));
    }
  }
  void close_sending() { ::shutdown(fd_, SHUT_WR); }
  // Everything the server sends until it closes, or until `timeout` passes (closed() says which).
  std::string receive_all(std::chrono::milliseconds timeout = std::chrono::milliseconds(5000)) {
    std::string out;
    const auto deadline = std::chrono::steady_clock::now() + timeout;
    for (;;) {
      const auto left =
          std::chrono::duration_cast<std::chrono::milliseconds>(deadline - std::chrono::steady_clock::now());
      pollfd p{fd_, POLLIN, 0};
      if (left.count() <= 0 || ::poll(&p, 1, static_cast<int>(left.count())) <= 0) return out;
      char buffer[65536];
      const ssize_t n = ::recv(fd_, buffer, sizeof buffer, 0);
      if (n <= 0) {
        closed_ = true;
        return out;
      }
      out.append(buffer, static_cast<std::size_t>(n));
    }
  }
  bool closed() const noexcept { return closed_; }

 private:
  int fd_;
  bool connected_ = false;
  bool closed_ = false;
};

// Sends `request`, closes the sending side and returns the whole answer.
inline std::string round_trip(int port, std::string_view request) {
  RawConnection c(port);
  c.send(request);
  c.close_sending();
  return c.receive_all();
}

// The status code of the first answer in `bytes`, 0 when it does not start with one.
inline int status_of(std::string_view bytes) {
  if (bytes.size() < 12 || bytes.substr(0, 9) != "HTTP/1.1 ") return 0;
  return std::atoi(std::string(bytes.substr(9, 3)).c_str());
}

inline std::string body_of(const std::string& bytes) {
  const auto at = bytes.find("\r\n\r\n");
  return at == std::string::npos ? std::string() : bytes.substr(at + 4);
}

}  // namespace vola_test
