// A list of point filters run in order on a cloud: what `vola convert`, `vola translate`,
// `vola tile`, `vola pipeline`, Python and C share. Each stage is written as one string,
// the same in every front end:
//
//   where:EXPR                   keep the points EXPR holds for (expression.hpp)
//   smrf[:cell=1,slope=0.15,window=18,threshold=0.5,scalar=1.25]
//                                ground classification (smrf.hpp): class 2 ground, 1 the rest
//   hag                          height_above_ground column (neighbours.hpp)
//   outlier[:k=8,multiplier=2]   drop statistical outliers
//   voxel:R                      one point per R-cube, the nearest its centre
//   poisson:R                    no two points closer than R, in file order
//   crop:MINX,MINY,MAXX,MAXY     keep a box (x, y); crop:MINX,MINY,MINZ,MAXX,MAXY,MAXZ with z
//   polygon:FILE                 keep the points inside a GeoJSON or WKT polygon file
//
// Lengths are in the points' units, but smrf's, which are metres (filters/units.hpp).
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "vola/builder.hpp"
#include "vola/filters/crop.hpp"
#include "vola/filters/expression.hpp"
#include "vola/filters/neighbours.hpp"
#include "vola/filters/smrf.hpp"

namespace vola::filters {

struct Stage {
  enum class Kind { where, smrf, hag, outlier, voxel, poisson, crop, polygon };
  Kind kind = Kind::where;
  std::string spec;  // as written
  std::optional<Expression> expression;  // where
  SmrfOptions smrf;
  OutlierOptions outlier;
  double size = 0.0;  // voxel, poisson
  CropBox box;
  PolygonSet polygons;
  // Whether the stage looks at one point at a time (where, crop, polygon), so that it
  // can run on a file chunk by chunk.
  bool per_point() const noexcept { return kind == Kind::where || kind == Kind::crop || kind == Kind::polygon; }
};

// One stage from its string; throws OptionError("filters", ...) naming the stage and
// what is wrong (an unknown name lists the known ones). A polygon file is read here.
Stage parse_stage(const std::string& spec);
std::vector<Stage> parse_stages(const std::vector<std::string>& specs);

// What one stage did.
struct StageReport {
  std::string spec;
  std::uint64_t points_in = 0, points_out = 0;
  std::uint64_t ground = 0;  // smrf: points classified ground
};

struct FilterResult {
  std::vector<std::uint64_t> kept;  // input index of each point left, increasing
  std::vector<StageReport> stages;
};

// Runs the stages in order on `cloud` (points dropped, columns changed or added);
// `epsg`/`wkt` name the points' CRS for the metre parameters of smrf. `first_index`
// numbers the points for FilterResult::kept (a chunk's offset in its file).
FilterResult run_stages(const std::vector<Stage>& stages, PointCloud& cloud, const std::optional<std::uint32_t>& epsg,
                        const std::string& wkt, std::uint64_t first_index = 0);

// The points of `cloud` the per-point stages keep (all of `stages` must be per_point()).
std::vector<bool> per_point_mask(const std::vector<Stage>& stages, const PointCloud& cloud);

}  // namespace vola::filters
