// Runs a PDAL-style JSON pipeline (vola/filters/pipeline.hpp describes the JSON): one
// reader, point filters, writers. Point outputs (.las, .laz, .ply, .xyz) go through
// `vola translate`'s writers with the filters applied to the records; .vol outputs
// through the conversion pipeline (convert.hpp) with the same filters. `vola pipeline`
// and Python's vola.pipeline both call this, so a pipeline means one thing everywhere.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "vola/filters/stages.hpp"

namespace vola {

struct PipelineOutputReport {
  std::string input, output;
  bool voxels = false;             // a .vol written by the conversion pipeline
  std::uint64_t voxel_count = 0;   // .vol outputs
  std::vector<std::string> filter_lines;          // .vol outputs: ConvertReport::filters
  std::vector<filters::StageReport> stages;       // each stage's counts
  std::vector<std::string> warnings;              // for the user: CRS relabelled, CRS not kept, ...
};

// `json` is the pipeline's text; `name` (its file name, or "<string>") names it in errors.
// Throws InvalidArgument "pipeline stage N (TYPE): ..." for a pipeline it cannot run, and
// the readers' and writers' errors as convert_file and translate_points throw them.
std::vector<PipelineOutputReport> run_pipeline(const std::string& json, const std::string& name);

}  // namespace vola
