// Probabilistic scan insertion, vola against OctoMap 1.9.7 (Debian's liboctomap-dev), on
// the same scans in one process: vola::map::OccupancyMap::insert_scan (1 and 2 threads)
// and octomap::OcTree::insertPointCloud (OctoMap's defaults: hit 0.7, miss 0.4, clamping
// 0.1192/0.971; discretize off, lazy evaluation off), fresh maps each repetition, the
// median of --reps. Each scan is read just before it is inserted and freed after, as a
// robot gets them, so memory holds one scan at a time; the clock runs only around the
// insertion (for OctoMap, after the conversion to its float point cloud). Then, from the last repetition's maps:
//   - files: OctoMap .ot (probabilities) and .bt (max likelihood, pruned) against vola's
//     state map with log-odds and without (the two bits per voxel), compressed;
//   - decisions: occupied / free / unknown at voxel centres, over every voxel either map
//     knows (OctoMap's pruned leaves expanded, at most 4096 sampled voxels each).
// `--only vola|octomap` inserts with one peer alone and prints the process's peak memory
// (getrusage), for whole-process memory figures (bench/map_peers.sh runs both).
//
//   vola_map_peers SCANLIST --voxel-size R [--max-range M] [--reps 3] [--only vola|octomap [--threads N]] [--out DIR]
#include <octomap/OcTree.h>
#include <sys/resource.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <random>
#include <string>
#include <vector>

#include "vola/file.hpp"
#include "vola/io/input.hpp"
#include "vola/map/occupancy_map.hpp"
#include "vola/map/scan_list.hpp"
#include "vola/map/state_map.hpp"

namespace fs = std::filesystem;
using Clock = std::chrono::steady_clock;

namespace {

struct Scan {
  std::vector<double> world;  // x y z per point
  vola::Point origin;
};

struct Args {
  std::string list, only, out = ".";
  double voxel = 0.1, max_range = 0.0;
  int reps = 3;
  unsigned threads = 0;  // vola's threads with --only (0: all)
};

Args parse(int argc, char** argv) {
  Args a;
  for (int i = 1; i < argc; ++i) {
    const std::string arg = argv[i];
    const auto value = [&] {
      if (i + 1 >= argc) throw std::runtime_error(arg + " needs a value");
      return std::string(argv[++i]);
    };
    if (arg == "--voxel-size") a.voxel = std::stod(value());
    else if (arg == "--max-range") a.max_range = std::stod(value());
    else if (arg == "--reps") a.reps = std::stoi(value());
    else if (arg == "--only") a.only = value();
    else if (arg == "--threads") a.threads = static_cast<unsigned>(std::stoul(value()));
    else if (arg == "--out") a.out = value();
    else a.list = arg;
  }
  if (a.list.empty()) throw std::runtime_error("usage: vola_map_peers SCANLIST --voxel-size R [options]");
  return a;
}

// One scan in the world frame, read when it is about to be inserted: a robot gets its
// scans one at a time, so neither peer holds more than the scan it is inserting.
Scan read_scan(const vola::map::ScanEntry& e) {
  vola::io::InputOptions options;
  options.attributes = false;
  vola::io::Input in = vola::io::read_input(e.file, "auto", options);
  e.pose.apply(in.cloud.xyz);
  return {std::move(in.cloud.xyz), e.pose.translation};
}

double median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  return v[v.size() / 2];
}

double seconds_since(Clock::time_point start) { return std::chrono::duration<double>(Clock::now() - start).count(); }

// Insertion time only: each scan is read (and, for OctoMap, converted to its float point
// cloud) outside the clock and freed after it is inserted.
vola::map::OccupancyMap vola_insert(const std::vector<vola::map::ScanEntry>& scans, const Args& a, unsigned threads,
                                    double& seconds) {
  vola::map::OccupancyMap map(a.voxel);
  seconds = 0;
  for (const vola::map::ScanEntry& e : scans) {
    const Scan s = read_scan(e);
    const auto start = Clock::now();
    map.insert_scan(s.world, s.origin, a.max_range, threads);
    seconds += seconds_since(start);
  }
  return map;
}

