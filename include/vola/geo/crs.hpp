// Coordinate reference systems through PROJ: the header's lat/lon of the bbox centre
// (as the reference computes it) and the CRS as WKT for our extension.
#pragma once

#include <cstdint>
#include <memory>
#include <optional>
#include <span>
#include <string>
#include <utility>

#include "vola/frame.hpp"

namespace vola::geo {

// WGS84 (lat, lon) of the bbox centre ((minx+maxx)/2, (miny+maxy)/2) given in
// EPSG:`epsg`, with x = easting/longitude (PROJ's always_xy). Throws vola::Error for
// a code PROJ does not know or a point it cannot transform.
std::pair<double, double> centre_lat_lon(std::uint32_t epsg, const Box& bbox);
// The same for a CRS given as WKT (or any definition PROJ accepts).
std::pair<double, double> centre_lat_lon(const std::string& crs, const Box& bbox);

// The CRS as WKT2 (2019), or throws vola::Error for an unknown code.
std::string crs_wkt(std::uint32_t epsg);

// The projected or geographic 2D CRS EPSG:`epsg` as a GeoTIFF key directory (LAS files
// carry one) qualifies it, as GDAL reads the keys, in WKT2 (2019); empty when the code
// alone says it all (or is neither kind of CRS PROJ knows). Unit arguments are EPSG unit
// codes (0 or anything that is not a length unit: none):
//  - `linear_unit` (ProjLinearUnitsGeoKey) other than the code's own: the code's CRS with
//    its coordinates in that unit (the parameters keep their meaning: a false easting of
//    700000 m is 2296583.33 US survey feet). pdal_mvk-thin.las is NAD83 / Mississippi West
//    (EPSG:26995, metres) in US survey feet.
//    A geographic CRS's degrees take no linear unit.
//  - `vertical_unit` (VerticalUnitsGeoKey, for files that name no vertical CRS) other than
//    the horizontal unit (for a geographic CRS: other than metres, the unit its heights
//    have without one): a compound CRS whose vertical part, of unknown datum, is in that
//    unit (GDAL's reading with GTIFF_REPORT_COMPD_CS), so that heights are not taken in
//    the unit of x and y.
// Throws vola::Error when PROJ cannot be loaded or fails outside these rules.
std::string keyed_projected_crs(std::uint32_t epsg, std::uint32_t linear_unit, std::uint32_t vertical_unit = 0);

// The EPSG code of a CRS given as WKT (the horizontal part of a compound CRS), from
// its own identifier or, failing that, PROJ's identification with confidence >= 70%.
std::optional<std::uint32_t> epsg_from_wkt(const std::string& wkt);

// Whether two CRS definitions (WKT of any version, PROJ strings, "EPSG:<code>") name the
// same CRS by meaning, as PROJ judges it (proj_is_equivalent_to), whatever the
// spelling of names ("GRS 1980" or "GRS_1980") and axis order of geographic CRSs aside.
// Throws vola::Error when PROJ cannot read either.
bool same_crs(const std::string& a, const std::string& b);

// A CRS's WKT may carry a PROJ string (WKT1's EXTENSION["PROJ4", ...], WKT2's
// REMARK["PROJ CRS string: ..."]), which PROJ follows when a transformation is built with
// the CRS. vola's own PROJ contexts open files only inside PROJ's data folders, but
// GDAL's (the DEM reader, GeoTIFF export, tile footprints) open whatever file such a
// string names ("+init=/any/file:id", grids by name or path). The first such reference
// in `crs_text` ("+init=...", "+nadgrids=...": any grid but PROJ's built-in @null), or
// empty when there is none. Pure text: PROJ is not asked.
std::string crs_file_reference(const std::string& crs_text);

// What PROJ says a CRS is, for people.
struct CrsDescription {
  std::string name;                   // the CRS's own name
  std::string kind;                   // "projected", "geographic 2D", "compound", ...
  // The horizontal part's EPSG id, or PROJ's identification of it at >= 70% (equivalent);
  // none rather than a guess.
  std::optional<std::uint32_t> epsg;
  std::string horizontal_unit;        // "metre", "US survey foot", "degree", ...
  std::string vertical_name;          // the vertical CRS of a compound one (else empty)
  std::string vertical_unit;
};
// How describe_crs finds `epsg`: `search` asks PROJ to identify the CRS in its database
// when it carries no EPSG id of its own; `own_id_only` skips that search (it loads a few
// MiB of PROJ's database), for callers that want only the kind and units.
enum class EpsgLookup { search, own_id_only };
// Throws vola::Error when PROJ cannot read the definition.
CrsDescription describe_crs(const std::string& definition, EpsgLookup lookup = EpsgLookup::search);
// One line: "NAD83(HARN) / Oregon GIC Lambert (ft) (EPSG:2994), projected, foot" or, with
// no code, "... (no EPSG code), ..."; a compound CRS adds "; vertical NAME (UNIT)".
std::string crs_summary(const CrsDescription& crs);

// A CRS definition of any kind PROJ reads ("EPSG:32610", WKT 1 or 2, a PROJ string) as
// WKT2 (2019). Throws vola::Error when PROJ cannot read it.
std::string crs_wkt(const std::string& definition);

// Points from one CRS to another through PROJ (proj_create_crs_to_crs, the best
// transformation PROJ knows for the pair, axes in x = easting/longitude order, z
// converted when both CRSs have a vertical part), in batches of x y z triples in place,
// on all cores (vola::parallel_for, one PROJ object per worker). One transform() at a
// time per object.
class Reprojection {
 public:
  // Throws vola::Error when PROJ cannot read either CRS or has no transformation.
  // `threads`: at most this many for one transform() (0: vola::thread_count()); 1 for
  // callers that are themselves parallel workers.
  Reprojection(const std::string& from, const std::string& to, unsigned threads = 0);
  ~Reprojection();
  Reprojection(Reprojection&&) noexcept;
  Reprojection& operator=(Reprojection&&) noexcept;
  // Throws vola::Error naming the first point PROJ cannot transform.
  void transform(std::span<double> xyz) const;

