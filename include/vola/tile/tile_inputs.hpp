// What `vola tile` tiles, as the CLI and Python share it: point files (and a generated
// survey) opened as sources, moved into a target CRS, and the CRS every tile carries.
#pragma once

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "vola/tile/point_source.hpp"
#include "vola/tile/tiler.hpp"

namespace vola::tile {

struct TileInputs {
  // Members are named as the front ends' options (errors name them in `backticks`).
  std::vector<std::string> inputs;  // LAS/LAZ/COPC streamed in chunks; any other point file read whole
  std::uint64_t generate_survey = 0;  // > 0: also a generated survey of this many points
  SurveyOptions survey;               // its density and seed (points: generate_survey)
  // A CRS as a user names it (crs_definition_of): assign relabels the inputs, target
  // moves their points into it.
  std::string assign_crs, target_crs;
  bool allow_geographic = false;  // tile in degrees of a geographic CRS
  std::size_t chunk_points = 0;   // LAS points per work unit; 0: chunk_points_for(options)
  // Per-point filter stages (where, crop, polygon: vola/filters/stages.hpp), run on each
  // chunk in the inputs' own CRS, before any reprojection.
  std::vector<std::string> filters;
};

struct OpenedInputs {
  std::vector<std::unique_ptr<PointSource>> sources;
  std::uint64_t points = 0;  // over the sources
  // An input that states another CRS than assign_crs (relabelled without moving).
  std::vector<std::string> warnings;
  std::vector<const PointSource*> views() const;
};

// Opens the inputs (options.attributes says whether their columns are read), reprojects
// them when target_crs is given, and sets options.epsg and options.crs_wkt: assign_crs,
// else what the inputs say (they must agree). Throws InvalidArgument (an OptionError
// naming the member where one is to blame) for no input, a path that is not a regular
// file, an input with no CRS to reproject from, inputs that disagree, or a geographic CRS
// unless allow_geographic.
OpenedInputs open_inputs(const TileInputs& inputs, TileOptions& options);

}  // namespace vola::tile
