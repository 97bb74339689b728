// vola against its peers on the shared benchmark inputs (../shared/data/bench/README.md):
// OpenVDB 10 MaskGrid and BoolGrid through a ValueAccessor, OctoMap 1.9 OcTree.
//
// Everything runs single-threaded in this one process on the same int16 point arrays, and
// each figure is the median of --reps repetitions. For each set we measure
//   insert   : points -> structure (vola: build_from_voxels from the point array: key
//              encoding, radix sort, unique, level emission; the peers: one insertion per point)
//   memory   : bytes per occupied voxel as the structure reports it (vola: Tree::memory_bytes(),
//              rank directory included; OpenVDB: Grid::memUsage(); OctoMap: memoryUsage())
//   lookup   : random occupancy queries (half hits, half misses); the hit counts must agree
//   iterate  : visit every occupied voxel summing its coordinates; counts and sums must agree
//   file     : bits per occupied voxel on disk (.vol plain and zstd, .vdb, .bt, and xz -9 of each)
// and print one markdown table per set plus the project's targets with PASS/MISS.
//
// Usage: vola_peers [--data DIR] [--reps N] [--tmp DIR] [--sets surface,uniform]
//   DIR defaults to $VOLA_SHARED/data/bench, else ../shared/data/bench, else the shared folder
//   next to the source tree.
// Exit status: 0 when every implementation agrees on every count (targets may be missed),
// 1 on a disagreement or an error.

#include <openvdb/openvdb.h>
#include <openvdb/io/File.h>
#include <octomap/OcTree.h>

#include <algorithm>
#include <chrono>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <functional>
#include <malloc.h>
#include <iostream>
#include <optional>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

#include "vola/builder.hpp"
#include "vola/file.hpp"
#include "vola/tree.hpp"
#include "bench_data.hpp"

namespace fs = std::filesystem;

namespace {

constexpr int kDepth = 5;  // 4^5 = 1024 voxels per axis: the benchmark grid

using vola_bench::Points;
using vola_bench::read_points;

// ---------------------------------------------------------------------------------------
// Timing: the median of `reps` runs of f(), which returns nothing; seconds.
double seconds_since(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

double median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  const std::size_t n = v.size();
  return n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
}

// VOLA_BENCH_VERBOSE=1 prints every repetition's time on stderr.
const bool kVerbose = std::getenv("VOLA_BENCH_VERBOSE") != nullptr;

// Results must survive the optimiser: every loop feeds a checksum that is printed.
template <class T>
void keep(const T& value) {
  asm volatile("" : : "g"(&value) : "memory");
}

std::uintmax_t file_bytes(const fs::path& p) { return fs::exists(p) ? fs::file_size(p) : 0; }

bool have_xz() { return std::system("command -v xz >/dev/null 2>&1") == 0; }

// xz -9 of a file (kept beside it as .xz); 0 when xz is missing or fails.
std::uintmax_t xz_bytes(const fs::path& p) {
  static const bool available = have_xz();
  if (!available || !fs::exists(p)) return 0;
  const std::string cmd = "xz -9 -k -f -T1 '" + p.string() + "'";
  if (std::system(cmd.c_str()) != 0) return 0;
  const fs::path out = p.string() + ".xz";
  const auto size = file_bytes(out);
  fs::remove(out);
  return size;
}

// --- The implementations --------------------------------------------------------------
// The hot loops are [[gnu::flatten]]: everything they call from headers is inlined into
// them. Without it g++ 12 leaves OpenVDB's InternalNode::setValueAndCache out of line
// inside a virtual member and MaskGrid insertion runs 3x slower (20 vs 60 M points/s on
// the surface set), far below the published figure; every implementation gets the same.
#define VOLA_HOT [[gnu::flatten]]
// Each one owns its structure; the driver times build / lookup / iterate, interleaving the
// implementations repetition by repetition so that a slow spell of the machine hits all of
// them alike (the ratios are what we report).
struct FileSize {
  std::string kind;
  std::uintmax_t bytes = 0;
  std::uintmax_t xz_bytes = 0;
};

class Impl {
 public:
  explicit Impl(std::string name) : name_(std::move(name)) {}
  virtual ~Impl() = default;
  const std::string& name() const { return name_; }
  virtual void clear() = 0;                      // untimed: frees the previous build
  virtual void build(const Points& pts) = 0;     // timed: every point inserted
  virtual std::uint64_t voxels() const = 0;
  virtual std::size_t memory_bytes() const = 0;
  virtual std::uint64_t lookup(const Points& queries) const = 0;  // hit count
  virtual void iterate(std::uint64_t& count, std::uint64_t& coord_sum) const = 0;
  // Last: OctoMap's writeBinary prunes the tree it writes.
  virtual std::vector<FileSize> files(const fs::path& dir, const std::string& stem) = 0;

