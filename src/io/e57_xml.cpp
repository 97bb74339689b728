#include "e57_xml.hpp"

#include <expat.h>

#include "vola/error.hpp"

namespace vola::io {

namespace {

constexpr std::size_t kMaxXmlDepth = 64;

struct XmlTreeBuilder {
  XmlElement root;
  std::vector<XmlElement*> open;  // the elements not closed yet, innermost last
  bool has_root = false;
  std::string error;
  XML_Parser parser = nullptr;

  void fail(const std::string& why) {
    if (error.empty()) error = why;
    XML_StopParser(parser, XML_FALSE);
  }
};

void XMLCALL on_start(void* data, const XML_Char* name, const XML_Char** attributes) {
  auto& b = *static_cast<XmlTreeBuilder*>(data);
  if (b.open.size() >= kMaxXmlDepth) return b.fail("elements nest more than " + std::to_string(kMaxXmlDepth) + " deep");
  XmlElement* element = nullptr;
  if (b.open.empty()) {
    if (b.has_root) return b.fail("a second root element");
    b.has_root = true;
    element = &b.root;
  } else {
    b.open.back()->children.emplace_back();
    element = &b.open.back()->children.back();
  }
  element->name = name;
  for (const XML_Char** a = attributes; *a; a += 2) element->attributes.emplace_back(a[0], a[1]);
  b.open.push_back(element);
}

void XMLCALL on_end(void* data, const XML_Char*) { static_cast<XmlTreeBuilder*>(data)->open.pop_back(); }

void XMLCALL on_characters(void* data, const XML_Char* text, int length) {
  auto& b = *static_cast<XmlTreeBuilder*>(data);
  if (!b.open.empty()) b.open.back()->text.append(text, static_cast<std::size_t>(length));
}

}  // namespace

const XmlElement* XmlElement::child(std::string_view child_name) const {
  for (const XmlElement& c : children)
    if (c.name == child_name) return &c;
  return nullptr;
}

std::optional<std::string_view> XmlElement::attribute(std::string_view attribute_name) const {
  for (const auto& [key, value] : attributes)
    if (key == attribute_name) return value;
  return std::nullopt;
}

XmlElement parse_e57_xml(std::string_view text, const std::string& file, std::uint64_t offset) {
  XmlTreeBuilder b;
  b.parser = XML_ParserCreate("UTF-8");
  if (!b.parser) throw Error("expat: out of memory");
  XML_SetUserData(b.parser, &b);
  XML_SetElementHandler(b.parser, on_start, on_end);
  XML_SetCharacterDataHandler(b.parser, on_characters);
  // Pieces of at most 1 GiB (expat takes an int length).
  bool ok = true;
  while (ok) {
    const std::size_t piece = std::min<std::size_t>(text.size(), std::size_t{1} << 30);
    const bool last = piece == text.size();
    ok = XML_Parse(b.parser, text.data(), static_cast<int>(piece), last ? XML_TRUE : XML_FALSE) == XML_STATUS_OK;
    text.remove_prefix(piece);
    if (last) break;
  }
  if (!ok) {
    const std::string why = !b.error.empty() ? b.error : XML_ErrorString(XML_GetErrorCode(b.parser));
    const auto line = XML_GetCurrentLineNumber(b.parser);
    XML_ParserFree(b.parser);
    throw FormatError(file, offset, "the XML section, line " + std::to_string(line) + ": " + why);
  }
  XML_ParserFree(b.parser);
  if (!b.has_root) throw FormatError(file, offset, "the XML section holds no element");
  return std::move(b.root);
}

}  // namespace vola::io
