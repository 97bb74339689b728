// ASTM E57 (E2807) 3D imaging files, as terrestrial laser scanners and their software
// (Leica, FARO, Trimble, CloudCompare, PDAL, libE57Format) write them: the XML section
// describes each scan (data3D), its pose and the fields of its points, and a binary
// section per scan holds the points as bit-packed bytestreams. Read natively from the
// standard (no E57 library is packaged for Debian 12): every page's checksum is checked,
// points come in cartesian or spherical coordinates, each scan moved by its pose.
#pragma once

#include <array>
#include <cstdint>
#include <string>
#include <vector>

#include "vola/io/input.hpp"

namespace vola::io {

// One scan of the file, as its XML states it.
struct E57Scan {
  std::string name;
  std::uint64_t records = 0;                   // the points stored, invalid ones included
  std::vector<std::string> fields;             // the prototype's field names, in stream order
  bool has_pose = false;                       // a rotation or translation other than none
  std::array<double, 4> rotation{1, 0, 0, 0};  // quaternion w x y z (normalised)
  std::array<double, 3> translation{0, 0, 0};
};

struct E57Summary {
  std::uint32_t version_major = 0, version_minor = 0;
  std::string library;  // e57LibraryVersion, when stated
  std::string crs;      // coordinateMetadata (WKT, EPSG:code, ...), when stated
  std::vector<E57Scan> scans;
  std::uint64_t images = 0;  // images2D entries (not read)
};
// What the file's XML says; throws FormatError naming the file (and the byte) when the
// header, a page checksum or the XML is wrong.
E57Summary e57_summary(const std::string& path);

// Every scan's valid points in one cloud, in world coordinates (each scan's pose applied:
// rotation, then translation): cartesianX/Y/Z, else sphericalRange/Azimuth/Elevation
// (x = r cos(elevation) cos(azimuth), y = r cos(elevation) sin(azimuth), z = r
// sin(elevation)). Points whose cartesianInvalidState (sphericalInvalidState) is not 0
// are left out and counted in Input::not_finite. Columns, kept when every scan has the
// field: intensity, red/green/blue (colorRed/Green/Blue), return_index (returnIndex as
// stored: the standard counts from 0, some converters write LAS's 1-based numbers),
// number_of_returns (returnCount) and any other numeric field by its name as text columns
// are named (an extension's prefix dropped: las:pointSourceId -> point_source_id). The CRS
// from coordinateMetadata: "EPSG:N" as a code, other text as a definition (WKT).
Input read_e57(const std::string& path, const InputOptions& options);

}  // namespace vola::io
