#include "request_guard.hpp"

#include <algorithm>
#include <cctype>

namespace vola::viewer {

namespace {

std::string lower(std::string_view s) {
  std::string out(s);
  std::transform(out.begin(), out.end(), out.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  return out;
}

std::string bracketed(std::string name) {
  if (name.find(':') == std::string::npos || name.front() == '[') return name;
  name.insert(name.begin(), '[');
  name.push_back(']');
  return name;
}

// Length of the UTF-8 sequence starting at s[i], or 0 when it is not one (overlong forms,
// surrogates and code points over U+10FFFF included).
std::size_t sequence_length(std::string_view s, std::size_t i) noexcept {
  const auto b = [&](std::size_t k) { return static_cast<unsigned char>(s[i + k]); };
  const auto continuation = [&](std::size_t k) { return i + k < s.size() && (b(k) & 0xC0) == 0x80; };
  const unsigned char c = b(0);
  if (c < 0x80) return 1;
  if (c >= 0xC2 && c <= 0xDF) return continuation(1) ? 2 : 0;
  if (c >= 0xE0 && c <= 0xEF) {
    if (!continuation(1) || !continuation(2)) return 0;
    if (c == 0xE0 && b(1) < 0xA0) return 0;   // overlong
    if (c == 0xED && b(1) >= 0xA0) return 0;  // surrogates
    return 3;
  }
  if (c >= 0xF0 && c <= 0xF4) {
    if (!continuation(1) || !continuation(2) || !continuation(3)) return 0;
    if (c == 0xF0 && b(1) < 0x90) return 0;   // overlong
    if (c == 0xF4 && b(1) >= 0x90) return 0;  // over U+10FFFF
    return 4;
  }
  return 0;
}

}  // namespace

bool is_utf8(std::string_view text) noexcept {
  for (std::size_t i = 0; i < text.size();) {
    const std::size_t n = sequence_length(text, i);
    if (n == 0) return false;
    i += n;
  }
  return true;
}

HostNames::HostNames(std::vector<std::string> names) {
  for (const char* loopback : {"localhost", "127.0.0.1", "[::1]"}) names_.emplace_back(loopback);
  for (auto& n : names)
    if (!n.empty()) names_.push_back(lower(bracketed(std::move(n))));
}

bool HostNames::allows(std::string_view host) const {
  const std::string h = lower(host);
  const std::string port = std::to_string(port_);
  const auto is_name_with_port = [&](const std::string& n) {
    const std::string_view rest = std::string_view(h).substr(std::min(n.size(), h.size()));
    return h.compare(0, n.size(), n) == 0 &&
           ((rest.size() == port.size() + 1 && rest[0] == ':' && rest.substr(1) == port) ||
            (port_ == 80 && rest.empty()));
  };
  return std::any_of(names_.begin(), names_.end(), is_name_with_port);
}

std::optional<Refusal> refuse_before_routing(const httplib::Request& req, const HostNames& names) {
  if (!req.has_header("Host")) return Refusal{400, "the request has no Host header"};
  // Two Host headers could name this server and another: refuse rather than choose.
  if (req.get_header_value_count("Host") != 1) return Refusal{400, "the request has more than one Host header"};
  if (!names.allows(req.get_header_value("Host")))
    return Refusal{403, "this server answers only to its own names (localhost, 127.0.0.1, [::1], with its port)"};
  if (!is_utf8(req.path)) return Refusal{400, "the path is not UTF-8"};
  for (const auto& [key, value] : req.params)
    if (!is_utf8(key) || !is_utf8(value)) return Refusal{400, "a query parameter is not UTF-8"};
  return std::nullopt;
}

}  // namespace vola::viewer
