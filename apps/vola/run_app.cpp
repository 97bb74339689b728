#include "run_app.hpp"

#include <cstdio>
#include <exception>
#include <new>

#include "vola/error.hpp"

namespace vola::cli {

int run_app(CLI::App& app, int argc, char** argv) {
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    return app.exit(e);
  } catch (const vola::Error& e) {
    std::fprintf(stderr, "vola: %s\n", e.what());
    return 1;
  } catch (const std::bad_alloc&) {
    std::fprintf(stderr, "vola: out of memory\n");
    return 1;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "vola: %s\n", e.what());
    return 1;
  }
  return 0;
}

}  // namespace vola::cli
