// Seeds for fuzz_wkt_read: the OGC WKT records (LASF_Projection 2112) of the shared
// data folder's LAS files (beside golden/), the EPSG codes data/EXPECTED.txt names for
// them, and definitions written here: WKT1 with TOWGS84 (a bound CRS), WKT2 with an ID,
// a compound CRS with a vertical part, an engineering CRS, a PROJ string, a pipeline.
// Each definition is a seed for every entry point (its selector byte first,
// fuzz_wkt_read.cpp). Linked into fuzz_wkt_read_replay in place of fuzz_seeds.cpp.
#include <algorithm>
#include <cstring>
#include <fstream>
#include <iterator>
#include <regex>
#include <set>
#include <string>

#include "fuzz_seeds.hpp"

namespace vola_fuzz {
namespace {

namespace fs = std::filesystem;
using Bytes = std::vector<std::uint8_t>;

Seed text(const std::string& name, const std::string& s) { return {name, Bytes(s.begin(), s.end())}; }

// The definitions, once for each of the six entry points.
std::vector<Seed> for_each_entry_point(const std::vector<Seed>& definitions) {
  std::vector<Seed> seeds;
  for (std::uint8_t entry = 0; entry < 6; ++entry)
    for (const Seed& d : definitions) {
      Seed s{std::to_string(entry) + "_" + d.name, {entry}};
      s.bytes.insert(s.bytes.end(), d.bytes.begin(), d.bytes.end());
      seeds.push_back(std::move(s));
    }
  return seeds;
}

template <class T>
T get(const Bytes& b, std::size_t at) {
  T v{};
  if (at + sizeof(T) <= b.size()) std::memcpy(&v, b.data() + at, sizeof(T));
  return v;
}

// The payloads of a LAS file's LASF_Projection 2112 records (VLRs after the header).
std::vector<std::string> wkt_records(const Bytes& las) {
  std::vector<std::string> out;
  if (las.size() < 227 || std::memcmp(las.data(), "LASF", 4) != 0) return out;
  std::size_t at = get<std::uint16_t>(las, 94);
  const std::uint32_t count = get<std::uint32_t>(las, 100);
  for (std::uint32_t i = 0; i < count && at + 54 <= las.size(); ++i) {
    const std::string user(reinterpret_cast<const char*>(las.data() + at + 2), strnlen(reinterpret_cast<const char*>(las.data() + at + 2), 16));
    const std::uint16_t record = get<std::uint16_t>(las, at + 18), length = get<std::uint16_t>(las, at + 20);
    if (at + 54 + length > las.size()) break;
    if (user == "LASF_Projection" && record == 2112)
      out.emplace_back(reinterpret_cast<const char*>(las.data() + at + 54), length);
    at += 54 + std::size_t{length};
  }
  return out;
}

}  // namespace

std::vector<Seed> synthetic_seeds() {
  return for_each_entry_point({
      text("wkt1_bound.wkt",
           "PROJCS[\"NAD83 / UTM zone 15N\",GEOGCS[\"NAD83\",DATUM[\"North_American_Datum_1983\",SPHEROID[\"GRS 1980\","
           "6378137,298.257222101],TOWGS84[0,0,0,0,0,0,0]],PRIMEM[\"Greenwich\",0],UNIT[\"degree\",0.0174532925199433]],"
           "PROJECTION[\"Transverse_Mercator\"],PARAMETER[\"latitude_of_origin\",0],PARAMETER[\"central_meridian\",-93],"
           "PARAMETER[\"scale_factor\",0.9996],PARAMETER[\"false_easting\",500000],PARAMETER[\"false_northing\",0],"
           "UNIT[\"metre\",1]]"),
      text("wkt2_id.wkt",
           "PROJCRS[\"WGS 84 / UTM zone 33N\",BASEGEOGCRS[\"WGS 84\",DATUM[\"World Geodetic System 1984\",ELLIPSOID["
           "\"WGS 84\",6378137,298.257223563]],UNIT[\"degree\",0.0174532925199433]],CONVERSION[\"UTM zone 33N\",METHOD["
           "\"Transverse Mercator\"],PARAMETER[\"Latitude of natural origin\",0],PARAMETER[\"Longitude of natural origin\",15],"
           "PARAMETER[\"Scale factor at natural origin\",0.9996],PARAMETER[\"False easting\",500000],PARAMETER["
           "\"False northing\",0]],CS[Cartesian,2],AXIS[\"easting\",east],AXIS[\"northing\",north],UNIT[\"metre\",1],"
           "ID[\"EPSG\",32633]]"),
      text("compound.wkt",
           "COMPD_CS[\"NAD83 + NAVD88 height\",GEOGCS[\"NAD83\",DATUM[\"North_American_Datum_1983\",SPHEROID[\"GRS 1980\","
           "6378137,298.257222101]],PRIMEM[\"Greenwich\",0],UNIT[\"degree\",0.0174532925199433]],VERT_CS[\"NAVD88 height\","
           "VERT_DATUM[\"North American Vertical Datum 1988\",2005],UNIT[\"US survey foot\",0.304800609601219],"
           "AXIS[\"Gravity-related height\",UP]]]"),
      text("engineering.wkt", "ENGCRS[\"site grid\",EDATUM[\"site\"],CS[Cartesian,2],AXIS[\"x\",east],AXIS[\"y\",north],LENGTHUNIT[\"metre\",1]]"),
      text("proj_string.txt", "+proj=utm +zone=10 +datum=NAD83 +units=us-ft +no_defs +type=crs"),
      text("pipeline.txt", "+proj=pipeline +step +proj=unitconvert +xy_in=deg +xy_out=rad +step +proj=merc"),
      text("epsg_2056.txt", "EPSG:2056"),
      text("empty.txt", ""),
  });
}

// WKT records of every LAS file in data/las and data/laz, and the EPSG codes of EXPECTED.txt.
std::vector<Seed> golden_seeds(const fs::path& golden) {
  std::vector<Seed> seeds;
  std::set<std::string> seen;
  for (const char* sub : {"las", "laz"}) {
    const auto folder = shared_data(golden, sub);
    if (folder.empty()) continue;
    for (const auto& entry : fs::directory_iterator(folder)) {
      if (!entry.is_regular_file()) continue;
      std::ifstream in(entry.path(), std::ios::binary);
      Bytes head(1 << 16);
      in.read(reinterpret_cast<char*>(head.data()), static_cast<std::streamsize>(head.size()));
      head.resize(static_cast<std::size_t>(in.gcount()));
      for (const auto& wkt : wkt_records(head))
        if (seen.insert(wkt).second) seeds.push_back(text("wkt_" + entry.path().filename().string(), wkt));
    }
  }
  std::ifstream expected(golden.parent_path() / "data" / "EXPECTED.txt");
  const std::regex code_re(R"((?:ProjCS|GeogCS|EPSG)[=:](\d{4,5}))");
  std::string line;
  while (std::getline(expected, line))
    for (auto it = std::sregex_iterator(line.begin(), line.end(), code_re); it != std::sregex_iterator(); ++it) {
      const std::string code = "EPSG:" + (*it)[1].str();
      if (seen.insert(code).second) seeds.push_back(text("code_" + (*it)[1].str(), code));
    }
  std::sort(seeds.begin(), seeds.end(), [](const Seed& a, const Seed& b) { return a.name < b.name; });
  return for_each_entry_point(seeds);
}

}  // namespace vola_fuzz
