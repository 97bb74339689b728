#include "vola/viewer/server.hpp"

#include <httplib.h>

#include <charconv>
#include <cmath>
#include <limits>
#include <nlohmann/json.hpp>
#include <string>

#include "bounded_http_server.hpp"
#include "request_guard.hpp"
#include "transport.hpp"
#include "vola/error.hpp"
#include "web_assets.hpp"

namespace vola::viewer {

namespace {

struct NotFound : Error {
  using Error::Error;
};

// Text from a request (a path, a parameter, a file name) may not be UTF-8: replace what is
// not rather than throw (a throw from httplib's error handler ends the process).
void send_json(httplib::Response& res, int status, const nlohmann::json& body) {
  res.status = status;
  res.set_content(body.dump(-1, ' ', false, nlohmann::json::error_handler_t::replace), "application/json");
}

std::string param(const httplib::Request& req, const char* name) {
  if (!req.has_param(name)) throw InvalidArgument(std::string("missing query parameter '") + name + "'");
  return req.get_param_value(name);
}

// The whole text must be the number: "12x", "" and "1e99" for an integer are refused.
template <class T>
T integer_param(const httplib::Request& req, const char* name, T min, T max) {
  const std::string text = param(req, name);
  T value{};
  const auto [end, ec] = std::from_chars(text.data(), text.data() + text.size(), value);
  if (ec != std::errc{} || end != text.data() + text.size() || value < min || value > max)
    throw InvalidArgument(std::string("query parameter '") + name + "' = '" + text + "' is not an integer in " +
                          std::to_string(min) + ".." + std::to_string(max));
  return value;
}

double real_param(const httplib::Request& req, const char* name) {
  const std::string text = param(req, name);
  double value = 0.0;
  const auto [end, ec] = std::from_chars(text.data(), text.data() + text.size(), value);
  if (ec != std::errc{} || end != text.data() + text.size() || !std::isfinite(value))
    throw InvalidArgument(std::string("query parameter '") + name + "' = '" + text + "' is not a finite number");
  return value;
}

}  // namespace

struct Server::Impl {
  Impl(std::vector<std::unique_ptr<ViewedFile>> f, std::vector<std::unique_ptr<ViewedTileSet>> t, ServerOptions o)
      : files(std::move(f)), tile_sets(std::move(t)), options(std::move(o)), names(names_of(options)),
        http(options.limits) {
    names.set_port(options.port);
  }

  std::vector<std::unique_ptr<ViewedFile>> files;
  std::vector<std::unique_ptr<ViewedTileSet>> tile_sets;
  ServerOptions options;
  HostNames names;
  BoundedHttpServer http;

  static HostNames names_of(const ServerOptions& o) {
    std::vector<std::string> all = o.host_names;
    all.push_back(o.host);
    return HostNames(std::move(all));
  }

  // "files 0..2", or "no files" (a viewer of tile sets alone).
  static std::string numbered(std::size_t count, const std::string& what) {
    return count == 0 ? "no " + what : what + " 0.." + std::to_string(count - 1);
  }

  const ViewedFile& file(const httplib::Request& req) const {
    const std::string& text = req.matches[1];
    std::size_t i = 0;
    const auto [end, ec] = std::from_chars(text.data(), text.data() + text.size(), i);
    if (ec != std::errc{} || end != text.data() + text.size() || i >= files.size())
      throw NotFound("no file " + text + " (this viewer serves " + numbered(files.size(), "files") + ")");
    return *files[i];
  }