std::unique_ptr<octomap::OcTree> octomap_insert(const std::vector<vola::map::ScanEntry>& scans, const Args& a,
                                                double& seconds) {
  auto tree = std::make_unique<octomap::OcTree>(a.voxel);
  seconds = 0;
  for (const vola::map::ScanEntry& e : scans) {
    octomap::Pointcloud cloud;
    vola::Point o{};
    {
      const Scan s = read_scan(e);
      cloud.reserve(s.world.size() / 3);
      for (std::size_t p = 0; p + 2 < s.world.size(); p += 3)
        cloud.push_back(static_cast<float>(s.world[p]), static_cast<float>(s.world[p + 1]),
                        static_cast<float>(s.world[p + 2]));
      o = s.origin;
    }
    const auto start = Clock::now();
    tree->insertPointCloud(cloud, octomap::point3d(static_cast<float>(o[0]), static_cast<float>(o[1]),
                                                   static_cast<float>(o[2])),
                           a.max_range > 0 ? a.max_range : -1.0, false, false);
    seconds += seconds_since(start);
  }
  return tree;
}

// The process's CPU time (all threads, user and system), robust to a shared machine.
double cpu_seconds() {
  rusage usage{};
  getrusage(RUSAGE_SELF, &usage);
  const auto s = [](const timeval& t) { return static_cast<double>(t.tv_sec) + 1e-6 * static_cast<double>(t.tv_usec); };
  return s(usage.ru_utime) + s(usage.ru_stime);
}

long peak_rss_mib() {
  rusage usage{};
  getrusage(RUSAGE_SELF, &usage);
  return usage.ru_maxrss / 1024;
}

std::uintmax_t write_size(const vola::Tree& tree, const std::string& path) {
  vola::WriteOptions options;
  options.compress = true;
  vola::write(tree, path, options);
  return fs::file_size(path);
}

// The decision at every voxel either map knows; OctoMap's coarse leaves are expanded (at
// most 4096 random voxels each).
void compare_decisions(const vola::map::OccupancyMap& map, const octomap::OcTree& tree) {
  std::vector<vola::map::VoxelIndex> query;
  map.for_each([&](const vola::map::VoxelIndex& v, float) { query.push_back(v); });
  const double r = map.voxel_size();
  std::mt19937_64 rng(1);
  for (auto it = tree.begin_leafs(); it != tree.end_leafs(); ++it) {
    const double size = it.getSize();
    const auto n = static_cast<std::int64_t>(std::llround(size / r));
    const octomap::point3d c = it.getCoordinate();
    const auto first = [&](float centre) { return static_cast<std::int64_t>(std::floor((centre - size / 2) / r + 0.5)); };
    const std::int64_t x0 = first(c.x()), y0 = first(c.y()), z0 = first(c.z());
    const auto add = [&](std::int64_t i, std::int64_t j, std::int64_t k) {
      query.push_back({static_cast<std::int32_t>(x0 + i), static_cast<std::int32_t>(y0 + j),
                       static_cast<std::int32_t>(z0 + k)});
    };
    if (n * n * n <= 4096) {
      for (std::int64_t i = 0; i < n; ++i)
        for (std::int64_t j = 0; j < n; ++j)
          for (std::int64_t k = 0; k < n; ++k) add(i, j, k);
    } else {
      std::uniform_int_distribution<std::int64_t> pick(0, n - 1);
      for (int s = 0; s < 4096; ++s) add(pick(rng), pick(rng), pick(rng));
    }
  }
  std::sort(query.begin(), query.end());
  query.erase(std::unique(query.begin(), query.end()), query.end());
  std::uint64_t same = 0, confusion[3][3] = {};
  for (const auto& v : query) {
    const auto lo = map.log_odds(v);
    const int ours = !lo ? 0 : map.occupied(*lo) ? 2 : 1;
    const octomap::OcTreeNode* node = tree.search((v.i + 0.5) * r, (v.j + 0.5) * r, (v.k + 0.5) * r);
    const int theirs = !node ? 0 : tree.isNodeOccupied(node) ? 2 : 1;
    ++confusion[ours][theirs];
    same += ours == theirs;
  }
  std::printf("decisions: %llu voxel centres, %.4f%% the same (vola rows, OctoMap columns: unknown free occupied)\n",
              static_cast<unsigned long long>(query.size()), 100.0 * static_cast<double>(same) / query.size());
  const char* names[] = {"unknown", "free", "occupied"};
  for (int i = 0; i < 3; ++i)
    std::printf("  %-9s %12llu %12llu %12llu\n", names[i], static_cast<unsigned long long>(confusion[i][0]),
                static_cast<unsigned long long>(confusion[i][1]), static_cast<unsigned long long>(confusion[i][2]));
}

}  // namespace

