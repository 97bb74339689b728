// The HTTP side of `vola view`: the page (HTML and the three.js bundle, compiled into the
// binary, so it needs no network) and its API, on the loopback interface only.
//
//   GET /                                    the page
//   GET /viewer.js                           the bundled script
//   GET /api/files                           JSON: metadata of every file (ViewedFile::metadata)
//   GET /api/files/F/cells?level=L&first=I&count=N   binary batch of cells (viewed_file.hpp)
//   GET /api/files/F/cell?level=L&x=X&y=Y&z=Z        JSON: one cell (ViewedFile::cell_info)
//   GET /api/files/F/pick?level=L&ox=..&oy=..&oz=..&dx=..&dy=..&dz=..[&tmax=T]
//                                            JSON: the first cell along a ray in cell units
// Bad requests get status 400 (404 for an unknown file or path) and {"error": "..."}.
#pragma once

#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "vola/viewer/viewed_file.hpp"

namespace vola::viewer {

class Server {
 public:
  explicit Server(std::vector<std::unique_ptr<ViewedFile>> files);
  ~Server();
  Server(const Server&) = delete;
  Server& operator=(const Server&) = delete;

  // Binds 127.0.0.1:port (0: a free port) and returns the port. IoError when it cannot.
  int bind(int port);
  // Serves until stop() (blocks).
  void listen();
  void stop();

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace vola::viewer
