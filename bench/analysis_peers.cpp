// Connected components and dilation: vola_analysis against OpenVDB's
// tools::segmentActiveVoxels and tools::dilateActiveValues on the same voxels, in the
// same run (issue 4, point 4).
//
// The scene: one .vol tile (e.g. `vola convert pdal_autzen_trim.las tile.vol
// --voxel-size 1 --no-attributes`: a real survey), repeated side by side along x and y
// until it holds at least --voxels occupied voxels, a margin of --radius voxels left on
// every side so that neither library clips the dilation. vola holds it as a Tree,
// OpenVDB as a MaskGrid (its smallest grid: one bit per voxel in 8^3 leaves).
//
// Each operation runs --reps times (OpenVDB's segmentation --peer-reps times: it can take
// minutes), each time in a forked child, so that every run starts from the same heap and
// its memory can be measured alone:
//   time    the median wall time of the operation (single-threaded: OpenVDB's tools
//           run under a one-thread TBB limit, vola's are single-threaded; OpenVDB's
//           dilation is timed without the copy of the input grid it dilates in place);
//   peak    the child's peak RSS growth during the operation (VmHWM reset through
//           /proc/self/clear_refs just before it): working memory plus the result;
//   result  the bytes of the result structures as the libraries count them
//           (Tree::memory_bytes() + 4 bytes of label per voxel; Grid::memUsage() of
//           every segment / of the dilated grid).
// Every child runs under an address-space limit (--memory-limit GiB, default 3/4 of the
// memory available at start): segmentActiveVoxels gives every segment its own MaskGrid of
// about 0.3 MB (a root and a 32^3 internal node), so a scene of 1e5 components asks for
// ~30 GB, and without the limit the kernel's OOM killer ends the child (and may pick other
// processes on the machine). A child past the limit reports "over N GiB" instead.
// The results are checked against each other: the same number of components with
// the same sizes (6-connectivity, as segmentActiveVoxels joins face neighbours), and
// the same dilated voxel count (cube element = NN_FACE_EDGE_VERTEX).
//
// usage: vola_analysis_peers TILE.vol [--voxels N] [--radius R] [--reps K] [--peer-reps K]
//                            [--memory-limit GiB]
// Exit status 0 when both libraries agree (or OpenVDB ran out of memory), 1 otherwise.
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <functional>
#include <new>
#include <stdexcept>
#include <string>
#include <vector>

#include <openvdb/openvdb.h>
#include <openvdb/tools/LevelSetUtil.h>
#include <openvdb/tools/Morphology.h>
#include <tbb/global_control.h>

#include "vola/analysis/components.hpp"
#include "vola/analysis/morphology.hpp"
#include "vola/builder.hpp"
#include "vola/file.hpp"

