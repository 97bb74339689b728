// The HTTP side of `vola view`: the page (HTML and the three.js bundle, compiled into the
// binary, so it needs no network) and its API.
//
//   GET /                                    the page
//   GET /viewer.js                           the bundled script
//   GET /api/files                           JSON: metadata of every file (ViewedFile::metadata)
//   GET /api/files/F/cells?level=L&first=I&count=N   binary batch of cells (viewed_file.hpp)
//   GET /api/files/F/cell?level=L&x=X&y=Y&z=Z        JSON: one cell (ViewedFile::cell_info)
//   GET /api/files/F/pick?level=L&ox=..&oy=..&oz=..&dx=..&dy=..&dz=..[&tmax=T]
//                                            JSON: the first cell along a ray in cell units
//   GET /api/tilesets                        JSON: every tile set's pieces (ViewedTileSet::metadata)
//   GET /api/tilesets/S/pieces/P/cells?level=L&first=I&count=N   a batch of piece P's cells
// Bad requests get status 400 (404 for an unknown file or path) and {"error": "..."}.
//
// Any web page the user opens can make the browser send requests here, and any local
// process can connect, so the server trusts nothing it is sent (docs/SECURITY.md):
// - it listens on 127.0.0.1 unless told otherwise;
// - it answers only requests whose Host names it (localhost, 127.0.0.1, [::1], the bound
//   address, or a name it was given; with its port): a page that rebinds its own DNS name
//   to 127.0.0.1 gets 403;
// - a request head over max_head_bytes gets 431, a body over max_body_bytes 413, a request
//   not received within receive_timeout 408; a connection over the waiting limit gets 503;
//   an error answer closes its connection;
// - a path or query that is not UTF-8 gets 400, an unknown path 404; it serves the
//   compiled-in page, the files it was given and the pieces their tile indexes list (by
//   index; viewed_tile_set.hpp keeps them inside the index's folder), nothing else from
//   the file system, and names files by their base names (pieces by their names in the index).
#pragma once

#include <chrono>
#include <cstddef>
#include <memory>
#include <string>
#include <string_view>
#include <vector>

#include "vola/viewer/viewed_file.hpp"
#include "vola/viewer/viewed_tile_set.hpp"

namespace vola::viewer {

// What one client can hold. The defaults suit one user's browser on this machine.
struct ServerLimits {
  std::size_t max_head_bytes = 16 * 1024;  // request line and headers
  std::size_t max_body_bytes = 64 * 1024;  // the API takes no bodies: this only bounds a hostile one
  // From a request's first byte to its last (head and body): a client that trickles bytes
  // holds a worker no longer than this.
  std::chrono::milliseconds receive_timeout{10'000};
  std::chrono::milliseconds send_timeout{60'000};       // writing one answer (a batch is up to 48 MiB)
  std::chrono::milliseconds keep_alive_timeout{5'000};  // idle time between two requests
  unsigned max_requests_per_connection = 100;
  unsigned workers = 8;                   // connections served at once
  unsigned max_waiting_connections = 64;  // accepted and queued; more get 503 at once
};

struct ServerOptions {
  std::string host = "127.0.0.1";  // the address to listen on (an IP literal or "localhost")
  int port = 0;                    // 0: a free port
  // Names besides the loopback ones and `host` that clients may put in Host (e.g. this
  // machine's LAN name when host is 0.0.0.0).
  std::vector<std::string> host_names;
  ServerLimits limits;
};

class Server {
 public:
  Server(std::vector<std::unique_ptr<ViewedFile>> files, ServerOptions options = {});
  Server(std::vector<std::unique_ptr<ViewedFile>> files, std::vector<std::unique_ptr<ViewedTileSet>> tile_sets,
         ServerOptions options = {});
  ~Server();
  Server(const Server&) = delete;
  Server& operator=(const Server&) = delete;

  // Binds options.host:options.port and returns the port. IoError when it cannot.
  int bind();
  // Serves until stop() (blocks).
  void listen();
  void stop();

  // Answers `request` (raw bytes, possibly several pipelined requests) as the server
  // answers one connection that sends them and then closes its side, and returns the
  // bytes it would send back. After bind(), Host is checked against the bound port. For
  // tests and the fuzzer: the same parser, limits and routes as a socket.
  std::string respond(std::string_view request);

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace vola::viewer
