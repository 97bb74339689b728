// Runs the fuzz entry point without libFuzzer: every golden file, the synthetic seeds
// and N seeded random mutations of them (bit flips, truncations, inserted and deleted
// bytes, header field changes, word overwrites). Used by ctest under the normal
// compiler; a crash or an abort (broken invariant) fails the test.
//
//   fuzz_replay [--mutations N | --seconds S] [--seed S] [--golden DIR] [--regressions DIR] [FILE...]
//   fuzz_replay --write-corpus DIR [--golden DIR] [--regressions DIR]   (for scripts/fuzz)
//
// --seconds: mutate for that long instead of N times (a sanitizer run of a target libFuzzer
// cannot build, docs/SECURITY.md).
// --regressions: a folder of inputs that once failed (tests/fuzz/regressions), replayed
// and mutated like the other seeds.
//
// With FILEs (e.g. libFuzzer crash artifacts) only those are replayed. With
// VOLA_FUZZ_LAST_INPUT=FILE each input is first written to FILE (the one a crash ends on). The golden
// folder defaults to $VOLA_SHARED/golden; when it is missing the run is skipped
// (exit 77), or fails when the environment variable CI is set.
#include <chrono>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <iterator>
#include <random>
#include <string>
#include <vector>

#include "fuzz_seeds.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size);

