// Internal to the conversion pipeline: the CRS rules, decided once for every front end.
#pragma once

#include <cstdint>
#include <future>
#include <optional>
#include <string>
#include <utility>

#include "vola/convert.hpp"
#include "vola/crs_rules.hpp"
#include "vola/geo/crs.hpp"
#include "vola/io/input.hpp"

namespace vola::convert_detail {

// The CRS the user assigned (`assign_crs`, or `epsg` as digits); empty when none.
std::string given_crs(const ConvertOptions& options);

// The input's CRS under the rules of vola/crs_rules.hpp (the CRS given wins).
ResolvedCrs input_crs(const std::string& path, const ConvertOptions& options, const io::Input& input);

// The points of `input` moved into options.target_crs from the input's CRS; the CRS
// of the result (the target, as given). Throws OptionError("target_crs") for input that
// is not points or states no CRS, and for a target PROJ cannot read.
ResolvedCrs reproject(const std::string& path, const ConvertOptions& options, io::Input& input);

// Throws OptionError for grid voxels of points in a geographic CRS (x and y in degrees, z
// in metres or feet: not cubes) unless options.allow_geographic; toolkit quantization,
// which fits any box, is only warned about.
void refuse_geographic_grid(const std::string& path, const ConvertOptions& options, const io::Input& input,
                            const ResolvedCrs& crs, Quantization quantization);

// Warnings about the CRS of a conversion: a CRS assigned to an input that states another
// (the coordinates are relabelled, not moved), and a geographic CRS (voxels whose x and y
// are degrees while z is in metres or feet).
std::vector<std::string> crs_warnings(const std::string& path, const ConvertOptions& options, const io::Input& input,
                                      const ResolvedCrs& crs);

// Under a geographic CRS, coordinates no longitude or latitude can be (|x| > 180 or
// |y| > 90: a scanner's export labelled WGS 84 that holds UTM metres), or under a
// geocentric one, points nowhere near the earth's surface: the sentence that says the
// label is likely wrong; else "".
std::string implausible_label(const std::string& path, const ResolvedCrs& crs, const Box& bounds);

// Before the points are reprojected: a `height` column (each point's z, or a LAS
// extra-bytes height, a z too) is reprojected as the z of its point's x and y, so that
// it ends in the target's vertical unit like the voxels (Autzen's feet became metres,
// its heights did not).
void reproject_heights(const geo::Reprojection& reprojection, PointCloud& cloud);

// The code the VOLA header carries: the known one, else the reference's default (2000).
std::uint32_t header_epsg(const std::optional<std::uint32_t>& known);

// The WGS84 (lat, lon) of the bbox centre, as geo::centre_lat_lon gives it. PROJ's
// transformation (its database, a third of a small conversion) is created on another
// thread while the tree is built; lat_lon() waits for it and rethrows its error.
class CentreLatLon {
 public:
  // The CRS the header's lat/lon are computed from: the known code (or the reference's
  // default), else the WKT.
  CentreLatLon(const std::optional<std::uint32_t>& known, const std::string& wkt);
  // (lat, lon), or none when the centre lies outside the CRS's domain. Call once.
  std::optional<std::pair<double, double>> lat_lon(const Box& bbox);

 private:
  std::future<geo::ToWgs84> transform_;
};

// The tree's georeference after the build: the header code, the WGS84 lat/lon of the
// bbox centre (through PROJ; 0, 0 when PROJ cannot place a CRS nobody named; +inf, as the
// reference toolkit writes them, for a centre outside the CRS's domain), and the CRS
// as WKT in the extension whenever it is known, except for a toolkit conversion of
// CRS-less input, which stays byte-identical to the reference's file. Returns a warning
// for a centre outside the domain of a CRS the input or the user named.
std::optional<std::string> georeference(Tree& tree, const ResolvedCrs& crs, Quantization quantization,
                                        CentreLatLon& centre);

}  // namespace vola::convert_detail
