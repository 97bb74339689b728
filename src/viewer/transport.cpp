#include "transport.hpp"

#include <arpa/inet.h>
#include <netinet/in.h>
#include <poll.h>
#include <sys/socket.h>

#include <algorithm>
#include <cerrno>
#include <cstring>

namespace vola::viewer {

namespace {

void address_of(const sockaddr_storage& a, std::string& ip, int& port) {
  char text[INET6_ADDRSTRLEN] = {};
  if (a.ss_family == AF_INET6) {
    const auto& v6 = reinterpret_cast<const sockaddr_in6&>(a);
    inet_ntop(AF_INET6, &v6.sin6_addr, text, sizeof text);
    port = ntohs(v6.sin6_port);
  } else if (a.ss_family == AF_INET) {
    const auto& v4 = reinterpret_cast<const sockaddr_in&>(a);
    inet_ntop(AF_INET, &v4.sin_addr, text, sizeof text);
    port = ntohs(v4.sin_port);
  } else {
    port = 0;
  }
  ip = text;
}

int milliseconds_until(Clock::time_point deadline) {
  const auto left = std::chrono::duration_cast<std::chrono::milliseconds>(deadline - Clock::now()).count();
  return static_cast<int>(std::clamp<long long>(left, 0, 1'000'000));
}

}  // namespace

bool SocketTransport::wait(short events, Clock::time_point deadline) {
  for (;;) {
    pollfd p{fd_, events, 0};
    const int r = ::poll(&p, 1, milliseconds_until(deadline));
    if (r > 0) return true;
    if (r == 0) {
      timed_out_ = true;
      return false;
    }
    if (errno != EINTR) return false;
  }
}

bool SocketTransport::wait_readable(Clock::time_point deadline) { return wait(POLLIN, deadline); }

long SocketTransport::receive(char* p, std::size_t n, Clock::time_point deadline) {
  for (;;) {
    if (!wait(POLLIN, deadline)) return -1;
    const ssize_t r = ::recv(fd_, p, n, MSG_DONTWAIT);
    if (r >= 0) return static_cast<long>(r);
    if (errno != EINTR && errno != EAGAIN && errno != EWOULDBLOCK) return -1;
  }
}

bool SocketTransport::send(const char* p, std::size_t n, Clock::time_point deadline) {
  while (n > 0) {
    if (!wait(POLLOUT, deadline)) return false;
    // MSG_NOSIGNAL: a client that hangs up mid-answer must not kill the server (SIGPIPE).
    const ssize_t r = ::send(fd_, p, n, MSG_NOSIGNAL | MSG_DONTWAIT);
    if (r < 0) {
      if (errno == EINTR || errno == EAGAIN || errno == EWOULDBLOCK) continue;
      return false;
    }
    p += r;
    n -= static_cast<std::size_t>(r);
  }
  return true;
}

void SocketTransport::remote_address(std::string& ip, int& port) const {
  sockaddr_storage a{};
  socklen_t len = sizeof a;
  if (::getpeername(fd_, reinterpret_cast<sockaddr*>(&a), &len) != 0) a.ss_family = AF_UNSPEC;
  address_of(a, ip, port);
}

void SocketTransport::local_address(std::string& ip, int& port) const {
  sockaddr_storage a{};
  socklen_t len = sizeof a;
  if (::getsockname(fd_, reinterpret_cast<sockaddr*>(&a), &len) != 0) a.ss_family = AF_UNSPEC;
  address_of(a, ip, port);
}

long MemoryTransport::receive(char* p, std::size_t n, Clock::time_point) {
  const std::size_t k = std::min(n, input_.size() - read_);
  std::memcpy(p, input_.data() + read_, k);
  read_ += k;
  return static_cast<long>(k);
}

bool MemoryTransport::send(const char* p, std::size_t n, Clock::time_point) {
  output_.append(p, n);
  return true;
}

void MemoryTransport::remote_address(std::string& ip, int& port) const {
  ip = "127.0.0.1";
  port = 0;
}

void MemoryTransport::local_address(std::string& ip, int& port) const {
  ip = "127.0.0.1";
  port = 0;
}

}  // namespace vola::viewer