  // Piece req.matches[2] of tile set req.matches[1].
  std::shared_ptr<const ViewedFile> piece(const httplib::Request& req) const {
    const std::string& set_text = req.matches[1];
    const std::string& piece_text = req.matches[2];
    std::size_t s = 0, p = 0;
    const auto [set_end, set_ec] = std::from_chars(set_text.data(), set_text.data() + set_text.size(), s);
    if (set_ec != std::errc{} || set_end != set_text.data() + set_text.size() || s >= tile_sets.size())
      throw NotFound("no tile set " + set_text + " (this viewer serves " + std::to_string(tile_sets.size()) + ")");
    const ViewedTileSet& set = *tile_sets[s];
    const auto [piece_end, piece_ec] = std::from_chars(piece_text.data(), piece_text.data() + piece_text.size(), p);
    if (piece_ec != std::errc{} || piece_end != piece_text.data() + piece_text.size() || p >= set.pieces().size())
      throw NotFound("no piece " + piece_text + " in tile set " + set_text + " (it has " +
                     numbered(set.pieces().size(), "pieces") + ")");
    return set.piece(p);
  }

  // Runs a handler, turning vola errors into 400/404 with a JSON message.
  template <class F>
  static httplib::Server::Handler guarded(F f) {
    return [f](const httplib::Request& req, httplib::Response& res) {
      try {
        f(req, res);
      } catch (const NotFound& e) {
        send_json(res, 404, {{"error", e.what()}});
      } catch (const Error& e) {
        send_json(res, 400, {{"error", e.what()}});
      }
    };
  }

  void guards() {
    http.set_pre_routing_handler([this](const httplib::Request& req, httplib::Response& res) {
      const auto refusal = refuse_before_routing(req, names);
      if (!refusal) return httplib::Server::HandlerResponse::Unhandled;
      send_json(res, refusal->status, {{"error", refusal->cause}});
      return httplib::Server::HandlerResponse::Handled;
    });
    // An error answer closes the connection (bounded_http_server.cpp): say so.
    http.set_post_routing_handler([](const httplib::Request&, httplib::Response& res) {
      if (res.status >= 400) {
        res.set_header("Connection", "close");
        res.headers.erase("Keep-Alive");
      }
    });
  }