int main(int argc, char** argv) try {
  const Args a = parse(argc, argv);
  const std::vector<vola::map::ScanEntry> scans = vola::map::read_scan_list(a.list);
  std::size_t points = 0;
  for (const vola::map::ScanEntry& e : scans) points += read_scan(e).world.size() / 3;
  std::printf("scans: %zu, %zu points, voxel %g, max range %g, OctoMap %s\n", scans.size(), points, a.voxel, a.max_range,
              VOLA_OCTOMAP_VERSION);
  if (!a.only.empty()) {
    const long before = peak_rss_mib();
    const double cpu_before = cpu_seconds();
    double seconds = 0;
    std::size_t bytes = 0;
    if (a.only == "vola") bytes = vola_insert(scans, a, a.threads, seconds).memory_bytes();
    else if (a.only == "octomap") bytes = octomap_insert(scans, a, seconds)->memoryUsage();
    else throw std::runtime_error("--only vola or octomap");
    std::printf("%s alone: %.3f s (process CPU %.3f s, reading included), map %.1f MiB, process peak %ld MiB (%ld MiB "
                "before inserting)\n",
                a.only.c_str(), seconds, cpu_seconds() - cpu_before, static_cast<double>(bytes) / (1 << 20),
                peak_rss_mib(), before);
    return 0;
  }
  std::vector<double> one, two, octo;
  vola::map::OccupancyMap map(a.voxel);
  std::unique_ptr<octomap::OcTree> tree;
  for (int r = 0; r < a.reps; ++r) {
    double s = 0;
    vola_insert(scans, a, 1, s);
    one.push_back(s);
    map = vola_insert(scans, a, 2, s);
    two.push_back(s);
    tree = octomap_insert(scans, a, s);
    octo.push_back(s);
  }
  const double p = static_cast<double>(points);
  std::printf("insert (median of %d): vola 1 thread %.3f s (%.2f M points/s), 2 threads %.3f s (%.2f M points/s), "
              "OctoMap %.3f s (%.3f M points/s)\n",
              a.reps, median(one), p / median(one) / 1e6, median(two), p / median(two) / 1e6, median(octo),
              p / median(octo) / 1e6);
  std::printf("speed: vola 1 thread %.1fx OctoMap, 2 threads %.1fx\n", median(octo) / median(one),
              median(octo) / median(two));
  std::printf("map: vola %zu known voxels in %zu blocks, %.1f MiB; OctoMap %zu leaves, %.1f MiB\n", map.size(),
              map.block_count(), map.memory_bytes() / 1048576.0, tree->getNumLeafNodes(), tree->memoryUsage() / 1048576.0);

  compare_decisions(map, *tree);  // before writeBinary, which prunes the tree
  fs::create_directories(a.out);
  const std::string ot = a.out + "/octomap.ot", bt = a.out + "/octomap.bt";
  tree->write(ot);
  tree->writeBinary(bt);
  vola::Tree state = vola::map::freeze(map);
  const auto with_odds = write_size(state, a.out + "/vola_state.vol");
  state.attributes().clear();
  const auto two_bits = write_size(state, a.out + "/vola_two_bits.vol");
  const auto ot_bytes = fs::file_size(ot), bt_bytes = fs::file_size(bt);
  std::printf("files: vola with log-odds %ju B vs OctoMap .ot %ju B (%.3f of it); vola two bits %ju B vs .bt %ju B "
              "(%.3f of it)\n",
              with_odds, ot_bytes, static_cast<double>(with_odds) / ot_bytes, two_bits, bt_bytes,
              static_cast<double>(two_bits) / bt_bytes);
  return 0;
} catch (const std::exception& e) {
  std::fprintf(stderr, "vola_map_peers: %s\n", e.what());
  return 1;
}
