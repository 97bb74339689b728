// vola/geo/crs.hpp over libvola_proj.so (proj_plugin.hpp), loaded the first time a CRS
// is needed: a run that never transforms a coordinate never loads PROJ.
#include "vola/geo/crs.hpp"

#include <array>
#include <map>
#include <mutex>
#include <vector>

#include "proj_plugin.hpp"
#include "vola/parallel.hpp"

namespace vola::geo {

namespace {

const plugin::ProjEntries& proj(const std::string& purpose) {
  const auto entries = reinterpret_cast<plugin::ProjEntriesEntry>(
      vola::plugin::plugin_symbol("proj", plugin::kProjEntriesSymbol, purpose));
  return *entries();
}

// Calls one entry point and throws what it reports.
template <class Call>
void run(const std::string& purpose, Call&& call) {
  plugin::PluginFailure failure;
  call(proj(purpose), failure);
  vola::plugin::throw_failure(failure);
}

}  // namespace

std::pair<double, double> centre_lat_lon(std::uint32_t epsg, const Box& bbox) {
  return centre_lat_lon("EPSG:" + std::to_string(epsg), bbox);
}

std::pair<double, double> centre_lat_lon(const std::string& crs, const Box& bbox) {
  std::pair<double, double> lat_lon;
  run("the latitude and longitude of a bounding box", [&](const plugin::ProjEntries& p, plugin::PluginFailure& f) {
    p.centre_lat_lon(crs, bbox, lat_lon, f);
  });
  return lat_lon;
}

std::string crs_wkt(std::uint32_t epsg) {
  std::string wkt;
  run("the WKT of EPSG:" + std::to_string(epsg),
      [&](const plugin::ProjEntries& p, plugin::PluginFailure& f) { p.crs_wkt(epsg, wkt, f); });
  return wkt;
}

std::optional<std::uint32_t> epsg_from_wkt(const std::string& wkt) {
  std::optional<std::uint32_t> epsg;
  run("the EPSG code of a WKT CRS",
      [&](const plugin::ProjEntries& p, plugin::PluginFailure& f) { p.epsg_from_wkt(wkt, epsg, f); });
  return epsg;
}

std::string keyed_projected_crs(std::uint32_t epsg, std::uint32_t linear_unit, std::uint32_t vertical_unit) {
  // Every LAS header with GeoKeys asks (most with the code's own units): once per process
  // for each set of keys, rather than loading PROJ's database per file.
  static std::mutex mutex;
  static std::map<std::array<std::uint32_t, 3>, std::string> known;
  const std::array<std::uint32_t, 3> keys{epsg, linear_unit, vertical_unit};
  {
    const std::lock_guard lock(mutex);
    if (const auto it = known.find(keys); it != known.end()) return it->second;
  }
  std::string wkt;
  run("EPSG:" + std::to_string(epsg) + " as GeoTIFF keys qualify it",
      [&](const plugin::ProjEntries& p, plugin::PluginFailure& f) {
        p.keyed_projected_crs(epsg, linear_unit, vertical_unit, wkt, f);
      });
  const std::lock_guard lock(mutex);
  if (known.size() < 1024) known.emplace(keys, wkt);
  return wkt;
}

std::optional<std::string> crs_definition(const Georef& georef) {
  if (!georef.crs_wkt.empty()) return georef.crs_wkt;
  if (georef.epsg != kUnsetEpsg) return "EPSG:" + std::to_string(georef.epsg);
  return std::nullopt;
}

std::optional<CrsPair> different_crs(const Georef& a, const Georef& b) {
  const std::optional<std::string> crs_a = crs_definition(a), crs_b = crs_definition(b);
  if (!crs_a || !crs_b || *crs_a == *crs_b) return std::nullopt;
  bool same = false;
  try {
    same = same_crs(*crs_a, *crs_b);
  } catch (const Error&) {
    same = false;  // PROJ cannot read one of them: not provably the same
  }
  if (same) return std::nullopt;
  const auto name = [](const std::string& definition) {
    try {
      return crs_summary(describe_crs(definition));
    } catch (const Error&) {
      return definition.substr(0, 80);
    }
  };
  return CrsPair{name(*crs_a), name(*crs_b)};
}

std::string crs_wkt1(const std::string& definition) {
  std::string wkt;
  run("a CRS as WKT1", [&](const plugin::ProjEntries& p, plugin::PluginFailure& f) { p.crs_wkt1(definition, wkt, f); });
  return wkt;
}

bool same_crs(const std::string& a, const std::string& b) {
  bool same = false;
  run("whether two CRSs are the same", [&](const plugin::ProjEntries& p, plugin::PluginFailure& f) { p.same_crs(a, b, same, f); });
  return same;
}

CrsDescription describe_crs(const std::string& definition, EpsgLookup lookup) {
  CrsDescription out;
  run("a description of a CRS",
      [&](const plugin::ProjEntries& p, plugin::PluginFailure& f) { p.describe_crs(definition, lookup, out, f); });
  return out;
}

std::string crs_summary(const CrsDescription& crs) {
  std::string line = crs.name.empty() ? "unnamed CRS" : crs.name;
  const std::string which = crs.vertical_name.empty() ? "EPSG:" : "horizontal EPSG:";
  line += crs.epsg ? " (" + which + std::to_string(*crs.epsg) + ")" : " (no EPSG code)";
  if (!crs.kind.empty()) line += ", " + crs.kind;
  if (!crs.horizontal_unit.empty()) line += ", " + crs.horizontal_unit;
  if (!crs.vertical_name.empty())
    line += "; vertical " + crs.vertical_name + (crs.vertical_unit.empty() ? "" : " (" + crs.vertical_unit + ")");
  return line;
}

std::string crs_wkt(const std::string& definition) {
  std::string wkt;
  run("a CRS as WKT", [&](const plugin::ProjEntries& p, plugin::PluginFailure& f) { p.crs_wkt_of(definition, wkt, f); });
  return wkt;
}

// One PROJ transformation per worker (PROJ objects are not shared between threads),
// each made the first time its worker needs one.
struct Reprojection::State {
  const plugin::ProjEntries* entries = nullptr;
  std::string from, to;
  std::vector<void*> per_worker;
  ~State() {
    for (void* t : per_worker)
      if (t) entries->reprojection_close(t);
  }
  void* worker(unsigned w) {
    if (!per_worker[w]) {
      plugin::PluginFailure failure;
      entries->reprojection_open(from, to, per_worker[w], failure);
      vola::plugin::throw_failure(failure);
    }
    return per_worker[w];
  }
};

Reprojection::Reprojection(const std::string& from, const std::string& to, unsigned threads)
    : state_(std::make_unique<State>()) {
  state_->entries = &proj("reprojecting points");
  state_->from = from;
  state_->to = to;
  state_->per_worker.assign(resolve_thread_count(threads), nullptr);
  state_->worker(0);  // fails here, before any point, for a CRS or pair PROJ cannot do
}

Reprojection::~Reprojection() = default;
Reprojection::Reprojection(Reprojection&&) noexcept = default;
Reprojection& Reprojection::operator=(Reprojection&&) noexcept = default;

void Reprojection::transform(std::span<double> xyz) const {
  // Batches of 64K points: large enough to pay for a thread, small enough to share out.
  constexpr std::size_t kBatch = std::size_t{1} << 16;
  ParallelOptions options;
  options.threads = static_cast<unsigned>(state_->per_worker.size());
  options.grain = kBatch;
  options.name = "geo.reproject";
  State& state = *state_;
  parallel_for(
      xyz.size() / 3,
      [&state, xyz](const Chunk& chunk) {
        plugin::PluginFailure failure;
        state.entries->reprojection_transform(state.worker(chunk.worker), xyz.data() + 3 * chunk.begin,
                                              chunk.end - chunk.begin, failure);
        vola::plugin::throw_failure(failure);
      },
      options);
}

struct ToWgs84::State {
  const plugin::ProjEntries* entries = nullptr;
  void* transformation = nullptr;
  ~State() {
    if (transformation) entries->to_wgs84_close(transformation);
  }
};

ToWgs84::ToWgs84(const std::string& definition) : state_(std::make_unique<State>()) {
  state_->entries = &proj("coordinates in longitude and latitude");
  plugin::PluginFailure failure;
  state_->entries->to_wgs84_open(definition, state_->transformation, failure);
  vola::plugin::throw_failure(failure);
}

ToWgs84::~ToWgs84() = default;
ToWgs84::ToWgs84(ToWgs84&&) noexcept = default;
ToWgs84& ToWgs84::operator=(ToWgs84&&) noexcept = default;

Point ToWgs84::transform(const Point& p) const {
  Point out{};
  plugin::PluginFailure failure;
  state_->entries->to_wgs84_transform(state_->transformation, p, out, failure);
  vola::plugin::throw_failure(failure);
  return out;
}

}  // namespace vola::geo
