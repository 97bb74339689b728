// What a request must be before any route sees it.
//
// Host: a web page can point a DNS name it controls at 127.0.0.1 (DNS rebinding); the
// browser then lets that page read this server's answers, since for the browser they
// come from the page's own origin. The browser still sends the page's name in Host, so
// answering only the names this server has (with its port) shuts that door.
//
// UTF-8: httplib hands routes the percent-decoded path and query, any bytes at all;
// names and messages built from them go out as JSON, which must be UTF-8.
#pragma once

#include <httplib.h>

#include <optional>
#include <string>
#include <string_view>
#include <vector>

namespace vola::viewer {

bool is_utf8(std::string_view text) noexcept;

class HostNames {
 public:
  // `names`: the loopback names are always included; an IPv6 literal may come with or
  // without brackets.
  explicit HostNames(std::vector<std::string> names);
  void set_port(int port) { port_ = port; }
  // Whether `host` (a Host header) is one of the names with this server's port (or with
  // no port when the port is 80), ignoring case.
  bool allows(std::string_view host) const;

 private:
  std::vector<std::string> names_;  // lower case, IPv6 literals bracketed
  int port_ = 0;
};

// The status and cause a request is refused with before routing (Host, UTF-8), or none.
struct Refusal {
  int status;
  std::string cause;
};
std::optional<Refusal> refuse_before_routing(const httplib::Request& req, const HostNames& names);

}  // namespace vola::viewer