namespace {

// A "Field:   123 kB" line of a /proc file, in KiB; -1 when absent.
long status_kib_of(const char* file, const char* field) {
  std::ifstream in(file);
  std::string line;
  while (std::getline(in, line))
    if (line.rfind(field, 0) == 0) return std::stol(line.substr(std::strlen(field)));
  return -1;
}

long status_kib(const char* field) { return status_kib_of("/proc/self/status", field); }

void reset_peak_rss() {
  std::ofstream clear("/proc/self/clear_refs");
  clear << "5";  // resets VmHWM to the current RSS (Linux >= 4.0)
}

struct Outcome {
  bool out_of_memory = false;  // the child hit --memory-limit
  double seconds = 0;
  double peak_mib = 0;
  double result_mib = 0;
  std::uint64_t check = 0;   // components: count; dilation: voxels
  std::uint64_t check2 = 0;  // components: sum of squared sizes
};

// Runs `op` in a child process and returns what it measured there.
constexpr int kOutOfMemoryExit = 3;

Outcome in_child(const std::function<Outcome()>& op, double limit_bytes) {
  int fd[2];
  if (pipe(fd) != 0) throw std::runtime_error("pipe");
  const pid_t pid = fork();
  if (pid == 0) {
    close(fd[0]);
    const rlimit limit{static_cast<rlim_t>(limit_bytes), static_cast<rlim_t>(limit_bytes)};
    setrlimit(RLIMIT_AS, &limit);
    reset_peak_rss();
    const long before = status_kib("VmRSS:");
    const auto t0 = std::chrono::steady_clock::now();
    // An exception must not unwind into main() here: the child would then run the
    // parent's remaining benchmarks itself. Report it and leave at once.
    Outcome r;
    try {
      r = op();
    } catch (const std::bad_alloc&) {
      _exit(kOutOfMemoryExit);
    } catch (const std::exception& e) {
      std::fprintf(stderr, "vola_analysis_peers: in a measured child: %s\n", e.what());
      _exit(1);
    }
    // An operation may time only its own part (it sets seconds); else the whole call.
    if (r.seconds == 0) r.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    r.peak_mib = static_cast<double>(status_kib("VmHWM:") - before) / 1024.0;
    if (write(fd[1], &r, sizeof r) != static_cast<ssize_t>(sizeof r)) _exit(1);
    _exit(0);
  }
  close(fd[1]);
  Outcome r;
  const bool ok = read(fd[0], &r, sizeof r) == static_cast<ssize_t>(sizeof r);
  close(fd[0]);
  int status = 0;
  waitpid(pid, &status, 0);
  if (!ok && WIFEXITED(status) && WEXITSTATUS(status) == kOutOfMemoryExit) {
    r.out_of_memory = true;
    return r;
  }
  if (WIFSIGNALED(status))
    throw std::runtime_error("a measured child was killed by signal " + std::to_string(WTERMSIG(status)));
  if (!ok || !WIFEXITED(status) || WEXITSTATUS(status) != 0) throw std::runtime_error("a measured child failed");
  return r;
}

// The median run of `reps` (by time); peak and result memory of that same run.
// A run out of memory ends the series: the next ones would only repeat it.
Outcome median_of(int reps, double limit_bytes, const std::function<Outcome()>& op) {
  std::vector<Outcome> runs;
  for (int i = 0; i < reps; ++i) {
    runs.push_back(in_child(op, limit_bytes));
    if (runs.back().out_of_memory) return runs.back();
  }
  for (const Outcome& r : runs)
    if (r.check != runs[0].check || r.check2 != runs[0].check2) throw std::runtime_error("runs disagree");
  std::sort(runs.begin(), runs.end(), [](const Outcome& a, const Outcome& b) { return a.seconds < b.seconds; });
  return runs[runs.size() / 2];
}

constexpr double kMiB = 1048576.0;
constexpr double kGiB = 1024.0 * kMiB;

}  // namespace