 private:
  std::string name_;
};

// --- vola ---------------------------------------------------------------------------------
class VolaImpl final : public Impl {
 public:
  VolaImpl() : Impl("vola Tree (depth 5)") {}
  void clear() override { tree_ = vola::Tree(); }
  VOLA_HOT void build(const Points& pts) override {
    // The int16 -> Voxel conversion is timed too: the build starts from the same point
    // array the peers insert from.
    const std::size_t n = pts.size();
    std::vector<vola::Voxel> voxels(n);
    for (std::size_t i = 0; i < n; ++i)
      voxels[i] = vola::Voxel{static_cast<std::uint32_t>(pts.xyz[3 * i]), static_cast<std::uint32_t>(pts.xyz[3 * i + 1]),
                              static_cast<std::uint32_t>(pts.xyz[3 * i + 2])};
    tree_ = vola::build_from_voxels(voxels, kDepth);
  }
  std::uint64_t voxels() const override { return tree_.voxel_count(); }
  std::size_t memory_bytes() const override { return tree_.memory_bytes(); }
  VOLA_HOT std::uint64_t lookup(const Points& queries) const override {
    const std::size_t nq = queries.size();
    const std::int16_t* q = queries.xyz.data();
    std::uint64_t hits = 0;
    for (std::size_t i = 0; i < nq; ++i)
      hits += tree_.contains(static_cast<std::uint32_t>(q[3 * i]), static_cast<std::uint32_t>(q[3 * i + 1]),
                             static_cast<std::uint32_t>(q[3 * i + 2]));
    return hits;
  }
  VOLA_HOT void iterate(std::uint64_t& count, std::uint64_t& sum) const override {
    std::uint64_t c = 0, s = 0;
    tree_.for_each_voxel([&](const vola::Voxel& v) {
      ++c;
      s += std::uint64_t{v.x} + v.y + v.z;
    });
    count = c;
    sum = s;
  }
  std::vector<FileSize> files(const fs::path& dir, const std::string& stem) override {
    std::vector<FileSize> out;
    const fs::path vol = dir / (stem + ".vol");
    vola::write(tree_, vol.string());
    out.push_back({".vol", file_bytes(vol), xz_bytes(vol)});
    fs::remove(vol);
    if (vola::compression_available()) {
      vola::WriteOptions wo;
      wo.compress = true;
      const fs::path volz = dir / (stem + ".zstd.vol");
      vola::write(tree_, volz.string(), wo);
      // Round trip: the compressed file must hold the same voxels.
      const vola::Tree back = vola::read(volz.string());
      if (back.voxel_count() != tree_.voxel_count() || back.keys() != tree_.keys())
        throw std::runtime_error("compressed .vol does not read back to the same tree");
      out.push_back({".vol zstd (WriteOptions.compress)", file_bytes(volz), 0});
      fs::remove(volz);
    }
    return out;
  }

