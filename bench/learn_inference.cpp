// Inference time of the 3D CNN classifiers per sample: the whole classify() call (VOLA
// bits -> input tensor -> network -> softmax), at 1 and 2 threads, batches of 1 and 32,
// with 1 vote and with N votes (the object seen in N orientations about z, --votes,
// default 12), median of several runs: wall time, and the process's CPU time (all its
// threads; at one thread, the time the core spent on the call even when other programs
// share the machine).
//
//   learn_inference DATASET_DIR MODEL.pt [MODEL.pt ...] [--runs N] [--votes N] [--threads N] [--reference]
//
// --threads N measures at N threads only (default: 1 and all cores). --reference times the
// network's training-time forward pass (torch's own layer choices, as classify() ran before
// its inference pass) for comparison.
// DATASET_DIR holds <class>/*.vol (vola dataset's layout); its first 32 files are the batch.
#include <algorithm>
#include <chrono>
#include <ctime>
#include <cstdio>
#include <cstring>
#include <string>
#include <thread>
#include <vector>

#include "vola/learn/classifier.hpp"

namespace {

double process_cpu_ms() {
  timespec t{};
  clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &t);
  return double(t.tv_sec) * 1e3 + double(t.tv_nsec) / 1e6;
}

double median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  return v.size() % 2 ? v[v.size() / 2] : (v[v.size() / 2 - 1] + v[v.size() / 2]) / 2;
}

}  // namespace

int main(int argc, char** argv) {
  std::vector<std::string> positional;
  int runs = 5, votes = 12;
  unsigned only_threads = 0;
  for (int i = 1; i < argc; ++i) {
    if (std::strcmp(argv[i], "--runs") == 0 && i + 1 < argc)
      runs = std::max(1, std::atoi(argv[++i]));
    else if (std::strcmp(argv[i], "--votes") == 0 && i + 1 < argc)
      votes = std::max(1, std::atoi(argv[++i]));
    else if (std::strcmp(argv[i], "--reference") == 0)
      vola::learn::detail::reference_inference = true;
    else if (std::strcmp(argv[i], "--threads") == 0 && i + 1 < argc)
      only_threads = unsigned(std::max(1, std::atoi(argv[++i])));
    else
      positional.emplace_back(argv[i]);
  }
  if (positional.size() < 2) {
    std::fprintf(stderr, "usage: learn_inference DATASET_DIR MODEL.pt [MODEL.pt ...] [--runs N] [--votes N] [--threads N] [--reference]\n");
    return 2;
  }
  try {
    auto entries = vola::learn::list_dataset(positional[0]);
    // Spread the 32 over the classes: every k-th file.
    std::vector<vola::learn::DatasetEntry> chosen;
    const std::size_t step = std::max<std::size_t>(1, entries.size() / 32);
    for (std::size_t i = 0; i < entries.size() && chosen.size() < 32; i += step) chosen.push_back(entries[i]);
    const auto samples = vola::learn::load_samples(chosen);
    std::vector<const vola::Tree*> trees;
    for (const auto& s : samples) trees.push_back(&s.tree);
    const unsigned cores = std::max(1u, std::thread::hardware_concurrency());
    std::printf("%-40s %-6s %7s %5s %5s %12s %12s   (median of %d runs, %zu samples per run; %s pass)\n", "model", "arch",
                "threads", "batch", "votes", "ms/sample", "cpu ms", runs, trees.size(),
                vola::learn::detail::reference_inference ? "reference forward" : "inference");
    for (std::size_t m = 1; m < positional.size(); ++m) {
      const vola::learn::Classifier classifier(positional[m]);
      const std::vector<unsigned> thread_counts = only_threads ? std::vector<unsigned>{only_threads} : std::vector<unsigned>{1u, cores};
      for (unsigned threads : thread_counts) {
        vola::learn::set_threads(int(threads));
        const std::vector<int> vote_counts = votes == 1 ? std::vector<int>{1} : std::vector<int>{1, votes};
        for (int v : vote_counts)
        for (std::size_t batch : {std::size_t(1), std::size_t(32)}) {
          // One warm-up call (allocations, thread pool), then timed runs over all samples.
          classifier.classify(std::span(trees.data(), std::min(batch, trees.size())), v);
          std::vector<double> per_sample, cpu_per_sample;
          for (int r = 0; r < runs; ++r) {
            const double cpu_start = process_cpu_ms();
            const auto start = std::chrono::steady_clock::now();
            for (std::size_t first = 0; first < trees.size(); first += batch)
              classifier.classify(std::span(trees.data() + first, std::min(batch, trees.size() - first)), v);
            const double ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
            per_sample.push_back(ms / double(trees.size()));
            cpu_per_sample.push_back((process_cpu_ms() - cpu_start) / double(trees.size()));
          }
          std::printf("%-40s %-6s %7u %5zu %5d %12.2f %12.2f\n", positional[m].c_str(),
                      std::string(vola::learn::architecture_name(classifier.architecture())).c_str(), threads, batch, v,
                      median(per_sample), median(cpu_per_sample));
          std::fflush(stdout);
        }
      }
    }
  } catch (const std::exception& e) {
    std::fprintf(stderr, "learn_inference: %s\n", e.what());
    return 1;
  }
  return 0;
}
