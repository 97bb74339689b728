// The layout of a fuzz_ept_read input: an EPT dataset's files one after another, each
// ended by kEptPartEnd (bytes no JSON text and few node files hold).
#pragma once

#include <string>
#include <string_view>
#include <vector>

namespace vola_fuzz {

inline constexpr std::string_view kEptPartEnd{"\0EPT\0", 5};

// The parts of `input`; a last part without its end marker counts too.
inline std::vector<std::string_view> split_ept_parts(std::string_view input) {
  std::vector<std::string_view> parts;
  while (!input.empty()) {
    const std::size_t end = input.find(kEptPartEnd);
    parts.push_back(input.substr(0, end));
    if (end == std::string_view::npos) break;
    input.remove_prefix(end + kEptPartEnd.size());
  }
  return parts;
}

// One input from the dataset's files, in the order of split_ept_parts.
inline std::string join_ept_parts(const std::vector<std::string>& parts) {
  std::string out;
  for (const auto& p : parts) out.append(p).append(kEptPartEnd);
  return out;
}

}  // namespace vola_fuzz
