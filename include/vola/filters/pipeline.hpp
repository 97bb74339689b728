// PDAL-style JSON pipelines: an array of stages (or {"pipeline": [...]}), a reader first,
// filters, then writers, as `vola pipeline FILE.json` runs them:
//
//   ["autzen.laz",
//    {"type": "filters.smrf"},
//    {"type": "filters.range", "limits": "Classification[2:2]"},
//    "ground.laz"]
//
// A file named without a type is the reader when first, a writer when last (its kind
// from the extension, its options checked as that stage's) and refused anywhere else,
// where PDAL reads it as one more input.
//
// Readers: a file name, or {"type": "readers.las" (or any readers.*), "filename": ...}.
// Filters, each into one stage string of stages.hpp: filters.smrf (cell, slope, window,
// threshold, scalar), filters.range (limits "Dim[min:max]" with () for open ends and !
// to negate; ranges of one dimension are joined by ||, of different ones by &&, as PDAL
// does), filters.expression (expression), filters.hag_nn / filters.hag, filters.outlier
// (mean_k, multiplier; method "statistical"), filters.crop (bounds "([x0, x1], [y0, y1])"
// or with [z0, z1], a GeoJSON bbox, or an object of minx ... maxz; polygon as WKT),
// filters.sample (radius or cell: Poisson), filters.voxelcenternearestneighbor (cell, 1
// by default). Writers: a file name, or
// {"type": "writers.las" | "writers.ply" | "writers.text" | "writers.vola", "filename": ...};
// .vol writers take "voxel_size", "depth", "compress", "dense", "attributes".
// Every error names the stage's index (0-based, as in the array) and what is wrong.
#pragma once

#include <map>
#include <string>
#include <vector>

namespace vola::filters {

struct PipelineWriter {
  std::string filename;
  // .vol writers: option name -> value as JSON text ("2.5", "true", "\"EPSG:2994\"").
  std::map<std::string, std::string> options;
  bool voxels() const;  // a .vol output
};

struct Pipeline {
  std::string input;
  std::vector<std::string> stages;  // stage strings (stages.hpp)
  std::vector<PipelineWriter> writers;
};

// Throws InvalidArgument "pipeline stage N (TYPE): ..." for anything it cannot run.
Pipeline parse_pipeline(const std::string& json, const std::string& name);

// PDAL's filters.range limits as a --where expression: "Classification[2:2],Z(:500]"
// -> "(Classification >= 2 && Classification <= 2) && (Z < 500)". Throws InvalidArgument.
std::string range_expression(const std::string& limits);

}  // namespace vola::filters