 private:
  vola::Tree tree_;
};

// --- OpenVDB ---------------------------------------------------------------------------
template <class GridT>
class VdbImpl final : public Impl {
 public:
  explicit VdbImpl(std::string name) : Impl(std::move(name)) {}
  void clear() override { grid_.reset(); }
  VOLA_HOT void build(const Points& pts) override {
    const std::size_t n = pts.size();
    const std::int16_t* p = pts.xyz.data();
    grid_ = GridT::create();
    auto acc = grid_->getAccessor();
    for (std::size_t i = 0; i < n; ++i) {
      const openvdb::Coord c(p[3 * i], p[3 * i + 1], p[3 * i + 2]);
      if constexpr (std::is_same_v<typename GridT::ValueType, bool>)
        acc.setValueOn(c, true);
      else
        acc.setValueOn(c);
    }
  }
  std::uint64_t voxels() const override { return grid_->activeVoxelCount(); }
  std::size_t memory_bytes() const override { return grid_->memUsage(); }
  VOLA_HOT std::uint64_t lookup(const Points& queries) const override {
    const std::size_t nq = queries.size();
    const std::int16_t* q = queries.xyz.data();
    auto acc = grid_->getConstAccessor();
    std::uint64_t hits = 0;
    for (std::size_t i = 0; i < nq; ++i) hits += acc.isValueOn(openvdb::Coord(q[3 * i], q[3 * i + 1], q[3 * i + 2]));
    return hits;
  }
  VOLA_HOT void iterate(std::uint64_t& count, std::uint64_t& sum) const override {
    std::uint64_t c = 0, s = 0;
    for (auto it = grid_->cbeginValueOn(); it; ++it) {
      if (!it.isVoxelValue()) throw std::runtime_error("unexpected active tile in " + name());
      const openvdb::Coord xyz = it.getCoord();
      ++c;
      s += static_cast<std::uint64_t>(xyz.x() + xyz.y() + xyz.z());
    }
    count = c;
    sum = s;
  }
  std::vector<FileSize> files(const fs::path& dir, const std::string& stem) override {
    const fs::path vdb = dir / (stem + "_" + GridT::gridType() + ".vdb");
    {
      openvdb::io::File file(vdb.string());  // default compression, as the published figures
      file.write(openvdb::GridCPtrVec{grid_});
      file.close();
    }
    FileSize f{".vdb", file_bytes(vdb), xz_bytes(vdb)};
    fs::remove(vdb);
    return {f};
  }

 private:
  typename GridT::Ptr grid_;
};

// --- OctoMap -----------------------------------------------------------------------------
class OctoImpl final : public Impl {
 public:
  OctoImpl() : Impl("OctoMap OcTree (resolution 1)") {}
  void clear() override { tree_.reset(); }
  // Voxel (x, y, z) is the cell whose centre is (x + 0.5, y + 0.5, z + 0.5).
  static float centre(std::int16_t v) { return static_cast<float>(v) + 0.5f; }
  VOLA_HOT void build(const Points& pts) override {
    const std::size_t n = pts.size();
    const std::int16_t* p = pts.xyz.data();
    tree_ = std::make_unique<octomap::OcTree>(1.0);
    for (std::size_t i = 0; i < n; ++i)
      tree_->updateNode(octomap::point3d(centre(p[3 * i]), centre(p[3 * i + 1]), centre(p[3 * i + 2])), true);
    voxels_ = 0;
  }
  std::uint64_t voxels() const override {
    if (voxels_ == 0) {
      std::uint64_t sum = 0;
      iterate(voxels_, sum);
    }
    return voxels_;
  }
  std::size_t memory_bytes() const override { return tree_->memoryUsage(); }
  VOLA_HOT std::uint64_t lookup(const Points& queries) const override {
    const std::size_t nq = queries.size();
    const std::int16_t* q = queries.xyz.data();
    std::uint64_t hits = 0;
    for (std::size_t i = 0; i < nq; ++i) {
      const octomap::OcTreeNode* node = tree_->search(centre(q[3 * i]), centre(q[3 * i + 1]), centre(q[3 * i + 2]));
      hits += node != nullptr && tree_->isNodeOccupied(node);
    }
    return hits;
  }
  // Occupied leaves; a pruned leaf of edge s stands for s^3 voxels, all visited.
  VOLA_HOT void iterate(std::uint64_t& count, std::uint64_t& sum) const override {
    std::uint64_t c = 0, s = 0;
    for (auto it = tree_->begin_leafs(), end = tree_->end_leafs(); it != end; ++it) {
      if (!tree_->isNodeOccupied(*it)) continue;
      const int e = static_cast<int>(it.getSize());
      const octomap::point3d mid = it.getCoordinate();  // centre of the leaf cube
      const float half = 0.5f * static_cast<float>(e);
      const int x0 = static_cast<int>(mid.x() - half), y0 = static_cast<int>(mid.y() - half),
                z0 = static_cast<int>(mid.z() - half);
      if (e == 1) {
        ++c;
        s += static_cast<std::uint64_t>(x0 + y0 + z0);
        continue;
      }
      for (int z = z0; z < z0 + e; ++z)
        for (int y = y0; y < y0 + e; ++y)
          for (int x = x0; x < x0 + e; ++x) {
            ++c;
            s += static_cast<std::uint64_t>(x + y + z);
          }
    }
    count = c;
    sum = s;
  }
  std::vector<FileSize> files(const fs::path& dir, const std::string& stem) override {
    const fs::path bt = dir / (stem + ".bt");
    {
      // writeBinary converts to maximum likelihood and prunes first; it also reports
      // progress on std::cout, which would break our tables.
      std::ostringstream chatter;
      std::streambuf* old = std::cout.rdbuf(chatter.rdbuf());
      const bool ok = tree_->writeBinary(bt.string());
      std::cout.rdbuf(old);
      if (!ok) throw std::runtime_error("OctoMap writeBinary failed");
    }
    FileSize f{".bt", file_bytes(bt), xz_bytes(bt)};
    fs::remove(bt);
    return {f};
  }

