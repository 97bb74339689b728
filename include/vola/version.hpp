// Library version and the inline namespace that carries it (vola::v1), so that two
// incompatible builds of the library cannot be linked into one program by accident.
#pragma once

#define VOLA_VERSION_MAJOR 0
#define VOLA_VERSION_MINOR 1
#define VOLA_VERSION_PATCH 0
#define VOLA_VERSION_STRING "0.1.0"

#define VOLA_INLINE_NAMESPACE_BEGIN inline namespace v1 {
#define VOLA_INLINE_NAMESPACE_END }
