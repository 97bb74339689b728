#include "vola/io/ept.hpp"

#include <algorithm>
#include <array>
#include <charconv>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <nlohmann/json.hpp>
#include <set>
#include <string_view>

#include "column_names.hpp"
#include "file_bytes.hpp"
#include "vola/error.hpp"
#include "vola/io/las.hpp"
#include "vola/little_endian.hpp"

namespace vola::io {

namespace {

namespace fs = std::filesystem;
using nlohmann::json;

// The octree's depth is bounded by the coordinates' 64 bits; EPT writers stay far below.
constexpr int kMaxDepth = 62;

// ept.json and hierarchy files are small (Entwine splits large hierarchies into subtree
// files); a parsed JSON document takes several times its bytes, so larger ones are refused.
constexpr std::uint64_t kMaxJsonBytes = std::uint64_t{64} << 20;

json parse_json_file(const fs::path& path) {
  std::error_code error;
  const std::uint64_t size = fs::file_size(path, error);
  if (!error && size > kMaxJsonBytes)
    throw FormatError(path.string(), std::nullopt,
                      std::to_string(size) + " bytes of JSON, more than the " + std::to_string(kMaxJsonBytes >> 20) +
                          " MiB an EPT metadata file may take here");
  const std::vector<std::uint8_t> bytes = read_file_bytes(path.string());
  try {
    return json::parse(bytes.begin(), bytes.end());
  } catch (const json::exception& e) {
    throw FormatError(path.string(), std::nullopt, std::string("not valid JSON: ") + e.what());
  }
}

// "D-X-Y-Z" with X, Y, Z below 2^D, as its four numbers.
std::array<std::uint64_t, 4> parse_key(const std::string& key, const fs::path& file) {
  std::array<std::uint64_t, 4> k{};
  const char* at = key.data();
  const char* end = key.data() + key.size();
  for (int i = 0; i < 4; ++i) {
    const auto [next, error] = std::from_chars(at, end, k[static_cast<std::size_t>(i)]);
    if (error != std::errc{} || next == at || (i < 3 && (next == end || *next != '-')) || (i == 3 && next != end))
      throw FormatError(file.string(), std::nullopt, "'" + key + "' is not a node key D-X-Y-Z");
    at = i < 3 ? next + 1 : next;
  }
  if (k[0] > kMaxDepth || k[1] >> k[0] || k[2] >> k[0] || k[3] >> k[0])
    throw FormatError(file.string(), std::nullopt, "node key '" + key + "' lies outside an octree of its depth");
  return k;
}

struct Dimension {
  std::string name;      // as the schema spells it
  char type = 'f';       // 's' signed, 'u' unsigned, 'f' float
  std::size_t size = 4;  // bytes
  std::size_t offset = 0;
  double scale = 1.0, add = 0.0;
};

double load_value(const std::uint8_t* p, const Dimension& d) {
  double v = 0;
  switch (d.type) {
    case 's':
      v = d.size == 1   ? static_cast<double>(static_cast<std::int8_t>(p[0]))
          : d.size == 2 ? static_cast<double>(load_le<std::int16_t>(p))
          : d.size == 4 ? static_cast<double>(load_le<std::int32_t>(p))
                        : static_cast<double>(load_le<std::int64_t>(p));
      break;
    case 'u':
      v = d.size == 1   ? static_cast<double>(p[0])
          : d.size == 2 ? static_cast<double>(load_le<std::uint16_t>(p))
          : d.size == 4 ? static_cast<double>(load_le<std::uint32_t>(p))
                        : static_cast<double>(load_le<std::uint64_t>(p));
      break;
    default: {
      if (d.size == 4) {
        float f;
        std::memcpy(&f, p, 4);
        v = f;
      } else {
        std::memcpy(&v, p, 8);
      }
    }
  }
  return v * d.scale + d.add;
}

ValueType value_type(const Dimension& d) {
  if (d.scale != 1.0 || d.add != 0.0) return ValueType::f64;
  if (d.type == 'f') return d.size == 4 ? ValueType::f32 : ValueType::f64;
  if (d.type == 'u')
    return d.size == 1 ? ValueType::u8 : d.size == 2 ? ValueType::u16 : d.size == 4 ? ValueType::u32 : ValueType::f64;
  return d.size == 1 ? ValueType::i8 : d.size == 2 ? ValueType::i16 : d.size == 4 ? ValueType::i32 : ValueType::f64;
}

std::vector<Dimension> schema_of(const json& ept, const std::string& where) {
  if (!ept.contains("schema") || !ept["schema"].is_array())
    throw FormatError(where, std::nullopt, "ept.json has no \"schema\" list");
  std::vector<Dimension> dims;
  std::size_t offset = 0;
  for (const json& d : ept["schema"]) {
    if (!d.is_object() || !d.contains("name") || !d["name"].is_string() || !d.contains("type") ||
        !d["type"].is_string() || !d.contains("size") || !d["size"].is_number_unsigned())
      throw FormatError(where, std::nullopt, "a schema entry needs a name, a type and a size: " + d.dump());
    Dimension dim;
    dim.name = d["name"].get<std::string>();
    const std::string type = d["type"].get<std::string>();
    dim.size = d["size"].get<std::size_t>();
    dim.type = type == "signed" ? 's' : type == "unsigned" ? 'u' : type == "float" ? 'f' : '?';
    const bool sized = dim.type == 'f' ? (dim.size == 4 || dim.size == 8)
                                       : (dim.size == 1 || dim.size == 2 || dim.size == 4 || dim.size == 8);
    if (dim.type == '?' || !sized)
      throw FormatError(where, std::nullopt,
                        "schema dimension " + dim.name + ": " + type + " of " + std::to_string(dim.size) +
                            " bytes is not an EPT type");
    for (const char* key : {"scale", "offset"})
      if (d.contains(key) && !d[key].is_number())
        throw FormatError(where, std::nullopt, "schema dimension " + dim.name + ": " + key + " must be a number");
    if (d.contains("scale")) dim.scale = d["scale"].get<double>();
    if (d.contains("offset")) dim.add = d["offset"].get<double>();
    if (!(std::isfinite(dim.scale) && dim.scale != 0 && std::isfinite(dim.add)))
      throw FormatError(where, std::nullopt,
                        "schema dimension " + dim.name + ": scale and offset must be finite, scale not 0");
    dim.offset = offset;
    offset += dim.size;
    dims.push_back(std::move(dim));
  }
  for (const char* axis : {"X", "Y", "Z"})
    if (std::none_of(dims.begin(), dims.end(), [&](const Dimension& d) { return d.name == axis; }))
      throw FormatError(where, std::nullopt, std::string("the schema has no ") + axis + " dimension");
  return dims;
}

// Appends one node's cloud to `out`; the first node sets the columns.
void append_cloud(PointCloud& out, PointCloud&& node, const std::string& file, bool first) {
  if (first) {
    out = std::move(node);
    return;
  }
  if (node.attributes.size() != out.attributes.size())
    throw FormatError(file, std::nullopt, "holds other dimensions than the dataset's first node");
  for (std::size_t a = 0; a < node.attributes.size(); ++a) {
    if (node.attributes[a].name != out.attributes[a].name)
      throw FormatError(file, std::nullopt, "holds other dimensions than the dataset's first node");
    auto& values = out.attributes[a].values;
    values.insert(values.end(), node.attributes[a].values.begin(), node.attributes[a].values.end());
  }
  out.xyz.insert(out.xyz.end(), node.xyz.begin(), node.xyz.end());
  out.payload.insert(out.payload.end(), node.payload.begin(), node.payload.end());
}

PointCloud binary_node(const std::string& file, const std::vector<Dimension>& dims, std::uint64_t count,
                       const InputOptions& options) {
  const std::vector<std::uint8_t> bytes = read_file_bytes(file);
  const std::size_t record = dims.back().offset + dims.back().size;
  if (bytes.size() % record != 0 || bytes.size() / record != count)
    throw FormatError(file, std::nullopt,
                      "holds " + std::to_string(bytes.size()) + " bytes, not the " + std::to_string(count) +
                          " records of " + std::to_string(record) + " bytes the hierarchy states");
  std::array<const Dimension*, 3> axis{};
  std::vector<const Dimension*> others;
  PointCloud cloud;
  for (const Dimension& d : dims) {
    if (d.name == "X" || d.name == "Y" || d.name == "Z") {
      axis[static_cast<std::size_t>(d.name[0] - 'X')] = &d;
    } else if (options.attributes) {
      const std::string column = point_column_name(d.name);
      if (std::any_of(cloud.attributes.begin(), cloud.attributes.end(),
                      [&](const auto& a) { return a.name == column; }))
        continue;  // a second dimension of one name stays unread, as in PLY and text
      others.push_back(&d);
      cloud.attributes.push_back({column, value_type(d), point_column_reduction(column, d.name), {}});
    }
  }
  const std::size_t n = static_cast<std::size_t>(count);
  cloud.xyz.resize(3 * n);
  for (auto& a : cloud.attributes) a.values.resize(n);
  for (std::size_t i = 0; i < n; ++i) {
    const std::uint8_t* r = bytes.data() + i * record;
    for (std::size_t a = 0; a < 3; ++a) cloud.xyz[3 * i + a] = load_value(r + axis[a]->offset, *axis[a]);
    for (std::size_t k = 0; k < others.size(); ++k)
      cloud.attributes[k].values[i] = load_value(r + others[k]->offset, *others[k]);
  }
  return cloud;
}

// The nodes with points of the dataset whose ept.json (at `ept_json`) is `ept`.
std::vector<EptNode> nodes_of(const json& ept, const std::string& ept_json) {
  const fs::path root = fs::path(ept_json).parent_path();
  if (!ept.is_object() || !ept.contains("points") || !ept["points"].is_number_unsigned())
    throw FormatError(ept_json, std::nullopt, "ept.json states no point count (\"points\")");
  const std::uint64_t total = ept["points"].get<std::uint64_t>();
  std::vector<std::pair<std::array<std::uint64_t, 4>, EptNode>> nodes;
  std::set<std::string> seen, files_read;
  std::vector<std::string> files = {"0-0-0-0"};
  std::uint64_t stated = 0;
  while (!files.empty()) {
    const fs::path file = root / "ept-hierarchy" / (files.back() + ".json");
    if (!files_read.insert(files.back()).second)
      throw FormatError(file.string(), std::nullopt,
                        "is named by a count of -1 a second time (a loop of hierarchy files)");
    files.pop_back();
    const json hierarchy = parse_json_file(file);
    if (!hierarchy.is_object())
      throw FormatError(file.string(), std::nullopt, "a hierarchy file must be one JSON object");
    for (const auto& [key, count] : hierarchy.items()) {
      const auto k = parse_key(key, file);
      if (!seen.insert(key).second)
        throw FormatError(file.string(), std::nullopt,
                          "node " + key + " appears a second time (a loop of hierarchy files?)");
      if (!count.is_number_integer() || count.get<std::int64_t>() < -1)
        throw FormatError(file.string(), std::nullopt,
                          "node " + key + ": the count " + count.dump() + " is not an integer >= -1");
      const std::int64_t c = count.get<std::int64_t>();
      if (c == -1) {
        files.push_back(key);
        seen.erase(key);  // the subtree file lists it again with its count
        continue;
      }
      if (c == 0) continue;
      stated += static_cast<std::uint64_t>(c);
      if (stated > total)
        throw FormatError(
            file.string(), std::nullopt,
            "the nodes hold more points than ept.json's " + std::to_string(total) + " (at node " + key + ")");
      nodes.push_back({k, {key, static_cast<int>(k[0]), {k[1], k[2], k[3]}, static_cast<std::uint64_t>(c)}});
    }
    if (seen.size() > (std::uint64_t{1} << 24))
      throw FormatError(file.string(), std::nullopt, "more than 2^24 nodes: not read");
  }
  std::sort(nodes.begin(), nodes.end(), [](const auto& a, const auto& b) { return a.first < b.first; });
  std::vector<EptNode> out;
  for (auto& [k, node] : nodes) out.push_back(std::move(node));
  return out;
}

// What the parsed ept.json `ept` (at `ept_json`) says of its dataset.
EptDataset dataset_of(const json& ept, const std::string& ept_json) {
  if (!ept.is_object() || !ept.contains("dataType") || !ept["dataType"].is_string())
    throw FormatError(ept_json, std::nullopt, "not an EPT ept.json: no \"dataType\"");
  EptDataset d;
  d.data_type = ept["dataType"].get<std::string>();
  if (ept.contains("version") && ept["version"].is_string()) d.version = ept["version"].get<std::string>();
  if (ept.contains("points") && ept["points"].is_number_unsigned()) d.points = ept["points"].get<std::uint64_t>();
  const auto box = [&](const char* key) -> std::optional<std::array<double, 6>> {
    if (!ept.contains(key) || !ept[key].is_array() || ept[key].size() != 6) return std::nullopt;
    std::array<double, 6> b{};
    for (std::size_t i = 0; i < 6; ++i) {
      if (!ept[key][i].is_number()) return std::nullopt;
      b[i] = ept[key][i].get<double>();
    }
    return b;
  };
  if (const auto b = box("bounds")) d.bounds = *b;
  d.conforming = box("boundsConforming");
  if (ept.contains("schema") && ept["schema"].is_array())
    for (const json& dim : ept["schema"])
      if (dim.is_object() && dim.contains("name") && dim["name"].is_string())
        d.dimensions.push_back(dim["name"].get<std::string>());
  if (ept.contains("srs") && ept["srs"].is_object()) {
    const json& srs = ept["srs"];
    if (srs.contains("wkt") && srs["wkt"].is_string()) d.wkt = srs["wkt"].get<std::string>();
    if (srs.contains("authority") && srs["authority"] == "EPSG" && srs.contains("horizontal")) {
      const std::string code =
          srs["horizontal"].is_string() ? srs["horizontal"].get<std::string>() : srs["horizontal"].dump();
      std::uint32_t epsg = 0;
      const auto [end, error] = std::from_chars(code.data(), code.data() + code.size(), epsg);
      if (error == std::errc{} && end == code.data() + code.size() && epsg > 0) d.epsg = epsg;
    }
  }
  return d;
}

}  // namespace

std::vector<EptNode> ept_nodes(const std::string& ept_json) { return nodes_of(parse_json_file(ept_json), ept_json); }

EptDataset ept_dataset(const std::string& ept_json) { return dataset_of(parse_json_file(ept_json), ept_json); }

std::array<double, 6> ept_node_bounds(const EptDataset& dataset, const EptNode& node) {
  std::array<double, 6> cube{};
  const double parts = std::ldexp(1.0, node.depth);
  for (std::size_t a = 0; a < 3; ++a) {
    const double lo = dataset.bounds[a], hi = dataset.bounds[a + 3];
    const double step = (hi - lo) / parts;
    cube[a] = lo + static_cast<double>(node.place[a]) * step;
    // The last cube along an axis ends at the dataset's own bound, not at a rounded sum.
    cube[a + 3] =
        node.place[a] + 1 == std::uint64_t{1} << node.depth ? hi : lo + static_cast<double>(node.place[a] + 1) * step;
  }
  return cube;
}

namespace {

bool meets(const std::array<double, 6>& cube, const Box& box) {
  for (std::size_t a = 0; a < 3; ++a)
    if (cube[a] > box.max[a] || cube[a + 3] < box.min[a]) return false;
  return true;
}

std::uint64_t size_or_zero(const fs::path& file) {
  std::error_code error;
  const std::uint64_t size = fs::file_size(file, error);
  return error ? 0 : size;
}

}  // namespace

Input read_ept(const std::string& ept_json, const InputOptions& options) {
  const fs::path root = fs::path(ept_json).parent_path();
  const json ept = parse_json_file(ept_json);  // once: the dataset, the nodes and the schema all come from it
  const EptDataset dataset = dataset_of(ept, ept_json);
  const std::string& type = dataset.data_type;
  if (type == "zstandard")
    throw FormatError(
        ept_json, std::nullopt,
        "EPT data of type zstandard is not read by vola; rebuild the dataset as laszip or binary (entwine "
        "build --dataType laszip), or read it with PDAL first");
  if (type != "laszip" && type != "binary")
    throw FormatError(ept_json, std::nullopt, "unknown EPT dataType '" + type + "' (laszip, binary or zstandard)");
  const std::vector<Dimension> dims = type == "binary" ? schema_of(ept, ept_json) : std::vector<Dimension>{};
  Input in;
  in.format = "ept";
  in.wkt = dataset.wkt;
  in.epsg = dataset.epsg;
  std::vector<EptNode> nodes = nodes_of(ept, ept_json);
  const auto file_of = [&](const EptNode& node) {
    return (root / "ept-data" / (node.key + (type == "laszip" ? ".laz" : ".bin"))).string();
  };
  for (const EptNode& node : nodes) in.bytes_total += size_or_zero(file_of(node));
  if (options.copc_level) std::erase_if(nodes, [&](const EptNode& n) { return n.depth > *options.copc_level; });
  const bool has_cube = dataset.bounds[0] < dataset.bounds[3] && dataset.bounds[1] < dataset.bounds[4] &&
                        dataset.bounds[2] < dataset.bounds[5];
  if (options.region && has_cube)  // without a cube of its own, no node can be placed: all are read
    std::erase_if(nodes, [&](const EptNode& n) { return !meets(ept_node_bounds(dataset, n), *options.region); });
  std::uint64_t done = 0, total = 0, bytes_read = 0;
  for (const EptNode& n : nodes) total += n.points;
  bool first = true;
  for (const EptNode& node : nodes) {
    const std::string file = file_of(node);
    bytes_read += size_or_zero(file);
    PointCloud cloud;
    if (type == "laszip") {
      LasReader las(file);  // every node whole: the dataset's levels, not a node's (a node is no COPC file)
      cloud = las_points(las, options.attributes, options.payload, nullptr);
      if (in.wkt.empty() && !in.epsg) in.wkt = las.header().wkt, in.epsg = las.header().epsg;
    } else {
      cloud = binary_node(file, dims, node.points, options);
    }
    if (cloud.size() != node.points)
      throw FormatError(file, std::nullopt,
                        "holds " + std::to_string(cloud.size()) + " points where the hierarchy states " +
                            std::to_string(node.points));
    append_cloud(in.cloud, std::move(cloud), file, first);
    first = false;
    done += node.points;
    if (options.progress) options.progress(done, total);
  }
  in.bytes_read = [bytes_read] { return bytes_read; };
  return in;
}

}  // namespace vola::io