 private:
  std::unique_ptr<octomap::OcTree> tree_;
  mutable std::uint64_t voxels_ = 0;
};

struct Measure {
  std::string name;
  double insert_mps = 0;       // M input points / s
  double bytes_per_voxel = 0;  // memory
  double lookup_mps = 0;       // M queries / s
  double iterate_mvps = 0;     // M voxels / s
  std::vector<FileSize> files;
  std::uint64_t voxels = 0;     // occupied voxels the structure reports
  std::uint64_t hits = 0;       // lookups that found an occupied voxel
  std::uint64_t iterated = 0;   // voxels visited by the iteration
  std::uint64_t coord_sum = 0;  // sum of x + y + z over the iteration
};

struct Options {
  fs::path data;
  fs::path tmp;
  int reps = 5;
  std::vector<std::string> sets = {"surface", "uniform"};
  bool keep_heap = true;
};

// Runs f(impl index) `reps` times for each implementation, interleaved; returns the median
// seconds per implementation. `before` runs untimed ahead of each timed call. With `warm`,
// so does one untimed call of f: a structure's lookups are then timed with its data in the
// caches, as they would be when run back to back, and not after the previous
// implementation has evicted it (all four together are ~100-400 MB).
template <class F>
std::vector<double> interleaved_medians(std::size_t impls, int reps, const std::string& what,
                                        const std::vector<std::unique_ptr<Impl>>& all, F&& f, bool warm,
                                        const std::function<void(std::size_t)>& before = {}) {
  std::vector<std::vector<double>> t(impls);
  for (int r = -1; r < reps; ++r)  // r = -1: a warm-up round, not counted
    for (std::size_t i = 0; i < impls; ++i) {
      if (before) before(i);
      if (warm && r >= 0) f(i);
      const auto t0 = std::chrono::steady_clock::now();
      f(i);
      if (r >= 0) t[i].push_back(seconds_since(t0));
    }
  std::vector<double> med(impls);
  for (std::size_t i = 0; i < impls; ++i) {
    med[i] = median(t[i]);
    if (kVerbose) {
      std::cerr << all[i]->name() << " " << what << ":";
      for (const double s : t[i]) std::cerr << " " << s * 1e3 << " ms";
      std::cerr << "\n";
    }
  }
  return med;
}

std::vector<Measure> run_set(const Points& pts, const Points& queries, const Options& opt, const std::string& set) {
  std::vector<std::unique_ptr<Impl>> impls;
  impls.push_back(std::make_unique<VolaImpl>());
  impls.push_back(std::make_unique<VdbImpl<openvdb::MaskGrid>>("OpenVDB MaskGrid + ValueAccessor"));
  impls.push_back(std::make_unique<VdbImpl<openvdb::BoolGrid>>("OpenVDB BoolGrid + ValueAccessor"));
  impls.push_back(std::make_unique<OctoImpl>());
  const std::size_t k = impls.size();
  std::vector<Measure> ms(k);
  for (std::size_t i = 0; i < k; ++i) ms[i].name = impls[i]->name();

  const auto t_build = interleaved_medians(
      k, opt.reps, "insert", impls, [&](std::size_t i) { impls[i]->build(pts); }, false,
      [&](std::size_t i) { impls[i]->clear(); });
  for (std::size_t i = 0; i < k; ++i) {
    ms[i].insert_mps = static_cast<double>(pts.size()) / t_build[i] / 1e6;
    ms[i].voxels = impls[i]->voxels();
    ms[i].bytes_per_voxel = static_cast<double>(impls[i]->memory_bytes()) / static_cast<double>(ms[i].voxels);
  }
  const auto t_lookup = interleaved_medians(k, opt.reps, "lookup", impls, [&](std::size_t i) {
    const std::uint64_t hits = impls[i]->lookup(queries);
    keep(hits);
    ms[i].hits = hits;
  }, true);
  const auto t_iter = interleaved_medians(k, opt.reps, "iterate", impls, [&](std::size_t i) {
    std::uint64_t count = 0, sum = 0;
    impls[i]->iterate(count, sum);
    keep(sum);
    ms[i].iterated = count;
    ms[i].coord_sum = sum;
  }, true);
  for (std::size_t i = 0; i < k; ++i) {
    ms[i].lookup_mps = static_cast<double>(queries.size()) / t_lookup[i] / 1e6;
    ms[i].iterate_mvps = static_cast<double>(ms[i].iterated) / t_iter[i] / 1e6;
    ms[i].files = impls[i]->files(opt.tmp, set);
    impls[i]->clear();
  }
  return ms;
}

// --- Report ------------------------------------------------------------------------------
std::string fmt(double v) {
  if (v <= 0) return "-";
  char buf[64];
  if (v >= 100) std::snprintf(buf, sizeof buf, "%.0f", v);
  else if (v >= 10) std::snprintf(buf, sizeof buf, "%.1f", v);
  else if (v >= 0.1) std::snprintf(buf, sizeof buf, "%.2f", v);
  else std::snprintf(buf, sizeof buf, "%.3f", v);
  return buf;
}

double bits_per_voxel(std::uintmax_t bytes, std::uint64_t voxels) {
  return voxels ? 8.0 * static_cast<double>(bytes) / static_cast<double>(voxels) : 0.0;
}

void print_table(const std::string& set, const std::vector<Measure>& ms, std::uint64_t points) {
  std::cout << "\n### " << set << " set (" << points << " points, " << ms.front().voxels << " occupied voxels)\n\n";
  std::cout << "| " << set
            << " set | insert (M points/s) | memory (bytes/voxel) | random lookup (M/s) | iterate (M voxels/s) "
               "| file (bits/voxel) | file, xz -9 (bits/voxel) |\n";
  std::cout << "|---|---|---|---|---|---|---|\n";
  for (const auto& m : ms) {
    for (std::size_t f = 0; f < std::max<std::size_t>(1, m.files.size()); ++f) {
      const FileSize file = f < m.files.size() ? m.files[f] : FileSize{};
      if (f == 0)
        std::cout << "| " << m.name << " | " << fmt(m.insert_mps) << " | " << fmt(m.bytes_per_voxel) << " | "
                  << fmt(m.lookup_mps) << " | " << fmt(m.iterate_mvps);
      else
        std::cout << "| " << m.name << ", " << file.kind << " | | | |";
      std::cout << " | " << fmt(bits_per_voxel(file.bytes, m.voxels)) << (file.bytes ? " (" + file.kind + ")" : "")
                << " | " << fmt(bits_per_voxel(file.xz_bytes, m.voxels)) << " |\n";
    }
  }
}

struct Target {
  std::string what;
  double vola_value;
  double peer_value;  // 0 = an absolute target
  std::string peer_name;
  double ratio;  // vola / peer (or the absolute value)
  std::string goal;
  bool pass;
};

void print_targets(const std::string& set, const std::vector<Target>& targets) {
  std::cout << "\n| " << set << " set target | vola | peer | vola / peer | target | result |\n";
  std::cout << "|---|---|---|---|---|---|\n";
  for (const auto& t : targets)
    std::cout << "| " << t.what << " | " << fmt(t.vola_value) << " | "
              << (t.peer_value > 0 ? fmt(t.peer_value) + " (" + t.peer_name + ")" : "-") << " | "
              << (t.peer_value > 0 ? fmt(t.ratio) : "-") << " | " << t.goal << " | " << (t.pass ? "PASS" : "**MISS**")
              << " |\n";
  std::cout << "\n";
  for (const auto& t : targets)
    std::cout << "TARGET " << set << " | " << t.what << " | " << (t.peer_value > 0 ? "ratio " : "value ")
              << fmt(t.ratio) << " | " << t.goal << " | " << (t.pass ? "PASS" : "MISS") << "\n";
}

bool verify(const std::string& set, const std::vector<Measure>& ms) {
  bool ok = true;
  const Measure& ref = ms.front();
  std::cout << "\nChecks (" << set << "): ";
  for (const auto& m : ms) {
    if (m.voxels != ref.voxels || m.iterated != ref.voxels || m.coord_sum != ref.coord_sum || m.hits != ref.hits) {
      ok = false;
      std::cout << "\nMISMATCH " << m.name << ": voxels " << m.voxels << " iterated " << m.iterated << " coord sum "
                << m.coord_sum << " hits " << m.hits << " (vola: " << ref.voxels << ", " << ref.iterated << ", "
                << ref.coord_sum << ", " << ref.hits << ")";
    }
  }
  if (ok)
    std::cout << "all " << ms.size() << " implementations agree: " << ref.voxels << " voxels, coordinate sum "
              << ref.coord_sum << ", " << ref.hits << " hits out of the lookups\n";
  else
    std::cout << "\n";
  return ok;
}

const Measure& find(const std::vector<Measure>& ms, const std::string& prefix) {
  for (const auto& m : ms)
    if (m.name.rfind(prefix, 0) == 0) return m;
  throw std::logic_error("no measure " + prefix);
}

const FileSize* find_file(const Measure& m, const std::string& kind_prefix) {
  for (const auto& f : m.files)
    if (f.kind.rfind(kind_prefix, 0) == 0) return &f;
  return nullptr;
}

std::vector<Target> targets_for(const std::string& set, const std::vector<Measure>& ms) {
  const Measure& v = find(ms, "vola");
  const Measure& mask = find(ms, "OpenVDB MaskGrid");
  const Measure& oct = find(ms, "OctoMap");
  const std::string mg = "MaskGrid";
  std::vector<Target> t;
  if (set == "surface") {
    t.push_back({"build from the points (M points/s)", v.insert_mps, mask.insert_mps, mg,
                 v.insert_mps / mask.insert_mps, ">= 2", v.insert_mps >= 2 * mask.insert_mps});
  }
  const double mem_goal = set == "surface" ? 6.0 : 8.0;
  t.push_back({"memory incl. rank directory (bytes/voxel)", v.bytes_per_voxel, mask.bytes_per_voxel, mg,
               v.bytes_per_voxel / mask.bytes_per_voxel, set == "surface" ? "<= 1/6 = 0.167" : "<= 1/8 = 0.125",
               v.bytes_per_voxel * mem_goal <= mask.bytes_per_voxel});
  t.push_back({"random lookup (M/s)", v.lookup_mps, mask.lookup_mps, mg, v.lookup_mps / mask.lookup_mps, ">= 1.5",
               v.lookup_mps >= 1.5 * mask.lookup_mps});
  if (set != "surface") return t;
  t.push_back({"full iteration (M voxels/s)", v.iterate_mvps, mask.iterate_mvps, mg, v.iterate_mvps / mask.iterate_mvps,
               ">= 4", v.iterate_mvps >= 4 * mask.iterate_mvps});
  if (const FileSize* plain = find_file(v, ".vol")) {
    const double b = bits_per_voxel(plain->bytes, v.voxels);
    t.push_back({"file, uncompressed (bits/voxel)", b, 0, "", b, "<= 15", b <= 15});
  }
  if (const FileSize* z = find_file(v, ".vol zstd")) {
    const double b = bits_per_voxel(z->bytes, v.voxels);
    t.push_back({"file, zstd option (bits/voxel)", b, 0, "", b, "<= 5", b <= 5});
    const FileSize* bt = find_file(oct, ".bt");
    if (bt && bt->xz_bytes) {
      const double btxz = bits_per_voxel(bt->xz_bytes, oct.voxels);
      t.push_back({"file, zstd vs OctoMap .bt + xz -9 (bits/voxel)", b, btxz, ".bt xz -9", b / btxz,
                   "< 1 (context)", b < btxz});
    }
  } else {
    t.push_back({"file, zstd option (bits/voxel)", 0, 0, "", 0, "<= 5 (zstd not built)", false});
  }
  return t;
}

Options parse_args(int argc, char** argv) {
  Options o;
  o.data = vola_bench::default_data_dir();
  o.tmp = fs::temp_directory_path();
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    auto value = [&]() -> std::string {
      if (i + 1 >= argc) throw std::runtime_error(a + " needs a value");
      return argv[++i];
    };
    if (a == "--data") o.data = value();
    else if (a == "--reps") o.reps = std::max(1, std::stoi(value()));
    else if (a == "--tmp") o.tmp = value();
    else if (a == "--fresh-pages") o.keep_heap = false;
    else if (a == "--sets") {
      o.sets.clear();
      std::stringstream ss(value());
      for (std::string set; std::getline(ss, set, ',');) o.sets.push_back(set);
    } else if (a == "-h" || a == "--help") {
      std::cout << "usage: vola_peers [--data DIR] [--reps N] [--tmp DIR] [--sets surface,uniform] [--fresh-pages]\n"
                   "  --fresh-pages: let malloc return freed memory to the kernel (every build then pays\n"
                   "                 first-touch page faults, which are slow and erratic in some VMs)\n";
      std::exit(0);
    } else {
      throw std::runtime_error("unknown argument " + a);
    }
  }
  return o;
}

}  // namespace

