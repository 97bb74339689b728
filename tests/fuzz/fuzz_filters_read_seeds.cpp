// Seeds for fuzz_filters_read: --where expressions (PDAL's spellings, every operator and
// precedence level), GeoJSON and WKT polygons (holes, multipolygons, features), and JSON
// pipelines of every stage type; byte 0 picks the parser (0 where, 1 polygon, 2 pipeline).
// Linked into fuzz_filters_read_replay in place of fuzz_seeds.cpp.
#include <string>

#include "fuzz_seeds.hpp"

namespace vola_fuzz {

namespace {

Seed seed(const std::string& name, char kind, const std::string& s) {
  std::vector<std::uint8_t> bytes{static_cast<std::uint8_t>(kind)};
  bytes.insert(bytes.end(), s.begin(), s.end());
  return {name, std::move(bytes)};
}

}  // namespace

std::vector<Seed> synthetic_seeds() {
  return {
      seed("where_class", 0, "Classification == 2"),
      seed("where_mixed", 0, "Classification == 2 && (Intensity > 100 || ReturnNumber == 1)"),
      seed("where_not", 0, "!(z < 400) && number_of_returns <= 2.5e0"),
      seed("where_dims", 0, "x < y || Z != -1.5 && intensity >= classification"),
      seed("polygon_wkt", 1, "POLYGON((0 0, 2 0, 2 2, 0 2, 0 0), (0.5 0.5, 1 0.5, 1 1, 0.5 0.5))"),
      seed("multipolygon_wkt", 1, "MULTIPOLYGON(((0 0,1 0,1 1,0 0)),((5 5,6 5,6 6,5 5)))"),
      seed("polygon_geojson", 1,
           R"({"type": "FeatureCollection", "features": [{"type": "Feature", "properties": {}, "geometry":
               {"type": "Polygon", "coordinates": [[[0,0],[3,0],[3,3],[0,3],[0,0]]]}}]})"),
      seed("multipolygon_geojson", 1,
           R"({"type": "MultiPolygon", "coordinates": [[[[0,0],[1,0],[1,1],[0,0]]], [[[2,2],[4,2],[4,4],[2,2]]]]})"),
      seed("pipeline_ground", 2,
           R"(["in.laz", {"type": "filters.smrf"}, {"type": "filters.range", "limits": "Classification[2:2]"}, "out.laz"])"),
      seed("pipeline_all", 2,
           R"json({"pipeline": [{"type": "readers.las", "filename": "a.las"},
               {"type": "filters.smrf", "cell": 1.5, "slope": 0.2, "window": 16, "threshold": 0.45, "scalar": 1.2},
               {"type": "filters.hag_nn"}, {"type": "filters.expression", "expression": "HeightAboveGround > 2"},
               {"type": "filters.outlier", "method": "statistical", "mean_k": 8, "multiplier": 2.0},
               {"type": "filters.crop", "bounds": "([0, 10], [0, 20], [-5, 5])"},
               {"type": "filters.crop", "polygon": "POLYGON((0 0,1 0,1 1,0 0))"},
               {"type": "filters.range", "limits": "Z(:500],Intensity[100:),Classification![7:7]"},
               {"type": "filters.sample", "radius": 0.5}, {"type": "filters.voxelcenternearestneighbor", "cell": 1},
               {"type": "writers.las", "filename": "b.laz"},
               {"type": "writers.vola", "filename": "c.vol", "voxel_size": 2.5, "compress": true}]})json"),
  };
}

// Nothing from the golden folder: the parsers read text people write.
std::vector<Seed> golden_seeds(const std::filesystem::path&) { return {}; }

}  // namespace vola_fuzz
