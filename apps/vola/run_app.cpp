#include "run_app.hpp"

#include <cstdio>
#include <exception>
#include <new>

#include "option_flags.hpp"
#include "suggest.hpp"
#include "vola/error.hpp"
#include "vola/output_file.hpp"
#include "vola/version.hpp"

namespace vola::cli {

int run_app(CLI::App& app, int argc, char** argv) {
  if (const auto unknown = unknown_subcommand(app, argc, argv)) {
    std::fprintf(stderr, "vola: %s\n", unknown->c_str());
    return 1;
  }
  // Ctrl-C or a kill in the middle of a write leaves the old file and no temporary.
  remove_temporaries_on_signal();
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    // A mistyped option gets vola's one line with a suggestion, not CLI11's text as well.
    if (e.get_exit_code() != 0)
      if (const auto unknown = unknown_option(app, argc, argv)) {
        std::fprintf(stderr, "vola: %s\n", unknown->c_str());
        return e.get_exit_code();
      }
    return app.exit(e);
  } catch (const vola::OptionError& e) {
    std::fprintf(stderr, "vola: %s\n", in_flags(e).c_str());
    return 1;
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

int run_companion(int argc, char** argv, const char* what, void (*const* add)(CLI::App&), std::size_t adds) {
  CLI::App app{std::string("vola " VOLA_VERSION_STRING " - ") + what};
  app.name("vola");
  app.require_subcommand(1);
  app.set_version_flag("--version", VOLA_VERSION_STRING);
  for (std::size_t i = 0; i < adds; ++i) add[i](app);
  return run_app(app, argc, argv);
}

}  // namespace vola::cli