 private:
  struct State;
  std::unique_ptr<State> state_;
};

// Two trees to be combined voxel for voxel (set operations): when both state a CRS and
// they differ by meaning (not equal, and PROJ does not find them equivalent, or cannot
// read one), what each is, for the error ("NAD83 / UTM zone 10N (EPSG:26910), projected,
// metre"); nullopt when they agree or either states none (the caller may warn).
struct CrsPair {
  std::string a, b;
};
std::optional<CrsPair> different_crs(const Georef& a, const Georef& b);

// The header's EPSG code when nobody said what the CRS is: the reference's default,
// which names no real CRS of the data.
inline constexpr std::uint32_t kUnsetEpsg = 2000;

// What the tree says its CRS is, as PROJ takes it: the WKT of our extension if
// present, else "EPSG:<code>" from the header, else nullopt (header code kUnsetEpsg
// and no WKT: the file has no CRS, and nothing should invent one).
std::optional<std::string> crs_definition(const Georef& georef);

// A CRS given as WKT of any version or "EPSG:<code>", written as OGC WKT 1 (the GDAL
// flavour LAS readers expect). Throws vola::Error when PROJ cannot read or write it.
std::string crs_wkt1(const std::string& definition);

// Many points from one CRS to WGS84 longitude/latitude through one PROJ
// transformation, created once.
class ToWgs84 {
 public:
  // Throws vola::Error for a CRS PROJ does not know.
  explicit ToWgs84(const std::string& definition);
  ~ToWgs84();
  ToWgs84(ToWgs84&&) noexcept;
  ToWgs84& operator=(ToWgs84&&) noexcept;

  // {longitude, latitude, z} with z passed through unchanged. Throws vola::Error for a
  // point PROJ cannot transform (outside the CRS's domain).
  Point transform(const Point& p) const;

 private:
  struct State;
  std::unique_ptr<State> state_;
};

}  // namespace vola::geo
