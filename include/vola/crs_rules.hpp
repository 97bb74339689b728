// The CRS rules of every conversion, decided once: what the inputs say, what the user
// names, and what the output carries. `vola convert` and `vola tile` (and the Python and C
// front ends through vola::convert) take their CRS from here.
#pragma once

#include <cstdint>
#include <optional>
#include <span>
#include <string>

#include "vola/frame.hpp"

namespace vola {

// What one input says its CRS is.
struct StatedCrs {
  std::string source;                  // the input's name, for errors
  std::optional<std::uint32_t> epsg;   // a code the input states
  std::string wkt;                     // a WKT the input states
};

// The CRS of a conversion.
struct ResolvedCrs {
  // The EPSG code: the one given, else the inputs' (stated, or found by PROJ from their
  // WKT with high confidence); none when nobody knows one.
  std::optional<std::uint32_t> epsg;
  // The CRS as WKT: the given code's, else the inputs' WKT, else their code's; empty
  // when the inputs have no CRS.
  std::string wkt;
  bool given = false;      // the user named the code
  bool stated = false;     // the inputs said something
};

// A CRS as a user may name it: "32610" means "EPSG:32610"; anything else (EPSG:n, WKT,
// a PROJ string) is kept as it is.
std::string crs_definition_of(const std::string& given);

// The EPSG code a definition names directly ("32610", "EPSG:32610"), else none.
std::optional<std::uint32_t> epsg_code_of(const std::string& given);

// `given` (a definition as crs_definition_of reads it; empty: none) wins over what the
// inputs say, relabelling them (and fails for a CRS PROJ does not know, before any work);
// without it, the inputs must agree by meaning (the same code, or WKTs PROJ finds
// equivalent however they are spelled, or all nothing), else InvalidArgument names the
// first two that differ.
ResolvedCrs resolve_crs(std::span<const StatedCrs> inputs, const std::string& given = {});

// Whether a CRS (WKT or any definition) is geographic: x and y in degrees. False for
// what PROJ cannot read.
bool is_geographic_crs(const std::string& definition);

// PROJ (and PDAL) leave z alone between two CRSs without vertical axes: a survey in feet
// reprojected to UTM keeps its heights in feet under a CRS in metres. When reprojecting
// `source` to `target` (definitions as crs_definition_of reads them) does that (neither
// has a vertical axis, their units differ, the source is not in degrees), the sentence to
// tell the user; else "". "" too for what PROJ cannot read. So too for a compound source
// (its vertical part in another unit than the target's) reprojected to a target with no
// vertical part: PROJ moves x and y and leaves z in the source's vertical unit.
std::string unconverted_heights(const std::string& source, const std::string& target);

// Whether assigning `assigned` to points that state `stated` moves their meaning in x and
// y: false when it is the same CRS, or a compound CRS whose horizontal part is the stated
// one (the heights given a vertical datum). Throws vola::Error when PROJ cannot read either.
bool relabels_horizontally(const std::string& stated, const std::string& assigned);

// A compound CRS whose heights are in another unit than x and y (NAD83 / Oregon Lambert in
// metres + NAVD88 in US survey feet): voxels of one size in it are not cubes. The sentence
// to tell the user; else "" (one unit, degrees, or what PROJ cannot read).
std::string mixed_units(const std::string& definition);

// Coordinates no longitude or latitude can be (|x| > 180 or |y| > 90) under a geographic
// CRS `definition`: a label that is likely wrong (a RiSCAN export labelled WGS 84 holding
// UTM metres). The sentence to tell the user, from the points' or tiles' box (min x, min y,
// max x, max y); else "" (in range, not geographic, or what PROJ cannot read).
std::string implausible_degrees(const std::string& definition, double min_x, double min_y, double max_x, double max_y);

// Points whose box centre lies nowhere near the earth's surface (closer to its centre than
// 6200 km or farther than 6500 km) under a geocentric CRS `definition` (PDAL's
// lone-star.laz: keys saying geocentric WGS 84 over UTM metres). The sentence to tell the
// user; else "" (plausible, not geocentric, or what PROJ cannot read).
std::string implausible_geocentric(const std::string& definition, const Box& box);

}  // namespace vola