namespace {

namespace fs = std::filesystem;
using Bytes = std::vector<std::uint8_t>;

constexpr std::size_t kBigSeed = 256 * 1024;  // large seeds get a few mutations only
constexpr int kBigSeedMutations = 10;

fs::path default_golden() {
  const char* shared = std::getenv("VOLA_SHARED");
  return fs::path(shared && *shared ? shared : VOLA_SHARED_DEFAULT) / "golden";
}

template <class T>
void put(Bytes& b, std::size_t at, T value) {
  if (at + sizeof(T) <= b.size()) std::memcpy(b.data() + at, &value, sizeof(T));
}

// One random structural or byte-level change.
void mutate_once(Bytes& b, std::mt19937_64& rng) {
  auto pick = [&](std::size_t n) { return n ? static_cast<std::size_t>(rng() % n) : 0; };
  const std::size_t words = b.size() > 80 ? (b.size() - 80) / 8 : 0;
  switch (rng() % 12) {
    case 0:  // flip a few bits
      for (int i = 0, n = 1 + static_cast<int>(rng() % 8); i < n && !b.empty(); ++i)
        b[pick(b.size())] ^= static_cast<std::uint8_t>(1u << (rng() % 8));
      break;
    case 1: {  // an interesting byte
      static const std::uint8_t values[] = {0, 1, 0x7F, 0x80, 0xFF, 10, 11, 2};
      if (!b.empty()) b[pick(b.size())] = values[rng() % std::size(values)];
      break;
    }
    case 2:  // truncate, often at a word boundary
      if (!b.empty()) b.resize(rng() % 2 ? pick(b.size()) : std::min(b.size(), 80 + 8 * pick(words + 1)));
      break;
    case 3: {  // insert bytes
      const std::size_t at = pick(b.size() + 1);
      Bytes extra(1 + rng() % 16);
      for (auto& x : extra) x = static_cast<std::uint8_t>(rng());
      b.insert(b.begin() + static_cast<std::ptrdiff_t>(at), extra.begin(), extra.end());
      break;
    }
    case 4: {  // delete a range
      if (b.empty()) break;
      const std::size_t at = pick(b.size());
      const std::size_t n = std::min(b.size() - at, std::size_t{1} + rng() % 24);
      b.erase(b.begin() + static_cast<std::ptrdiff_t>(at), b.begin() + static_cast<std::ptrdiff_t>(at + n));
      break;
    }
    case 5: {  // header: version, mode, depth
      static const std::uint16_t versions[] = {0, 1, 2, 3, 0xFFFF};
      put<std::uint16_t>(b, 4, versions[rng() % std::size(versions)]);
      put<std::uint8_t>(b, 6, static_cast<std::uint8_t>(rng() % 3));
      break;
    }
    case 6:
      put<std::uint8_t>(b, 7, static_cast<std::uint8_t>(rng() % 4 == 0 ? rng() : rng() % 12));
      break;
    case 7: {  // header: nbits, header size
      static const std::uint32_t nbits[] = {0, 1, 2, 64, 0xFFFFFFFFu};
      put<std::uint32_t>(b, 8, nbits[rng() % std::size(nbits)]);
      if (rng() % 8 == 0) put<std::uint32_t>(b, 0, static_cast<std::uint32_t>(rng() % 2 ? 81 : rng()));
      break;
    }
    case 8: {  // overwrite a word of the levels
      if (!words) break;
      static const std::uint64_t values[] = {0, ~std::uint64_t{0}, 1, std::uint64_t{1} << 63};
      put<std::uint64_t>(b, 80 + 8 * pick(words), rng() % 2 ? values[rng() % std::size(values)] : rng());
      break;
    }
    case 9: {  // overwrite an aligned word anywhere past the header (extension fields)
      if (b.size() < 88) break;
      const std::size_t at = 80 + 4 * pick((b.size() - 84) / 4);
      put<std::uint32_t>(b, at, rng() % 2 ? static_cast<std::uint32_t>(rng() % 64) : static_cast<std::uint32_t>(rng()));
      break;
    }
    case 10: {  // append an extension-looking tail
      static const char magic[] = "VOLAEXT";
      b.insert(b.end(), magic, magic + 8);
      for (int i = 0, n = static_cast<int>(rng() % 64); i < n; ++i) b.push_back(static_cast<std::uint8_t>(rng() % 4 ? rng() % 8 : rng()));
      break;
    }
    case 11: {  // duplicate a chunk at the end
      if (b.size() < 2) break;
      const std::size_t at = pick(b.size());
      const std::size_t n = std::min(b.size() - at, std::size_t{1} + rng() % 64);
      Bytes chunk(b.begin() + static_cast<std::ptrdiff_t>(at), b.begin() + static_cast<std::ptrdiff_t>(at + n));
      b.insert(b.end(), chunk.begin(), chunk.end());
      break;
    }
  }
}

// VOLA_FUZZ_LAST_INPUT=FILE: each input is written to FILE before it runs, so that the
// one a crash (an abort, a heap error in a library) ended on is left there.
void run(const Bytes& b) {
  static const char* last = std::getenv("VOLA_FUZZ_LAST_INPUT");
  if (last && *last) {
    std::ofstream out(last, std::ios::binary | std::ios::trunc);
    out.write(reinterpret_cast<const char*>(b.data()), static_cast<std::streamsize>(b.size()));
  }
  LLVMFuzzerTestOneInput(b.data(), b.size());
}

bool write_file(const fs::path& path, const Bytes& bytes) {
  std::ofstream out(path, std::ios::binary);
  out.write(reinterpret_cast<const char*>(bytes.data()), static_cast<std::streamsize>(bytes.size()));
  return static_cast<bool>(out);
}

}  // namespace

