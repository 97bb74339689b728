// vola-sonify: `vola sonify` in an executable of its own (libsndfile and its codecs,
// FFTW, libmysofa), which vola execs for it so that no other command loads them (companions.cpp).
#include "commands.hpp"
#include "run_app.hpp"

int main(int argc, char** argv) {
  constexpr void (*kCommands[])(CLI::App&) = {vola::cli::add_sonify};
  return vola::cli::run_companion(argc, argv, "auralisation of a scene (libsndfile, FFTW, libmysofa)", kCommands);
}
