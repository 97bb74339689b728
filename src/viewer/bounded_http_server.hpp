// httplib's server with its connection handling replaced: httplib parses requests and
// routes them; this class decides how long a connection may stay, how many bytes and how
// much time each request may take (request_stream.hpp), and how many connections may
// wait (connection_queue.hpp). Everything that accepts a connection, the socket loop and
// Server::respond alike, goes through serve().
#pragma once

#include <httplib.h>

#include "transport.hpp"
#include "vola/viewer/server.hpp"

namespace vola::viewer {

class BoundedHttpServer final : public httplib::Server {
 public:
  explicit BoundedHttpServer(const ServerLimits& limits);

  // Serves the requests of one connection until it closes, fails, is refused, answers an
  // error, or reaches a limit. Never throws.
  void serve(Transport& transport) noexcept;

 private:
  bool process_and_close_socket(socket_t sock) override;
  static void linger(Transport& transport) noexcept;

  const ServerLimits& limits_;
};

}  // namespace vola::viewer
