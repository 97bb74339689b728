// Entry point for the classifier's model files (learn::Classifier, what vola classify
// loads, .pt): the input is the file, written to a scratch file of this process. The
// bytes go to libtorch whole (torch::serialize::InputArchive, a TorchScript zip: its
// records, pickles and code are libtorch's to parse); vola checks what libtorch made of
// them (the model version and architecture records, the weights' names and shapes) and
// must turn every failure, libtorch's included, into a vola::Error naming the file.
// Replayed in ctest only: libtorch is not built for the sanitizers of the libFuzzer
// build (docs/SECURITY.md).
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <span>
#include <string>

#include "fuzz_seeds.hpp"
#include "scratch_file.hpp"
#include "vola/error.hpp"
#include "vola/learn/classifier.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string path = vola_fuzz::scratch_file("model", "pt", std::span(data, size));
  try {
    const vola::learn::Classifier classifier(path);
    const auto a = classifier.architecture();
    if (a != vola::learn::Architecture::small && a != vola::learn::Architecture::paper && a != vola::learn::Architecture::wide)
      std::abort();
    ++vola_fuzz::stats().parsed;
  } catch (const vola::Error& e) {
    if (std::getenv("VOLA_FUZZ_VERBOSE")) std::fprintf(stderr, "%s\n", e.what());  // replaying one input
    ++vola_fuzz::stats().refused;
  }
  return 0;
}