int main(int argc, char** argv) {
  long mutations = 20000;
  double budget_seconds = 0.0;  // > 0: mutate until then, whatever `mutations` says
  std::uint64_t seed = 1;
  fs::path golden = default_golden();
  fs::path corpus;
  fs::path regressions;
  std::vector<fs::path> files;
  for (int i = 1; i < argc; ++i) {
    const std::string arg = argv[i];
    auto value = [&]() -> std::string {
      if (i + 1 >= argc) {
        std::cerr << arg << " needs a value\n";
        std::exit(2);
      }
      return argv[++i];
    };
    if (arg == "--mutations") mutations = std::stol(value());
    else if (arg == "--seconds") budget_seconds = std::stod(value());
    else if (arg == "--seed") seed = std::stoull(value());
    else if (arg == "--golden") golden = value();
    else if (arg == "--write-corpus") corpus = value();
    else if (arg == "--regressions") regressions = value();
    else files.push_back(arg);
  }

  if (!files.empty()) {  // replay given inputs, e.g. crash artifacts
    for (const auto& f : files) {
      std::ifstream in(f, std::ios::binary);
      if (!in) {
        std::cerr << "cannot open " << f << "\n";
        return 2;
      }
      const Bytes b{std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
      std::cout << "replaying " << f << " (" << b.size() << " bytes)\n";
      run(b);
    }
    return 0;
  }

  std::vector<vola_fuzz::Seed> seeds = vola_fuzz::synthetic_seeds();
  if (!regressions.empty()) {
    if (!fs::is_directory(regressions)) {
      std::cerr << "no regressions folder " << regressions << "\n";
      return 1;
    }
    for (const auto& entry : fs::directory_iterator(regressions)) {
      std::ifstream in(entry.path(), std::ios::binary);
      seeds.push_back({std::string("regression_") + entry.path().filename().string(),
                       Bytes{std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()}});
    }
  }
  const bool have_golden = fs::is_directory(golden);
  if (have_golden) {
    auto g = vola_fuzz::golden_seeds(golden);
    seeds.insert(seeds.end(), g.begin(), g.end());
  }

  if (!corpus.empty()) {
    fs::create_directories(corpus);
    std::size_t written = 0;
    for (const auto& s : seeds) {
      if (s.bytes.size() > kBigSeed) continue;  // libFuzzer runs best on small inputs
      if (!write_file(corpus / s.name, s.bytes)) {
        std::cerr << "cannot write " << corpus / s.name << "\n";
        return 1;
      }
      ++written;
    }
    std::cout << "wrote " << written << " seeds to " << corpus << (have_golden ? "" : " (no golden folder)") << "\n";
    return 0;
  }

  if (!have_golden) {
    if (std::getenv("CI")) {
      std::cerr << "golden folder " << golden << " is missing (CI is set; set VOLA_SHARED)\n";
      return 1;
    }
    std::cout << "golden folder " << golden << " is missing: skipped (set VOLA_SHARED)\n";
    return 77;
  }

  const auto start = std::chrono::steady_clock::now();
  for (const auto& s : seeds) run(s.bytes);

  std::vector<std::size_t> small;
  for (std::size_t i = 0; i < seeds.size(); ++i)
    if (seeds[i].bytes.size() <= kBigSeed) small.push_back(i);
  std::mt19937_64 rng(seed);
  long done = 0;
  for (std::size_t i = 0; i < seeds.size(); ++i) {
    if (seeds[i].bytes.size() <= kBigSeed) continue;
    for (int k = 0; k < kBigSeedMutations; ++k, ++done) {
      Bytes b = seeds[i].bytes;
      mutate_once(b, rng);
      run(b);
    }
  }
  auto more = [&] {
    if (budget_seconds <= 0.0) return done < mutations;
    return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count() < budget_seconds;
  };
  for (; more(); ++done) {
    Bytes b = seeds[small[rng() % small.size()]].bytes;
    for (int k = 0, n = 1 + static_cast<int>(rng() % 3); k < n; ++k) mutate_once(b, rng);
    run(b);
  }
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  const auto& stats = vola_fuzz::stats();
  std::cout << "replayed " << seeds.size() << " seeds and " << done << " mutations (seed " << seed << ") in "
            << seconds << " s: " << stats.parsed << " parsed, " << stats.refused << " refused" << std::endl;  // before LSan at exit
  // Both outcomes must occur, or the mutations are not reaching the reader.
  if (stats.parsed == 0 || stats.refused == 0) {
    std::cerr << "the replay did not exercise both accepted and refused inputs\n";
    return 1;
  }
  return 0;
}
