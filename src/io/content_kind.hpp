// What a file is by its first bytes, for errors about a file read as something it is not
// (a WAV renamed .stl, a .vol named .las): the signatures of formats people have on disk.
#pragma once

#include <cstdint>
#include <optional>
#include <span>
#include <string>

namespace vola::io {

// "a WAV audio file", "a .vol file", ... by the signature at the start of `head` (the
// file's first bytes; 16 are enough); nullopt when none is known.
std::optional<std::string> content_kind(std::span<const std::uint8_t> head);

// content_kind of the file at `path` (nullopt when it cannot be read).
std::optional<std::string> content_kind_of_file(const std::string& path);

// " (its first bytes are those of KIND)" for an error message, or "".
std::string content_kind_note(std::span<const std::uint8_t> head);

}  // namespace vola::io
