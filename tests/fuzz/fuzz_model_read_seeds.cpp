// Seeds for fuzz_model_read: the models committed in models/ (whole: a few mutations
// each, they are 3.5 MB) and small archives written here with libtorch's own writer that
// vola must refuse at each of its checks: no weights, another model version, an unknown
// architecture, a weights record whose tensors do not fit the network, an archive of
// one tensor. Linked into fuzz_model_read_replay in place of fuzz_seeds.cpp.
#include <torch/torch.h>
#include <unistd.h>

#include <algorithm>
#include <fstream>
#include <iterator>
#include <string>

#include "fuzz_seeds.hpp"

#ifndef VOLA_FUZZ_MODELS_DIR
#define VOLA_FUZZ_MODELS_DIR ""
#endif

namespace vola_fuzz {
namespace {

namespace fs = std::filesystem;
using Bytes = std::vector<std::uint8_t>;

Bytes read_all(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  return Bytes(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
}

Bytes saved(torch::serialize::OutputArchive& archive) {
  const auto path = fs::temp_directory_path() / ("vola_fuzz_model_seed_" + std::to_string(::getpid()) + ".pt");
  archive.save_to(path.string());
  Bytes b = read_all(path);
  fs::remove(path);
  return b;
}

Bytes header_only(std::int64_t version, std::int64_t architecture) {
  torch::serialize::OutputArchive archive;
  archive.write("vola_model_version", torch::tensor(version));
  archive.write("vola_architecture", torch::tensor(architecture));
  return saved(archive);
}

}  // namespace

std::vector<Seed> synthetic_seeds() {
  std::vector<Seed> seeds{{"no_weights.pt", header_only(1, 1)},
                          {"version_2.pt", header_only(2, 1)},
                          {"architecture_7.pt", header_only(1, 7)}};
  torch::serialize::OutputArchive misfit, weights;
  misfit.write("vola_model_version", torch::tensor(std::int64_t{1}));
  misfit.write("vola_architecture", torch::tensor(std::int64_t{1}));
  weights.write("conv1.weight", torch::zeros({2, 1, 3, 3, 3}));
  weights.write("conv1.bias", torch::zeros({2}));
  misfit.write("model", weights);
  seeds.push_back({"misfit_weights.pt", saved(misfit)});
  torch::serialize::OutputArchive one;
  one.write("x", torch::arange(6).reshape({2, 3}));
  seeds.push_back({"one_tensor.pt", saved(one)});
  return seeds;
}

// The committed models (models/*.pt beside the sources; the shared data has none).
std::vector<Seed> golden_seeds(const fs::path&) {
  std::vector<Seed> seeds;
  const fs::path folder = VOLA_FUZZ_MODELS_DIR;
  if (!fs::is_directory(folder)) return seeds;
  for (const auto& entry : fs::directory_iterator(folder))
    if (entry.is_regular_file() && entry.path().extension() == ".pt")
      seeds.push_back({entry.path().filename().string(), read_all(entry.path())});
  std::sort(seeds.begin(), seeds.end(), [](const Seed& a, const Seed& b) { return a.name < b.name; });
  return seeds;
}

}  // namespace vola_fuzz
