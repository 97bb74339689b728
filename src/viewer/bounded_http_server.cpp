#include "bounded_http_server.hpp"

#include <sys/socket.h>
#include <unistd.h>

#include "connection_queue.hpp"
#include "request_stream.hpp"

namespace vola::viewer {

BoundedHttpServer::BoundedHttpServer(const ServerLimits& limits) : limits_(limits) {
  new_task_queue = [this] { return new ConnectionQueue(limits_.workers, limits_.max_waiting_connections); };
  // httplib refuses a declared Content-Length over this with 413 before reading it.
  set_payload_max_length(limits_.max_body_bytes);
  // httplib's default sets SO_REUSEPORT, with which a second viewer binds a port already
  // in use and the kernel splits the requests between the two. SO_REUSEADDR only: a
  // restarted viewer still rebinds a port whose old connections linger in TIME_WAIT.
  set_socket_options([](socket_t sock) {
    int yes = 1;
    ::setsockopt(sock, SOL_SOCKET, SO_REUSEADDR, &yes, sizeof yes);
  });
}

void BoundedHttpServer::serve(Transport& transport) noexcept {
  try {
    RequestStream stream(transport, limits_);
    for (unsigned i = 0; i < limits_.max_requests_per_connection; ++i) {
      if (!stream.has_buffered() && !transport.wait_readable(Clock::now() + limits_.keep_alive_timeout)) return;
      stream.begin_request();
      bool closed = false;
      const bool last = i + 1 == limits_.max_requests_per_connection;
      const bool answered = process_request(stream, last, closed, {});
      if (stream.refusal()) {
        stream.send_refusal();
        return;
      }
      // After an error the rest of the bytes cannot be trusted to start a request (an
      // unread body, a cut head): close rather than parse them.
      if (!answered || closed || stream.failed() || stream.at_end() || stream.answered_status() >= 400) return;
    }
  } catch (...) {
    // Out of memory while parsing: drop this connection, keep the server.
  }
}

// Closing a socket with unread bytes makes the kernel reset the connection, and a client
// may then lose the answer it has not read yet (a 413 while it still sends its body). So
// the server first says it is done (FIN), then reads and drops what comes for a moment.
void BoundedHttpServer::linger(Transport& transport) noexcept {
  ::shutdown(transport.socket(), SHUT_WR);
  const auto deadline = Clock::now() + std::chrono::milliseconds(500);
  char sink[4096];
  for (std::size_t dropped = 0; dropped < (std::size_t{1} << 20);) {
    const long n = transport.receive(sink, sizeof sink, deadline);
    if (n <= 0) return;
    dropped += static_cast<std::size_t>(n);
  }
}

bool BoundedHttpServer::process_and_close_socket(socket_t sock) {
  if (ConnectionQueue::shedding()) {
    static constexpr char kBusy[] =
        "HTTP/1.1 503 Service Unavailable\r\nContent-Length: 0\r\nConnection: close\r\nRetry-After: 1\r\n\r\n";
    // On the accepting thread: never block it.
    [[maybe_unused]] const auto sent = ::send(sock, kBusy, sizeof kBusy - 1, MSG_NOSIGNAL | MSG_DONTWAIT);
  } else {
    SocketTransport transport(sock);
    serve(transport);
    linger(transport);
  }
  ::shutdown(sock, SHUT_RDWR);
  ::close(sock);
  return true;
}

}  // namespace vola::viewer