  void routes() {
    http.Get("/", [](const httplib::Request&, httplib::Response& res) {
      const auto html = index_html();
      res.set_content(html.data(), html.size(), "text/html; charset=utf-8");
    });
    http.Get("/viewer.js", [](const httplib::Request&, httplib::Response& res) {
      const auto js = viewer_js();
      res.set_content(js.data(), js.size(), "text/javascript; charset=utf-8");
    });
    http.Get("/api/files", [this](const httplib::Request&, httplib::Response& res) {
      nlohmann::json list = nlohmann::json::array();
      for (std::size_t i = 0; i < files.size(); ++i) {
        list.push_back(files[i]->metadata());
        list.back()["index"] = i;
      }
      send_json(res, 200, list);
    });
    http.Get(R"(/api/files/(\d+)/cells)", guarded([this](const httplib::Request& req, httplib::Response& res) {
      const ViewedFile& f = file(req);
      const int level = integer_param<int>(req, "level", 0, f.tree().depth() - 1);
      const auto first = integer_param<std::uint64_t>(req, "first", 0, std::numeric_limits<std::uint64_t>::max());
      const auto count = integer_param<std::uint64_t>(req, "count", 0, kMaxBatchCells);
      res.set_content(f.cell_batch(level, first, count), "application/octet-stream");
    }));
    http.Get("/api/tilesets", [this](const httplib::Request&, httplib::Response& res) {
      nlohmann::json list = nlohmann::json::array();
      for (std::size_t i = 0; i < tile_sets.size(); ++i) {
        list.push_back(tile_sets[i]->metadata());
        list.back()["index"] = i;
      }
      send_json(res, 200, list);
    });
    http.Get(R"(/api/tilesets/(\d+)/pieces/(\d+)/cells)",
             guarded([this](const httplib::Request& req, httplib::Response& res) {
               const auto f = piece(req);
               const int level = integer_param<int>(req, "level", 0, f->tree().depth() - 1);
               const auto first =
                   integer_param<std::uint64_t>(req, "first", 0, std::numeric_limits<std::uint64_t>::max());
               const auto count = integer_param<std::uint64_t>(req, "count", 0, kMaxBatchCells);
               res.set_content(f->cell_batch(level, first, count), "application/octet-stream");
             }));
    http.Get(R"(/api/files/(\d+)/cell)", guarded([this](const httplib::Request& req, httplib::Response& res) {
      const ViewedFile& f = file(req);
      const int level = integer_param<int>(req, "level", 0, f.tree().depth() - 1);
      const std::uint32_t max = side_of(level + 1) - 1;
      const Voxel cell{integer_param<std::uint32_t>(req, "x", 0, max), integer_param<std::uint32_t>(req, "y", 0, max),
                       integer_param<std::uint32_t>(req, "z", 0, max)};
      send_json(res, 200, f.cell_info(level, cell));
    }));
    http.Get(R"(/api/files/(\d+)/pick)", guarded([this](const httplib::Request& req, httplib::Response& res) {
      const ViewedFile& f = file(req);
      const int level = integer_param<int>(req, "level", 0, f.tree().depth() - 1);
      raycast::Ray ray;
      ray.origin = {real_param(req, "ox"), real_param(req, "oy"), real_param(req, "oz")};
      ray.direction = {real_param(req, "dx"), real_param(req, "dy"), real_param(req, "dz")};
      if (req.has_param("tmax")) ray.t_max = real_param(req, "tmax");
      send_json(res, 200, f.pick(level, ray));
    }));
    // Called outside httplib's try: whatever goes wrong here must not escape.
    http.set_error_handler([](const httplib::Request& req, httplib::Response& res) noexcept {
      if (!res.body.empty()) return;
      try {
        send_json(res, res.status,
                  {{"error", res.status == 404 ? "no such path: " + req.path
                                               : "the request is not one this server understands (status " +
                                                     std::to_string(res.status) + ")"}});
      } catch (...) {
      }
    });
    // Anything else a handler throws (bad_alloc, ...): a 500 with its message, never a crash.
    http.set_exception_handler([](const httplib::Request&, httplib::Response& res, std::exception_ptr ep) {
      std::string what = "internal error";
      try {
        std::rethrow_exception(ep);
      } catch (const std::exception& e) {
        what = e.what();
      } catch (...) {
      }
      send_json(res, 500, {{"error", what}});
    });
  }
};

Server::Server(std::vector<std::unique_ptr<ViewedFile>> files, ServerOptions options)
    : Server(std::move(files), {}, std::move(options)) {}

Server::Server(std::vector<std::unique_ptr<ViewedFile>> files, std::vector<std::unique_ptr<ViewedTileSet>> tile_sets,
               ServerOptions options)
    : impl_(std::make_unique<Impl>(std::move(files), std::move(tile_sets), std::move(options))) {
  impl_->guards();
  impl_->routes();
}

Server::~Server() = default;

int Server::bind() {
  const std::string& host = impl_->options.host;
  const int port = impl_->options.port;
  if (port < 0 || port > 65535) throw IoError("cannot bind port " + std::to_string(port) + ": not in 0..65535");
  const int bound = port == 0 ? impl_->http.bind_to_any_port(host) : (impl_->http.bind_to_port(host, port) ? port : -1);
  if (bound <= 0)
    throw IoError("cannot bind " + host + ":" + (port == 0 ? std::string("(a free port)") : std::to_string(port)) +
                  " (in use, not an address of this machine, or not allowed)");
  impl_->names.set_port(bound);
  return bound;
}

std::string Server::respond(std::string_view request) {
  MemoryTransport transport(request);
  impl_->http.serve(transport);
  return std::move(transport.output());
}

void Server::listen() {
  if (!impl_->http.listen_after_bind()) throw IoError("the viewer's HTTP server stopped with an error");
}

void Server::stop() { impl_->http.stop(); }

}  // namespace vola::viewer
