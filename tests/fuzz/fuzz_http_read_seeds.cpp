// Seeds for fuzz_http_read: the requests vola view's page sends (the page, its script,
// the file list, cell batches, one cell, picks, the tile sets and a tile's cells), pipelined, with a body, chunked, with a
// foreign Host, percent-escapes that are not UTF-8; and, from the shared golden folder,
// requests carrying each small golden .vol file as their body (the API takes no bodies:
// the server must read past or refuse them). Linked into fuzz_http_read_replay in place
// of fuzz_seeds.cpp.
#include <algorithm>
#include <fstream>
#include <iterator>
#include <string>

#include "fuzz_seeds.hpp"

namespace vola_fuzz {
namespace {

using Bytes = std::vector<std::uint8_t>;
const std::string kHost = "Host: 127.0.0.1:8080\r\n";

Seed text(const std::string& name, const std::string& s) { return {name, Bytes(s.begin(), s.end())}; }
std::string get(const std::string& target, const std::string& extra = "") {
  return "GET " + target + " HTTP/1.1\r\n" + kHost + extra + "\r\n";
}

}  // namespace

std::vector<Seed> synthetic_seeds() {
  return {
      text("page", get("/", "User-Agent: Mozilla/5.0\r\nAccept: text/html\r\n")),
      text("script", get("/viewer.js", "Connection: close\r\n")),
      text("files", get("/api/files")),
      text("cells", get("/api/files/0/cells?level=2&first=0&count=100")),
      text("cell", get("/api/files/0/cell?level=3&x=1&y=2&z=0")),
      text("tilesets", get("/api/tilesets")),
      text("tile_cells", get("/api/tilesets/0/pieces/0/cells?level=3&first=0&count=100")),
      text("tile_bad", get("/api/tilesets/0/pieces/1/cells?level=0&first=0&count=1") +
                           get("/api/tilesets/3/pieces/0/cells?level=0&first=0&count=1")),
      text("pick", get("/api/files/0/pick?level=3&ox=-1&oy=0.5&oz=0.5&dx=1&dy=0&dz=0&tmax=100")),
      text("pipelined", get("/api/files") + get("/api/files/0/cell?level=0&x=0&y=0&z=0") + get("/api/files/9/cells?level=1&first=0&count=1")),
      text("foreign_host", "GET /api/files HTTP/1.1\r\nHost: evil.example:8080\r\n\r\n"),
      text("not_utf8", get("/api/files/0/cell?level=%ff&x=%c3%28&y=0&z=0")),
      text("post_body", "POST /api/files HTTP/1.1\r\n" + kHost + "Content-Length: 11\r\n\r\nhello world"),
      text("chunked", "POST / HTTP/1.1\r\n" + kHost + "Transfer-Encoding: chunked\r\n\r\n5\r\nhello\r\n0\r\n\r\n"),
      text("range", get("/viewer.js", "Range: bytes=0-10,20-30\r\n")),
      text("http10", "GET /api/files HTTP/1.0\r\n" + kHost + "\r\n"),
  };
}

// A POST per golden .vol file of at most 16 KiB, the file as its body.
std::vector<Seed> golden_seeds(const std::filesystem::path& golden) {
  std::vector<Seed> seeds;
  if (!std::filesystem::is_directory(golden)) return seeds;
  for (const auto& entry : std::filesystem::recursive_directory_iterator(golden)) {
    if (!entry.is_regular_file() || entry.path().extension() != ".vol" || entry.file_size() > 16 * 1024) continue;
    std::ifstream in(entry.path(), std::ios::binary);
    const std::string body{std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
    seeds.push_back(text("post_" + entry.path().filename().string(),
                         "POST /api/files/0/cells?level=1&first=0&count=8 HTTP/1.1\r\n" + kHost +
                             "Content-Type: application/octet-stream\r\nContent-Length: " + std::to_string(body.size()) +
                             "\r\n\r\n" + body + get("/api/files")));
  }
  std::sort(seeds.begin(), seeds.end(), [](const Seed& a, const Seed& b) { return a.name < b.name; });
  return seeds;
}

}  // namespace vola_fuzz
