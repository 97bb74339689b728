// The XML section of an E57 file as a small element tree (expat parses it): element
// names as written (extension elements keep their prefix, "nor:normalX"), attributes,
// text (CDATA included) and children in order.
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

namespace vola::io {

struct XmlElement {
  std::string name;
  std::vector<std::pair<std::string, std::string>> attributes;
  std::string text;
  std::vector<XmlElement> children;

  // The first child of that name, or nullptr.
  const XmlElement* child(std::string_view child_name) const;
  std::optional<std::string_view> attribute(std::string_view attribute_name) const;
};

// Parses `text` (the XML section of `file`); throws FormatError naming the file, the
// section's physical offset and expat's line and message. Elements nest at most 64 deep.
XmlElement parse_e57_xml(std::string_view text, const std::string& file, std::uint64_t offset);

}  // namespace vola::io