int main(int argc, char** argv) try {
  const Options opt = parse_args(argc, argv);
  if (opt.keep_heap) {
    // Keep freed memory in the process (no mmap for big blocks, no trimming): from the
    // second build on, every implementation reuses pages it has already touched. On a VM
    // whose first touch of a page is slow and erratic (Firecracker here: 5x spreads in
    // OpenVDB's insertion rate), this measures the structures, not the hypervisor. The same
    // for all implementations; --fresh-pages turns it off.
    mallopt(M_MMAP_THRESHOLD, 1 << 30);
    mallopt(M_TRIM_THRESHOLD, -1);
  }
  openvdb::initialize();
  fs::create_directories(opt.tmp);
  std::cout << "## vola vs OpenVDB " << openvdb::getLibraryAbiVersionString() << " and OctoMap "
            << VOLA_OCTOMAP_VERSION << "\n\nSingle thread; each figure is the median of " << opt.reps
            << " repetitions after a warm-up round, the implementations interleaved repetition by repetition "
               "(lookups and iteration: each timed pass right after an untimed one on the same structure); "
            << (opt.keep_heap ? "freed memory kept in the process" : "fresh pages (--fresh-pages)") << "; data "
            << opt.data.string() << "; xz " << (have_xz() ? "found" : "not found: no xz column") << "; zstd "
            << (vola::compression_available() ? "built" : "not built") << ".\n";
  bool ok = true;
  for (const auto& set : opt.sets) {
    const Points pts = read_points(opt.data / (set + "_points_1e6.npy"));
    const Points queries = read_points(opt.data / (set + "_queries_1e6.npy"));
    const std::vector<Measure> ms = run_set(pts, queries, opt, set);
    print_table(set, ms, pts.size());
    ok = verify(set, ms) && ok;
    print_targets(set, targets_for(set, ms));
    std::cout.flush();
  }
  return ok ? 0 : 1;
} catch (const std::exception& e) {
  std::cerr << "vola_peers: " << e.what() << "\n";
  return 1;
}