int main(int argc, char** argv) try {
  if (argc < 2) {
    std::fprintf(stderr,
                 "usage: %s TILE.vol [--voxels N] [--radius R] [--reps K] [--peer-reps K] [--memory-limit GiB]\n",
                 argv[0]);
    return 2;
  }
  std::uint64_t target = 10'000'000;
  int radius = 1, reps = 5, peer_reps = -1;
  double limit_gib = 0.75 * static_cast<double>(status_kib_of("/proc/meminfo", "MemAvailable:")) / (1024.0 * 1024.0);
  for (int i = 2; i + 1 < argc; i += 2) {
    if (!std::strcmp(argv[i], "--voxels")) target = std::stoull(argv[i + 1]);
    else if (!std::strcmp(argv[i], "--radius")) radius = std::stoi(argv[i + 1]);
    else if (!std::strcmp(argv[i], "--reps")) reps = std::stoi(argv[i + 1]);
    else if (!std::strcmp(argv[i], "--peer-reps")) peer_reps = std::stoi(argv[i + 1]);
    else if (!std::strcmp(argv[i], "--memory-limit")) limit_gib = std::stod(argv[i + 1]);
    else throw std::invalid_argument(std::string("unknown option ") + argv[i]);
  }
  if (peer_reps < 0) peer_reps = reps;
  if (radius < 1 || reps < 1 || peer_reps < 1) throw std::invalid_argument("--radius and --reps must be >= 1");
  if (!(limit_gib > 0)) throw std::invalid_argument("--memory-limit must be > 0 GiB");
  const double limit_bytes = limit_gib * kGiB;

  const vola::Tree tile = vola::read(argv[1]);
  if (tile.voxel_count() == 0) throw std::invalid_argument(std::string(argv[1]) + " has no voxels");
  std::uint32_t ext[3] = {0, 0, 0};
  std::vector<vola::Voxel> base;
  tile.for_each_voxel([&](const vola::Voxel& v) {
    base.push_back(v);
    ext[0] = std::max(ext[0], v.x + 1);
    ext[1] = std::max(ext[1], v.y + 1);
    ext[2] = std::max(ext[2], v.z + 1);
  });
  const auto tiles = static_cast<std::uint32_t>(
      std::ceil(std::sqrt(static_cast<double>(target) / static_cast<double>(base.size()))));
  const auto margin = static_cast<std::uint32_t>(radius);
  const std::uint32_t needed = std::max({ext[0] * tiles, ext[1] * tiles, ext[2]}) + 2 * margin;
  int depth = 1;
  while (vola::side_of(depth) < needed) ++depth;
  std::vector<vola::Key> keys;
  keys.reserve(base.size() * tiles * tiles);
  for (std::uint32_t ty = 0; ty < tiles; ++ty)
    for (std::uint32_t tx = 0; tx < tiles; ++tx)
      for (const vola::Voxel& v : base)
        keys.push_back(vola::encode(margin + v.x + tx * ext[0], margin + v.y + ty * ext[1], margin + v.z));
  const vola::Tree scene = vola::build_from_keys(std::move(keys), depth);

  openvdb::initialize();
  openvdb::MaskGrid::Ptr grid = openvdb::MaskGrid::create();
  {
    auto acc = grid->getAccessor();
    scene.for_each_voxel([&](const vola::Voxel& v) {
      acc.setValueOn(openvdb::Coord(static_cast<int>(v.x), static_cast<int>(v.y), static_cast<int>(v.z)));
    });
  }
  if (grid->activeVoxelCount() != static_cast<openvdb::Index64>(scene.voxel_count()))
    throw std::runtime_error("the OpenVDB grid does not hold the scene's voxels");
  // Both single-threaded: vola's operations are, and this machine's 2 cores are shared.
  tbb::global_control one_thread(tbb::global_control::max_allowed_parallelism, 1);

  std::printf("scene: %s tiled %ux%u: %llu voxels at depth %d (%u^3 grid), vola %d runs each, medians\n", argv[1], tiles,
              tiles, static_cast<unsigned long long>(scene.voxel_count()), depth, vola::side_of(depth), reps);
  std::printf("OpenVDB %s, segmentation %d runs; every run in a child limited to %.1f GiB of address space\n",
              openvdb::getLibraryAbiVersionString(), peer_reps, limit_gib);
  std::printf("input structures: vola Tree %.1f MiB, OpenVDB MaskGrid %.1f MiB\n\n",
              static_cast<double>(scene.memory_bytes()) / kMiB, static_cast<double>(grid->memUsage()) / kMiB);

  const Outcome vola_cc = median_of(reps, limit_bytes, [&] {
    const auto labels = vola::analysis::label_components(scene, vola::analysis::Connectivity::faces);
    Outcome r;
    r.check = labels.components.size();
    for (const auto& c : labels.components) r.check2 += c.voxels * c.voxels;
    r.result_mib = static_cast<double>(labels.label.capacity() * 4 + labels.components.capacity() *
                                                                          sizeof(vola::analysis::Component)) / kMiB;
    return r;
  });
  const Outcome vdb_cc = median_of(peer_reps, limit_bytes, [&] {
    std::vector<openvdb::MaskGrid::Ptr> segments;
    openvdb::tools::segmentActiveVoxels(*grid, segments);
    Outcome r;
    r.check = segments.size();
    std::size_t bytes = 0;
    for (const auto& s : segments) {
      const openvdb::Index64 n = s->activeVoxelCount();
      r.check2 += n * n;
      bytes += s->memUsage();
    }
    r.result_mib = static_cast<double>(bytes) / kMiB;
    return r;
  });
  const Outcome vola_dil = median_of(reps, limit_bytes, [&] {
    const vola::Tree grown = vola::analysis::dilate(scene, radius, vola::analysis::Element::cube);
    Outcome r;
    r.check = grown.voxel_count();
    r.result_mib = static_cast<double>(grown.memory_bytes()) / kMiB;
    return r;
  });
  const Outcome vdb_dil = median_of(reps, limit_bytes, [&] {
    // dilateActiveValues works in place: the copy (a new grid beside the input, as vola
    // makes) counts in memory but not in time.
    openvdb::MaskGrid::Ptr copy = grid->deepCopy();
    const auto t0 = std::chrono::steady_clock::now();  // timed: the dilation, not the copy
    openvdb::tools::dilateActiveValues(copy->tree(), radius, openvdb::tools::NN_FACE_EDGE_VERTEX,
                                       openvdb::tools::IGNORE_TILES);
    Outcome r;
    r.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    r.check = copy->activeVoxelCount();
    r.result_mib = static_cast<double>(copy->memUsage()) / kMiB;
    return r;
  });

  if (vola_cc.out_of_memory || vola_dil.out_of_memory)
    throw std::runtime_error("vola ran out of memory: raise --memory-limit");
  std::printf("| operation | vola s | OpenVDB s | speed-up | vola peak MiB | OpenVDB peak MiB | vola result MiB | "
              "OpenVDB result MiB | check |\n|---|---|---|---|---|---|---|---|---|\n");
  const std::string over = "over " + std::to_string(static_cast<int>(limit_gib)) + " GiB";
  auto row = [&](const std::string& what, const Outcome& v, const Outcome& o, const std::string& check) {
    if (o.out_of_memory) {
      std::printf("| %s | %.3f | %s | - | %.1f | %s | %.1f | - | %s |\n", what.c_str(), v.seconds, over.c_str(),
                  v.peak_mib, over.c_str(), v.result_mib, check.c_str());
      return;
    }
    std::printf("| %s | %.3f | %.3f | %.2fx | %.1f | %.1f | %.1f | %.1f | %s |\n", what.c_str(), v.seconds, o.seconds,
                o.seconds / v.seconds, v.peak_mib, o.peak_mib, v.result_mib, o.result_mib, check.c_str());
  };
  // A peer out of memory has nothing to compare: vola's result stands alone.
  const bool cc_agree = vdb_cc.out_of_memory || (vola_cc.check == vdb_cc.check && vola_cc.check2 == vdb_cc.check2);
  const bool dil_agree = vdb_dil.out_of_memory || vola_dil.check == vdb_dil.check;
  auto check_text = [](std::uint64_t mine, const Outcome& peer, bool agree, const char* unit, const char* same) {
    if (peer.out_of_memory) return std::to_string(mine) + " " + unit + ", OpenVDB out of memory";
    return std::to_string(mine) + " " + unit + (agree ? same : " vs " + std::to_string(peer.check) + " DIFFER");
  };
  row("components, 6-connected", vola_cc, vdb_cc,
      check_text(vola_cc.check, vdb_cc, cc_agree, "components", ", same sizes"));
  row("dilate, cube radius " + std::to_string(radius), vola_dil, vdb_dil,
      check_text(vola_dil.check, vdb_dil, dil_agree, "voxels", ", same"));

  auto verdict = [&](const char* what, const Outcome& v, const Outcome& o) {
    if (o.out_of_memory) {
      std::printf("%s: OpenVDB needs %s: vola PASSES both (%.3f s, %.1f MiB peak)\n", what, over.c_str(), v.seconds,
                  v.peak_mib);
      return;
    }
    const bool fast = v.seconds <= o.seconds;
    const bool small = v.peak_mib <= 0.5 * o.peak_mib;
    std::printf("%s: time %s (at least as fast), peak memory %s (at most half: %.1f vs %.1f MiB)\n", what,
                fast ? "PASS" : "MISS", small ? "PASS" : "MISS", v.peak_mib, 0.5 * o.peak_mib);
  };
  std::printf("\n");
  verdict("components", vola_cc, vdb_cc);
  verdict("dilation  ", vola_dil, vdb_dil);
  return cc_agree && dil_agree ? 0 : 1;
} catch (const std::exception& e) {
  std::fprintf(stderr, "vola_analysis_peers: %s\n", e.what());
  return 1;
}
