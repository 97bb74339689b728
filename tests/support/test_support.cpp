#include "test_support.hpp"

#include <stdlib.h>  // mkdtemp

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <sstream>
#include <stdexcept>

#include <nlohmann/json.hpp>

#ifndef VOLA_SHARED_DEFAULT
#error "tests/CMakeLists.txt defines VOLA_SHARED_DEFAULT (the shared folder next to the sources)"
#endif

namespace vola_test {

// ---- Slow reference model ----

Xyz coarse_cell(const Xyz& v, int level, int depth) {
  const int shift = 2 * (depth - 1 - level);
  return {v[0] >> shift, v[1] >> shift, v[2] >> shift};
}

unsigned slow_local_index(const Xyz& v, int level, int depth) {
  const int k = depth - 1 - level;
  return ((v[0] >> (2 * k)) & 3u) + 4 * ((v[1] >> (2 * k)) & 3u) + 16 * ((v[2] >> (2 * k)) & 3u);
}

std::vector<unsigned> slow_path(const Xyz& v, int level, int depth) {
  std::vector<unsigned> path;
  for (int l = 0; l <= level; ++l) path.push_back(slow_local_index(v, l, depth));
  return path;
}

std::vector<std::uint64_t> slow_sparse_words(const XyzSet& voxels, int depth) {
  std::vector<std::uint64_t> words;
  for (int level = 0; level < depth; ++level) {
    // Key: the path of the block's parent cell (empty for the root block).
    std::map<std::vector<unsigned>, std::uint64_t> blocks;
    if (level == 0) blocks[{}] = 0;
    for (const Xyz& v : voxels) {
      std::vector<unsigned> parent = slow_path(v, level, depth);
      const unsigned bit = parent.back();
      parent.pop_back();
      blocks[parent] |= std::uint64_t{1} << bit;
    }
    for (const auto& [path, word] : blocks) words.push_back(word);
  }
  return words;
}

std::vector<std::uint64_t> slow_dense_words(const XyzSet& voxels, int depth) {
  std::vector<std::uint64_t> words;
  for (int level = 0; level < depth; ++level) {
    const std::uint64_t s = std::uint64_t{1} << (2 * (level + 1));
    const std::size_t begin = words.size();
    words.resize(begin + (std::size_t{1} << (6 * level)), 0);
    for (const Xyz& c : slow_cells(voxels, level, depth)) {
      const std::uint64_t index = c[0] + s * c[1] + s * s * c[2];
      words[begin + index / 64] |= std::uint64_t{1} << (index % 64);
    }
  }
  return words;
}

XyzSet slow_cells(const XyzSet& voxels, int level, int depth) {
  XyzSet cells;
  for (const Xyz& v : voxels) cells.insert(coarse_cell(v, level, depth));
  return cells;
}

std::vector<Xyz> slow_storage_order(const XyzSet& voxels, int depth) {
  std::vector<std::pair<std::vector<unsigned>, Xyz>> keyed;
  for (const Xyz& v : voxels) keyed.emplace_back(slow_path(v, depth - 1, depth), v);
  std::sort(keyed.begin(), keyed.end());
  std::vector<Xyz> out;
  for (const auto& [path, v] : keyed) out.push_back(v);
  return out;
}

std::vector<Xyz> voxel_sequence(const vola::Tree& tree) {
  std::vector<Xyz> out;
  tree.for_each_voxel([&](const vola::Voxel& v) { out.push_back(to_xyz(v)); });
  return out;
}

XyzSet voxel_set(const vola::Tree& tree) {
  auto seq = voxel_sequence(tree);
  std::sort(seq.begin(), seq.end());  // a sorted range builds the set in linear time
  return XyzSet(seq.begin(), seq.end());
}

// ---- Random voxel sets ----

const char* shape_name(Shape shape) {
  switch (shape) {
    case Shape::empty: return "empty";
    case Shape::single: return "single";
    case Shape::uniform: return "uniform";
    case Shape::clustered: return "clustered";
    case Shape::slab: return "slab";
    case Shape::full_block: return "full_block";
  }
  return "?";
}

std::string Scenario::describe() const {
  std::ostringstream s;
  s << "seed " << seed << ", depth " << depth << ", " << shape_name(shape) << ", " << voxels.size()
    << " voxels drawn";
  return s.str();
}

Xyz random_xyz(std::mt19937_64& rng, int depth) {
  std::uniform_int_distribution<std::uint32_t> d(0, vola::side_of(depth) - 1);
  return {d(rng), d(rng), d(rng)};
}

std::vector<Xyz> random_voxels(std::mt19937_64& rng, int depth, Shape shape, std::size_t count) {
  const std::uint32_t side = vola::side_of(depth);
  const std::uint32_t last = side - 1;
  std::vector<Xyz> out;
  switch (shape) {
    case Shape::empty:
      break;
    case Shape::single: {
      // The corners are the likeliest places for off-by-one errors.
      const int pick = static_cast<int>(rng() % 3);
      const Xyz v = pick == 0 ? Xyz{0, 0, 0} : pick == 1 ? Xyz{last, last, last} : random_xyz(rng, depth);
      out.assign(1 + rng() % 3, v);  // the same voxel, possibly several times
      break;
    }
    case Shape::uniform:
      for (std::size_t i = 0; i < count; ++i) out.push_back(random_xyz(rng, depth));
      out.push_back({0, 0, 0});
      out.push_back({last, last, last});
      break;
    case Shape::clustered: {
      const int clusters = 1 + static_cast<int>(rng() % 4);
      std::vector<Xyz> centres;
      for (int c = 0; c < clusters; ++c) centres.push_back(random_xyz(rng, depth));
      const double spread = std::max(1.0, side / 64.0);
      std::normal_distribution<double> g(0.0, spread);
      for (std::size_t i = 0; i < count; ++i) {
        const Xyz& c = centres[i % centres.size()];
        Xyz v;
        for (int a = 0; a < 3; ++a) {
          const double p = std::clamp(c[a] + g(rng), 0.0, static_cast<double>(last));
          v[a] = static_cast<std::uint32_t>(p);
        }
        out.push_back(v);
      }
      break;
    }
    case Shape::slab: {
      // A plane of constant z with a few lines: many voxels share upper levels.
      const std::uint32_t z = static_cast<std::uint32_t>(rng() % side);
      std::uniform_int_distribution<std::uint32_t> d(0, last);
      for (std::size_t i = 0; i < count; ++i) out.push_back({d(rng), d(rng), z});
      break;
    }
    case Shape::full_block: {
      // A solid cube aligned on 4: full 64-bit words (all bits set).
      const std::uint32_t edge = std::min<std::uint32_t>(side, 4u << (rng() % 2));
      const std::uint32_t blocks = side / edge;
      const std::uint32_t ox = static_cast<std::uint32_t>(rng() % blocks) * edge;
      const std::uint32_t oy = static_cast<std::uint32_t>(rng() % blocks) * edge;
      const std::uint32_t oz = static_cast<std::uint32_t>(rng() % blocks) * edge;
      for (std::uint32_t z = 0; z < edge; ++z)
        for (std::uint32_t y = 0; y < edge; ++y)
          for (std::uint32_t x = 0; x < edge; ++x) out.push_back({ox + x, oy + y, oz + z});
      break;
    }
  }
  std::shuffle(out.begin(), out.end(), rng);
  return out;
}

Scenario make_scenario(std::uint64_t seed) {
  Scenario s;
  s.seed = seed;
  s.depth = 1 + static_cast<int>(seed % 10);
  std::mt19937_64 rng(0x9E3779B97F4A7C15ull ^ (seed * 0x100000001B3ull));
  s.shape = static_cast<Shape>((seed / 10) % 6);
  // Log-uniform 1..20000: small sets (one block, a few blocks) as often as large ones.
  const double log_count = std::uniform_real_distribution<double>(0.0, std::log(20000.0))(rng);
  const std::size_t count = static_cast<std::size_t>(std::exp(log_count));
  s.voxels = random_voxels(rng, s.depth, s.shape, count);
  return s;
}

std::vector<std::uint64_t> seeds_for(Shape shape, int repeats) {
  std::vector<std::uint64_t> seeds;
  for (int r = 0; r < repeats; ++r)
    for (int depth = 1; depth <= 10; ++depth)
      seeds.push_back(60 * static_cast<std::uint64_t>(r) + 10 * static_cast<std::uint64_t>(shape) +
                      static_cast<std::uint64_t>(depth - 1));
  return seeds;
}

// ---- Files ----

std::vector<std::uint8_t> read_bytes(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw std::runtime_error("cannot open " + path.string());
  return std::vector<std::uint8_t>(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
}

void write_bytes(const fs::path& path, const std::vector<std::uint8_t>& bytes) {
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  out.write(reinterpret_cast<const char*>(bytes.data()), static_cast<std::streamsize>(bytes.size()));
  if (!out) throw std::runtime_error("cannot write " + path.string());
}

std::vector<std::uint8_t> gunzip_file(const fs::path& path) {
  if (path.string().find('\'') != std::string::npos)
    throw std::runtime_error("gunzip_file: quote in path " + path.string());
  const std::string command = "gzip -dc -- '" + path.string() + "'";
  std::FILE* pipe = ::popen(command.c_str(), "r");
  if (!pipe) throw std::runtime_error("cannot run " + command);
  std::vector<std::uint8_t> out;
  std::uint8_t buffer[1 << 16];
  std::size_t got;
  while ((got = std::fread(buffer, 1, sizeof buffer, pipe)) > 0) out.insert(out.end(), buffer, buffer + got);
  const int status = ::pclose(pipe);
  if (status != 0) throw std::runtime_error(command + " failed with status " + std::to_string(status));
  return out;
}

TempDir::TempDir() {
  std::string pattern = (fs::temp_directory_path() / "vola-test-XXXXXX").string();
  if (!::mkdtemp(pattern.data())) throw std::runtime_error("mkdtemp failed for " + pattern);
  path_ = pattern;
}

TempDir::~TempDir() {
  std::error_code ignored;
  fs::remove_all(path_, ignored);
}

std::uint32_t slow_crc32c(const std::uint8_t* bytes, std::size_t size) {
  std::uint32_t crc = ~0u;
  for (std::size_t i = 0; i < size; ++i) {
    crc ^= bytes[i];
    for (int b = 0; b < 8; ++b) crc = (crc >> 1) ^ ((crc & 1u) ? 0x82F63B78u : 0u);
  }
  return ~crc;
}

void reseal_extension(std::vector<std::uint8_t>& bytes, std::size_t at) {
  const std::size_t trailer = bytes.size() - 16;
  put_le<std::uint64_t>(bytes, trailer, bytes.size() - at);
  put_le<std::uint32_t>(bytes, trailer + 8, slow_crc32c(bytes.data() + at, trailer + 8 - at));
}

std::vector<std::uint8_t> raw_file(const RawHeader& h, const std::vector<std::uint64_t>& words) {
  std::vector<std::uint8_t> out(80 + 8 * words.size(), 0);
  put_le(out, 0, h.header_size);
  put_le(out, 4, h.version);
  put_le(out, 6, h.mode);
  put_le(out, 7, h.depth);
  put_le(out, 8, h.nbits);
  put_le(out, 12, h.crs);
  put_le(out, 16, h.lat);
  put_le(out, 24, h.lon);
  for (int i = 0; i < 6; ++i) put_le(out, 32 + 8 * static_cast<std::size_t>(i), h.bbox[i]);
  for (std::size_t i = 0; i < words.size(); ++i) put_le(out, 80 + 8 * i, words[i]);
  return out;
}

// ---- Golden folder ----

fs::path golden_dir() {
  const char* shared = std::getenv("VOLA_SHARED");
  const fs::path base = shared && *shared ? fs::path(shared) : fs::path(VOLA_SHARED_DEFAULT);
  return base / "golden";
}

std::vector<GoldenCase> read_manifest(const fs::path& golden) {
  std::ifstream in(golden / "MANIFEST.tsv");
  if (!in) throw std::runtime_error("cannot open " + (golden / "MANIFEST.tsv").string());
  auto split = [](const std::string& line) {
    std::vector<std::string> fields;
    std::stringstream s(line);
    std::string field;
    while (std::getline(s, field, '\t')) fields.push_back(field);
    return fields;
  };
  std::string line;
  std::getline(in, line);
  const auto header = split(line);
  auto column = [&](const std::string& name) {
    const auto it = std::find(header.begin(), header.end(), name);
    if (it == header.end()) throw std::runtime_error("MANIFEST.tsv has no column " + name);
    return static_cast<std::size_t>(it - header.begin());
  };
  const std::size_t c_case = column("case"), c_depth = column("depth"), c_mode = column("mode"),
                    c_nbits = column("nbits"), c_crs = column("crs"), c_npoints = column("npoints"),
                    c_nvoxels = column("nvoxels"), c_file = column("vol_file"), c_size = column("vol_size");
  std::vector<GoldenCase> cases;
  while (std::getline(in, line)) {
    if (line.empty()) continue;
    const auto f = split(line);
    if (f.size() != header.size()) throw std::runtime_error("MANIFEST.tsv: malformed line: " + line);
    GoldenCase c;
    c.name = f[c_case];
    c.depth = std::stoi(f[c_depth]);
    c.mode = std::stoi(f[c_mode]);
    c.nbits = std::stoi(f[c_nbits]);
    c.crs = static_cast<std::uint32_t>(std::stoul(f[c_crs]));
    c.npoints = std::stoul(f[c_npoints]);
    c.nvoxels = std::stoul(f[c_nvoxels]);
    c.vol_file = f[c_file];
    if (f[c_size] != "-") c.vol_size = std::stoull(f[c_size]);
    cases.push_back(c);
  }
  return cases;
}

std::vector<std::uint8_t> golden_file_bytes(const fs::path& golden, const GoldenCase& c) {
  const fs::path file = golden / c.name / c.vol_file;
  if (file.extension() == ".gz") return gunzip_file(file);
  return read_bytes(file);
}

XyzSet read_voxel_list(const fs::path& path) {
  std::ifstream in(path);
  if (!in) throw std::runtime_error("cannot open " + path.string());
  XyzSet out;
  std::string line;
  while (std::getline(in, line)) {
    if (line.empty()) continue;
    std::istringstream s(line);
    Xyz v;
    if (!(s >> v[0] >> v[1] >> v[2])) throw std::runtime_error(path.string() + ": bad line: " + line);
    out.insert(v);
  }
  return out;
}

std::map<Xyz, std::uint64_t> read_spec_payloads(const fs::path& path) {
  std::ifstream in(path);
  if (!in) throw std::runtime_error("cannot open " + path.string());
  std::map<Xyz, std::uint64_t> out;
  std::string line;
  while (std::getline(in, line)) {
    if (line.empty()) continue;
    std::istringstream s(line);
    Xyz v;
    std::string hex;
    if (!(s >> v[0] >> v[1] >> v[2] >> hex)) throw std::runtime_error(path.string() + ": bad line: " + line);
    out[v] = std::stoull(hex, nullptr, 16);
  }
  return out;
}

GoldenParams read_params(const fs::path& case_dir) {
  std::ifstream in(case_dir / "params.json");
  if (!in) throw std::runtime_error("cannot open " + (case_dir / "params.json").string());
  const auto j = nlohmann::json::parse(in);
  GoldenParams p;
  p.depth = j.at("depth").get<int>();
  p.dense = j.at("dense").get<bool>();
  p.nbits = j.at("nbits").get<int>();
  p.crs = j.at("crs").get<std::uint32_t>();
  for (int a = 0; a < 3; ++a) {
    p.bbox.min[a] = j.at("bbox").at(0).at(a).get<double>();
    p.bbox.max[a] = j.at("bbox").at(1).at(a).get<double>();
  }
  return p;
}

int count_columns(const fs::path& path) {
  std::ifstream in(path);
  std::string line;
  if (!std::getline(in, line)) return 0;
  std::istringstream s(line);
  std::string token;
  int n = 0;
  while (s >> token) ++n;
  return n;
}

}  // namespace vola_test
