// Internal to the C API: the handle type and `guarded`, which runs an entry point's body
// and turns any exception into a status code and this thread's last-error message, so
// that no exception crosses into C.
#pragma once

#include <new>
#include <string>
#include <vector>

#include "vola/error.hpp"
#include "vola/file.hpp"
#include "vola/tree.hpp"
#include "vola/vola.h"

struct vola_tree {
  vola::Tree tree;
};

namespace vola::capi {

// This thread's last error message (vola_last_error).
std::string& last_error() noexcept;

// What this thread's last conversion or translation warned about, one warning a line
// (vola_last_warnings).
std::string& last_warnings() noexcept;

// Records a call's warnings for vola_last_warnings (called by every entry point that has
// warnings to give, before its work, with none, and after it with what it returned).
void set_last_warnings(const std::vector<std::string>& warnings);

inline vola_status fail(vola_status status, const std::string& message) noexcept {
  try {
    last_error() = message;
  } catch (...) {
    last_error().clear();  // no memory for the message: the status still says what happened
  }
  return status;
}

// The trees this thread's current call reads (tree_of records them). A mapped file cut
// by another process meanwhile leaves zero pages where the file was (file.hpp), so the
// call's answers would mean nothing: guarded() fails it instead of returning VOLA_OK.
std::vector<const vola::Tree*>& trees_in_use() noexcept;

// The handle's tree, refused when NULL or when its mapped file was cut before the call.
inline const vola::Tree& tree_of(const vola_tree* handle) {
  if (handle == nullptr) throw vola::InvalidArgument("tree is NULL");
  vola::check_mapped_often(handle->tree);
  trees_in_use().push_back(&handle->tree);
  return handle->tree;
}

// Called by an entry point before it writes its out-parameters: a tree the call read that
// was cut meanwhile fails the call first, so that the out-parameters stay untouched.
inline void check_trees_in_use() {
  for (const vola::Tree* tree : trees_in_use()) vola::check_mapped_often(*tree);
}

template <class Body>
vola_status guarded(Body&& body) noexcept {
  try {
    trees_in_use().clear();
    try {
      body();
    } catch (...) {
      // A tree cut during the call fails it as an I/O error naming the file, whatever its
      // zero pages made the call fail with ("<memory>: level 2 block 0 is empty ...").
      check_trees_in_use();
      throw;
    }
    check_trees_in_use();  // cut during the call
    trees_in_use().clear();
    return VOLA_OK;
  } catch (const vola::FormatError& e) {
    return fail(VOLA_ERROR_FORMAT, e.what());
  } catch (const vola::IoError& e) {
    return fail(VOLA_ERROR_IO, e.what());
  } catch (const vola::InvalidArgument& e) {
    return fail(VOLA_ERROR_INVALID_ARGUMENT, e.what());
  } catch (const std::bad_alloc&) {
    return fail(VOLA_ERROR_OUT_OF_MEMORY, "out of memory");
  } catch (const std::exception& e) {
    return fail(VOLA_ERROR_INTERNAL, e.what());
  } catch (...) {
    return fail(VOLA_ERROR_INTERNAL, "unknown error");
  }
}

inline void require(bool condition, const char* message) {
  if (!condition) throw vola::InvalidArgument(message);
}

}  // namespace vola::capi
