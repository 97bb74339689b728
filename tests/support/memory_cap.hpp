// Runs a piece of a test in a child process whose address space is capped (RLIMIT_AS),
// so that a reader that would allocate gigabytes for a hostile file fails there (with
// bad_alloc, or killed) instead of taking the machine's memory, and the test can show
// that the fixed reader refuses the file within the cap.
#pragma once

#include <cstdint>
#include <functional>
#include <string>

namespace vola_test {

// 2 GiB: far above what any of the small hostile files justifies, far below what they
// made the readers ask for.
inline constexpr std::uint64_t kHostileFileMemoryCap = std::uint64_t{2} << 30;

// Runs `f` in a forked child under the cap and returns what it returned; a vola::Error
// thrown comes back as "<type name>: <what()>" ("FormatError: ...", "InvalidArgument:
// ..."), any other exception as "exception: <what()>", a child that dies as
// "died: signal N". Under AddressSanitizer (which reserves terabytes of shadow memory)
// the cap is not set.
std::string run_with_memory_cap(const std::function<std::string()>& f, std::uint64_t bytes = kHostileFileMemoryCap);

}  // namespace vola_test
