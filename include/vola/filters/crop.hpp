// Cropping points to a box or to polygons (x and y only).
#pragma once

#include <array>
#include <optional>
#include <span>
#include <string>
#include <vector>

namespace vola::filters {

// A box in x and y, and in z when min_z/max_z are given; bounds included.
struct CropBox {
  double min_x = 0, min_y = 0, max_x = 0, max_y = 0;
  std::optional<double> min_z, max_z;
  bool contains(const double* p) const {
    return p[0] >= min_x && p[0] <= max_x && p[1] >= min_y && p[1] <= max_y && (!min_z || p[2] >= *min_z) &&
           (!max_z || p[2] <= *max_z);
  }
};

// Polygons, each as rings of (x, y) vertices (closed or not): the outer ring and its
// holes. A point is inside a polygon when it crosses an odd number of its rings' edges
// (even-odd, so holes need no special case), and inside the set when it is inside any
// polygon: overlapping polygons (two features, two members of a multipolygon) make a
// union, as in PDAL and every GIS.
struct PolygonSet {
  using Ring = std::vector<std::array<double, 2>>;
  std::vector<std::vector<Ring>> polygons;
  bool contains(double x, double y) const;
};

// A polygon from WKT (POLYGON, MULTIPOLYGON) or GeoJSON (a Polygon or MultiPolygon
// geometry, a Feature or a FeatureCollection of them: every polygon counts). Throws
// InvalidArgument naming what is wrong. Coordinates are taken as they are, in the
// points' CRS (no reprojection).
PolygonSet parse_polygons(const std::string& text, const std::string& name);
// The same from a file (.geojson/.json, or a WKT text file).
PolygonSet read_polygons(const std::string& path);

std::vector<bool> inside_box(std::span<const double> xyz, const CropBox& box);
std::vector<bool> inside_polygons(std::span<const double> xyz, const PolygonSet& polygons);

}  // namespace vola::filters
