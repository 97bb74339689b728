// Where `vola tile` gets its points: lists of chunks that can be read independently,
// in any order, by any thread or process. Work is shared by handing out chunk numbers,
// so no reader state is shared between workers (nor memory between MPI ranks).
#pragma once

#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "vola/frame.hpp"
#include "vola/stream_builder.hpp"

namespace vola::tile {

class PointSource {
 public:
  virtual ~PointSource() = default;
  virtual const std::string& name() const noexcept = 0;
  virtual std::uint64_t chunk_count() const noexcept = 0;
  virtual std::uint64_t point_count() const noexcept = 0;
  // Replaces `xyz` with the chunk's points (x y z per point). Safe to call from many
  // threads at once. Throws vola::Error (file, offset, cause) on bad input.
  virtual void read_chunk(std::uint64_t chunk, std::vector<double>& xyz) const = 0;

  // The attribute columns the points carry, as `vola convert` keeps them from this
  // format (LAS: colour, intensity, classification, height, returns, extra bytes); none
  // by default.
  virtual std::vector<AttributeSpec> attributes() const { return {}; }
  // The chunk's points as read_chunk gives them, and values[a] (one per point) for each
  // entry a of attributes(). The default reads the points and has no values.
  virtual void read_chunk_with_values(std::uint64_t chunk, std::vector<double>& xyz,
                                      std::vector<std::vector<double>>& values) const {
    read_chunk(chunk, xyz);
    values.clear();
  }

  // What the input says its CRS is (nothing for generated points).
  std::optional<std::uint32_t> epsg;
  std::string wkt;
};

// A LAS file (1.0-1.4, any point format), read with pread: chunk c is records
// [c * chunk_points, (c + 1) * chunk_points) (a file cut meanwhile: an IoError). A LAZ or
// COPC file: chunk c is the file's own LAZ chunk c (chunk_points unused).
std::unique_ptr<PointSource> open_las_points(const std::string& path, std::size_t chunk_points = std::size_t{1} << 20);
// Any other point format `vola convert` reads, read whole (one chunk), with the
// attribute columns the format carries unless `attributes` is false.
std::unique_ptr<PointSource> open_file_points(const std::string& path, bool attributes = true);

// `source`'s points moved from CRS `from` into CRS `to` (any definition PROJ reads) as
// each chunk is read; the result states `to` as its CRS. Throws vola::Error when PROJ
// cannot read either CRS.
std::unique_ptr<PointSource> reprojected(std::unique_ptr<PointSource> source, const std::string& from,
                                         const std::string& to);

// `source`'s points that the per-point filter stages keep (where, crop, polygon in
// vola/filters/stages.hpp's spelling), chunk by chunk; the stages' dimensions are x, y, z
// and the source's attribute columns. Throws OptionError("filters") for a stage that
// needs each point's neighbours (smrf, hag, outlier, decimation).
std::unique_ptr<PointSource> filtered(std::unique_ptr<PointSource> source, const std::vector<std::string>& stages);

// A survey the project generates: square city blocks (vola::synth::generate_city, 200 m)
// side by side in rows, each block one chunk with its own seed, so that any worker can
// generate any block and the whole is never stored. `density` points per square metre
// fixes the area; the points are spread evenly over the blocks.
struct SurveyOptions {
  std::uint64_t points = 1'000'000;
  double density = 10.0;
  std::uint64_t seed = 1;
  Point origin{500000.0, 5000000.0, 100.0};
};
std::unique_ptr<PointSource> generated_survey(const SurveyOptions& options);

}  // namespace vola::tile
