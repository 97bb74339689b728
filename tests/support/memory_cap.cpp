#include "memory_cap.hpp"

#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <exception>

#include "vola/error.hpp"

namespace vola_test {

namespace {

bool address_sanitizer() {
#if defined(__SANITIZE_ADDRESS__)
  return true;
#elif defined(__has_feature)
#if __has_feature(address_sanitizer)
  return true;
#else
  return false;
#endif
#else
  return false;
#endif
}

std::string outcome_of(const std::function<std::string()>& f) {
  try {
    return f();
  } catch (const vola::FormatError& e) {
    return std::string("FormatError: ") + e.what();
  } catch (const vola::InvalidArgument& e) {
    return std::string("InvalidArgument: ") + e.what();
  } catch (const vola::Error& e) {
    return std::string("Error: ") + e.what();
  } catch (const std::exception& e) {
    return std::string("exception: ") + e.what();
  }
}

[[noreturn]] void run_child(int out, std::uint64_t bytes, const std::function<std::string()>& f) {
  if (!address_sanitizer()) {
    const rlimit cap{bytes, bytes};
    setrlimit(RLIMIT_AS, &cap);
  }
  const std::string result = outcome_of(f);
  for (std::size_t done = 0; done < result.size();) {
    const ssize_t n = write(out, result.data() + done, result.size() - done);
    if (n <= 0) break;
    done += static_cast<std::size_t>(n);
  }
  _exit(0);  // no atexit handlers or gtest teardown in the child
}

}  // namespace

std::string run_with_memory_cap(const std::function<std::string()>& f, std::uint64_t bytes) {
  int fds[2];
  if (pipe(fds) != 0) return "died: no pipe";
  const pid_t child = fork();
  if (child < 0) return "died: no fork";
  if (child == 0) {
    close(fds[0]);
    run_child(fds[1], bytes, f);
  }
  close(fds[1]);
  std::string result;
  char buffer[4096];
  for (ssize_t n; (n = read(fds[0], buffer, sizeof buffer)) > 0;) result.append(buffer, static_cast<std::size_t>(n));
  close(fds[0]);
  int status = 0;
  waitpid(child, &status, 0);
  if (WIFSIGNALED(status)) return "died: signal " + std::to_string(WTERMSIG(status));
  return result;
}

}  // namespace vola_test
