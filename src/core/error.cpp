// The error handler of builds without exceptions (error.hpp, docs/EMBEDDED.md).
#include <atomic>
#include <cstdio>
#include <cstdlib>

#include "vola/error.hpp"
#include "vola/output_file.hpp"

namespace vola {
VOLA_INLINE_NAMESPACE_BEGIN

namespace {
std::atomic<ErrorHandler> handler{nullptr};
}  // namespace

ErrorHandler set_error_handler(ErrorHandler h) noexcept { return handler.exchange(h); }

namespace detail {
void fail(const Error& error) noexcept {
  if (const ErrorHandler h = handler.load()) h(error.what());
  std::fprintf(stderr, "vola: %s\n", error.what());
  // No destructor runs on this path: the half-written files would stay.
  remove_live_temporaries();
  std::abort();
}
}  // namespace detail

VOLA_INLINE_NAMESPACE_END
}  // namespace vola
