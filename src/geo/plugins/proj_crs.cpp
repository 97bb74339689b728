// libvola_proj.so: coordinate reference systems through PROJ, behind the entry points of
// proj_plugin.hpp (vola/geo/crs.hpp documents what each does).
#include <proj.h>
#include <proj_experimental.h>  // proj_crs_alter_cs_linear_unit

#include <sys/types.h>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <memory>
#include <string>
#include <vector>

#include "../proj_plugin.hpp"
#include "vola/error.hpp"

namespace vola::geo {

namespace {

struct ContextDeleter {
  void operator()(PJ_CONTEXT* c) const { proj_context_destroy(c); }
};
struct PjDeleter {
  void operator()(PJ* p) const { proj_destroy(p); }
};
using Context = std::unique_ptr<PJ_CONTEXT, ContextDeleter>;
using Pj = std::unique_ptr<PJ, PjDeleter>;

// PROJ opens files a definition names: "+init=/any/file:id", grids ("+nadgrids=/any/file",
// a WKT PARAMETERFILE), and bare names in the current directory after its own. A
// definition read from a file (a LAS WKT record, a tile index's crs_wkt) may not make
// vola read other local files (docs/SECURITY.md, "no escapes"), so every context opens
// files through this API, which allows only paths inside PROJ's own data directories
// (proj_info().searchpath: PROJ_DATA, the user's PROJ folder, the installed data), after
// resolving "..", and symbolic links.
const std::vector<std::string>& proj_data_directories() {
  static const std::vector<std::string> directories = [] {
    std::vector<std::string> out;
    const char* searchpath = proj_info().searchpath;
    const std::string all = searchpath ? searchpath : "";
    for (std::size_t start = 0; start <= all.size();) {
      std::size_t end = all.find(':', start);
      if (end == std::string::npos) end = all.size();
      std::error_code error;
      const auto directory = std::filesystem::weakly_canonical(all.substr(start, end - start), error);
      if (end > start && !error) out.push_back(directory.string());
      start = end + 1;
    }
    return out;
  }();
  return directories;
}

bool inside_proj_data(const char* name) {
  if (!name || !*name) return false;
  std::error_code error;
  const std::string path = std::filesystem::weakly_canonical(std::filesystem::absolute(name, error), error).string();
  if (error) return false;
  for (const auto& d : proj_data_directories())
    if (path.size() > d.size() && path.compare(0, d.size(), d) == 0 && path[d.size()] == '/') return true;
  return false;
}

std::FILE* file_of(PROJ_FILE_HANDLE* handle) { return reinterpret_cast<std::FILE*>(handle); }

const PROJ_FILE_API kConfinedFiles{
    1,
    [](PJ_CONTEXT*, const char* name, PROJ_OPEN_ACCESS access, void*) -> PROJ_FILE_HANDLE* {
      if (!inside_proj_data(name)) return nullptr;
      const char* mode = access == PROJ_OPEN_ACCESS_READ_ONLY     ? "rb"
                         : access == PROJ_OPEN_ACCESS_READ_UPDATE ? "r+b"
                                                                  : "w+b";
      return reinterpret_cast<PROJ_FILE_HANDLE*>(std::fopen(name, mode));
    },
    [](PJ_CONTEXT*, PROJ_FILE_HANDLE* f, void* buffer, std::size_t bytes, void*) {
      return std::fread(buffer, 1, bytes, file_of(f));
    },
    [](PJ_CONTEXT*, PROJ_FILE_HANDLE* f, const void* buffer, std::size_t bytes, void*) {
      return std::fwrite(buffer, 1, bytes, file_of(f));
    },
    [](PJ_CONTEXT*, PROJ_FILE_HANDLE* f, long long offset, int whence, void*) -> int {
      return ::fseeko(file_of(f), static_cast<off_t>(offset), whence) == 0;
    },
    [](PJ_CONTEXT*, PROJ_FILE_HANDLE* f, void*) -> unsigned long long {
      const off_t at = ::ftello(file_of(f));
      return at < 0 ? 0 : static_cast<unsigned long long>(at);
    },
    [](PJ_CONTEXT*, PROJ_FILE_HANDLE* f, void*) { std::fclose(file_of(f)); },
    [](PJ_CONTEXT*, const char* name, void*) -> int {
      std::error_code error;
      return inside_proj_data(name) && std::filesystem::exists(name, error);
    },
    [](PJ_CONTEXT*, const char* name, void*) -> int {
      std::error_code error;
      if (!inside_proj_data(name)) return false;
      std::filesystem::create_directories(name, error);
      return std::filesystem::is_directory(name, error);
    },
    [](PJ_CONTEXT*, const char* name, void*) -> int { return inside_proj_data(name) && std::remove(name) == 0; },
    [](PJ_CONTEXT*, const char* from, const char* to, void*) -> int {
      return inside_proj_data(from) && inside_proj_data(to) && std::rename(from, to) == 0;
    },
};

Context make_context() {
  Context ctx(proj_context_create());
  if (!ctx) throw Error("PROJ: cannot create a context");
  proj_log_level(ctx.get(), PJ_LOG_NONE);
  if (!proj_context_set_fileapi(ctx.get(), &kConfinedFiles, nullptr)) throw Error("PROJ: cannot confine its file access");
  return ctx;
}

std::string last_error(PJ_CONTEXT* ctx) {
  const int code = proj_context_errno(ctx);
  return code ? proj_context_errno_string(ctx, code) : "unknown error";
}

// Whether `definition` is a geocentric (earth-centred Cartesian) CRS.
bool geocentric(PJ_CONTEXT* ctx, const std::string& definition) {
  const Pj crs(proj_create(ctx, definition.c_str()));
  return crs && proj_get_type(crs.get()) == PJ_TYPE_GEOCENTRIC_CRS;
}

std::pair<double, double> centre_lat_lon(const std::string& source, const Box& bbox) {
  Context ctx = make_context();
  Pj transform(proj_create_crs_to_crs(ctx.get(), source.c_str(), "EPSG:4326", nullptr));
  if (!transform) throw Error("CRS " + source.substr(0, 60) + " is not known to PROJ: " + last_error(ctx.get()));
  Pj normalized(proj_normalize_for_visualization(ctx.get(), transform.get()));
  if (!normalized) throw Error("PROJ cannot normalise the axis order of " + source);
  const double cx = (bbox.min[0] + bbox.max[0]) / 2.0;
  const double cy = (bbox.min[1] + bbox.max[1]) / 2.0;
  // A geocentric CRS's z is a third of the position (at z = 0 every point lies on the
  // equatorial plane); any other CRS is placed at height 0, as the reference toolkit
  // places it (a datum shift moves the longitude by ~1e-8 degrees with the height, and
  // the header must match the reference's byte for byte).
  const double cz = geocentric(ctx.get(), source) ? (bbox.min[2] + bbox.max[2]) / 2.0 : 0.0;
  const PJ_COORD out = proj_trans(normalized.get(), PJ_FWD, proj_coord(cx, cy, std::isfinite(cz) ? cz : 0.0, 0));
  if (!std::isfinite(out.xy.x) || !std::isfinite(out.xy.y))
    throw Error("PROJ cannot transform (" + std::to_string(cx) + ", " + std::to_string(cy) + ") from " + source.substr(0, 60) +
                " to WGS84: " + last_error(ctx.get()));  // NOLINT
  return {out.xy.y, out.xy.x};
}

std::string crs_wkt(std::uint32_t epsg) {
  Context ctx = make_context();
  const std::string source = "EPSG:" + std::to_string(epsg);
  Pj crs(proj_create(ctx.get(), source.c_str()));
  if (!crs) throw Error("CRS " + source + " is not known to PROJ: " + last_error(ctx.get()));
  const char* wkt = proj_as_wkt(ctx.get(), crs.get(), PJ_WKT2_2019, nullptr);
  if (!wkt) throw Error("PROJ cannot write " + source + " as WKT");
  return wkt;
}

// A bound CRS (a WKT1 TOWGS84 clause) is the CRS it binds, for naming and comparing.
Pj unbound(PJ_CONTEXT* ctx, Pj crs) {
  if (crs && proj_get_type(crs.get()) == PJ_TYPE_BOUND_CRS) crs.reset(proj_get_source_crs(ctx, crs.get()));
  return crs;
}

// The horizontal part: a bound CRS's source, a compound CRS's first component.
Pj horizontal_part(PJ_CONTEXT* ctx, Pj crs) {
  for (int guard = 0; crs && guard < 4; ++guard) {
    const PJ_TYPE type = proj_get_type(crs.get());
    if (type == PJ_TYPE_BOUND_CRS) crs.reset(proj_get_source_crs(ctx, crs.get()));
    else if (type == PJ_TYPE_COMPOUND_CRS) crs.reset(proj_crs_get_sub_crs(ctx, crs.get(), 0));
    else break;
  }
  return crs;
}

std::optional<std::uint32_t> epsg_code(const char* auth, const char* code) {
  if (!auth || !code || std::string(auth) != "EPSG") return std::nullopt;
  try {
    return static_cast<std::uint32_t>(std::stoul(code));
  } catch (...) {
    return std::nullopt;
  }
}

// The CRS's own EPSG id, else PROJ's identification at 70% or more: 70 is PROJ's
// "equivalent, names differ"; below that the candidates are not the same CRS, and no
// code is better than an invented one.
std::optional<std::uint32_t> identify_epsg(PJ_CONTEXT* ctx, const PJ* crs) {
  if (auto c = epsg_code(proj_get_id_auth_name(crs, 0), proj_get_id_code(crs, 0))) return c;
  int* confidence = nullptr;
  PJ_OBJ_LIST* candidates = proj_identify(ctx, crs, "EPSG", nullptr, &confidence);
  std::optional<std::uint32_t> best;
  if (candidates) {
    int best_confidence = 69;
    for (int i = 0; i < proj_list_get_count(candidates); ++i) {
      if (confidence[i] <= best_confidence) continue;
      Pj candidate(proj_list_get(ctx, candidates, i));
      if (auto c = epsg_code(proj_get_id_auth_name(candidate.get(), 0), proj_get_id_code(candidate.get(), 0))) {
        best = c;
        best_confidence = confidence[i];
      }
    }
    proj_int_list_destroy(confidence);
    proj_list_destroy(candidates);
  }
  return best;
}

std::optional<std::uint32_t> epsg_from_wkt(const std::string& wkt) {
  Context ctx = make_context();
  Pj crs = horizontal_part(ctx.get(), Pj(proj_create(ctx.get(), wkt.c_str())));
  if (!crs) return std::nullopt;
  return identify_epsg(ctx.get(), crs.get());
}

Pj create_crs(PJ_CONTEXT* ctx, const std::string& definition) {
  Pj crs(proj_create(ctx, definition.c_str()));
  if (!crs) throw Error("CRS " + definition.substr(0, 60) + " is not known to PROJ: " + last_error(ctx));
  return crs;
}

bool same_crs(const std::string& a, const std::string& b) {
  if (a == b) return true;
  Context ctx = make_context();
  const Pj first = unbound(ctx.get(), create_crs(ctx.get(), a));
  const Pj second = unbound(ctx.get(), create_crs(ctx.get(), b));
  return proj_is_equivalent_to_with_ctx(ctx.get(), first.get(), second.get(),
                                        PJ_COMP_EQUIVALENT_EXCEPT_AXIS_ORDER_GEOGCRS) != 0;
}

const char* kind_of(PJ_TYPE type) {
  switch (type) {
    case PJ_TYPE_PROJECTED_CRS: return "projected";
    case PJ_TYPE_GEOGRAPHIC_2D_CRS: return "geographic 2D";
    case PJ_TYPE_GEOGRAPHIC_3D_CRS: return "geographic 3D";
    case PJ_TYPE_GEOCENTRIC_CRS: return "geocentric";
    case PJ_TYPE_VERTICAL_CRS: return "vertical";
    case PJ_TYPE_COMPOUND_CRS: return "compound";
    case PJ_TYPE_ENGINEERING_CRS: return "engineering";
    default: return "other";
  }
}

// The unit of a CRS's first axis ("metre", "US survey foot", "degree").
std::string axis_unit(PJ_CONTEXT* ctx, const PJ* crs) {
  const Pj cs(proj_crs_get_coordinate_system(ctx, crs));
  const char* unit = nullptr;
  if (!cs || !proj_cs_get_axis_info(ctx, cs.get(), 0, nullptr, nullptr, nullptr, nullptr, &unit, nullptr, nullptr))
    return {};
  return unit ? unit : "";
}

CrsDescription describe_with_proj(const std::string& definition, EpsgLookup lookup) {
  Context ctx = make_context();
  const Pj crs = unbound(ctx.get(), create_crs(ctx.get(), definition));
  CrsDescription out;
  const char* name = proj_get_name(crs.get());
  out.name = name ? name : "";
  out.kind = kind_of(proj_get_type(crs.get()));
  const Pj horizontal = horizontal_part(ctx.get(), Pj(proj_clone(ctx.get(), crs.get())));
  if (horizontal) {
    out.epsg = lookup == EpsgLookup::search
                   ? identify_epsg(ctx.get(), horizontal.get())
                   : epsg_code(proj_get_id_auth_name(horizontal.get(), 0), proj_get_id_code(horizontal.get(), 0));
    out.horizontal_unit = axis_unit(ctx.get(), horizontal.get());
  }
  // GDAL names a CRS it builds from GeoTIFF keys "unnamed" (a geocentric model over a
  // geographic code); the code PROJ identified has a name of its own ("WGS 84").
  if ((out.name.empty() || out.name == "unnamed" || out.name == "unknown") && out.epsg &&
      proj_get_type(crs.get()) != PJ_TYPE_COMPOUND_CRS) {
    const std::string code = std::to_string(*out.epsg);
    const Pj known(proj_create_from_database(ctx.get(), "EPSG", code.c_str(), PJ_CATEGORY_CRS, 0, nullptr));
    if (const char* known_name = known ? proj_get_name(known.get()) : nullptr) out.name = known_name;
  }
  if (proj_get_type(crs.get()) == PJ_TYPE_COMPOUND_CRS) {
    const Pj vertical = unbound(ctx.get(), Pj(proj_crs_get_sub_crs(ctx.get(), crs.get(), 1)));
    if (vertical) {
      const char* vname = proj_get_name(vertical.get());
      out.vertical_name = vname ? vname : "";
      out.vertical_unit = axis_unit(ctx.get(), vertical.get());
    }
  }
  return out;
}

std::string crs_wkt1(const std::string& definition) {
  Context ctx = make_context();
  Pj crs(proj_create(ctx.get(), definition.c_str()));
  if (!crs) throw Error("CRS " + definition.substr(0, 60) + " is not known to PROJ: " + last_error(ctx.get()));
  // One line: some LAS readers stop a WKT at its first newline.
  const char* const options[] = {"MULTILINE=NO", nullptr};
  const char* wkt = proj_as_wkt(ctx.get(), crs.get(), PJ_WKT1_GDAL, options);
  if (!wkt) throw Error("PROJ cannot write " + definition.substr(0, 60) + " as WKT1");
  return wkt;
}

// A transformation to WGS84 longitude/latitude (x = easting/longitude in and out).
class Wgs84Transformation {
 public:
  explicit Wgs84Transformation(const std::string& definition)
      : ctx_(make_context()), source_(definition.substr(0, 60)), geocentric_(geocentric(ctx_.get(), definition)) {
    Pj transform(proj_create_crs_to_crs(ctx_.get(), definition.c_str(), "EPSG:4326", nullptr));
    if (!transform) throw Error("CRS " + source_ + " is not known to PROJ: " + last_error(ctx_.get()));
    // EPSG:4326 is latitude first; normalised, PROJ takes and gives x = easting/longitude.
    transform_.reset(proj_normalize_for_visualization(ctx_.get(), transform.get()));
    if (!transform_) throw Error("PROJ cannot normalise the axis order of " + source_);
  }

  Point transform(const Point& p) const {
    const double z = geocentric_ && std::isfinite(p[2]) ? p[2] : 0.0;  // as centre_lat_lon places points
    const PJ_COORD out = proj_trans(transform_.get(), PJ_FWD, proj_coord(p[0], p[1], z, 0));
    if (!std::isfinite(out.xy.x) || !std::isfinite(out.xy.y))
      throw Error("PROJ cannot transform (" + std::to_string(p[0]) + ", " + std::to_string(p[1]) + ") from " +
                  source_ + " to WGS84: " + last_error(ctx_.get()));
    return {out.xy.x, out.xy.y, p[2]};
  }

 private:
  Context ctx_;
  Pj transform_;
  std::string source_;
  bool geocentric_ = false;
};

// A CRS's name as PROJ gives it ("WGS 84 / UTM zone 10N"), else the definition's start:
// for messages, where a WKT's first 60 characters say little.
std::string crs_name(PJ_CONTEXT* ctx, const std::string& definition) {
  const Pj crs(proj_create(ctx, definition.c_str()));
  const char* name = crs ? proj_get_name(crs.get()) : nullptr;
  return name && *name ? name : definition.substr(0, 60);
}

// Points from one CRS to another, in place, one batch at a time (proj_trans_generic over
// strided x y z). Own context: one object per thread.
class Reprojection {
 public:
  Reprojection(const std::string& from, const std::string& to)
      : ctx_(make_context()), names_(crs_name(ctx_.get(), from) + " to " + crs_name(ctx_.get(), to)) {
    Pj transform(proj_create_crs_to_crs(ctx_.get(), from.c_str(), to.c_str(), nullptr));
    if (!transform) throw Error("PROJ has no transformation from " + names_ + ": " + last_error(ctx_.get()));
    transform_.reset(proj_normalize_for_visualization(ctx_.get(), transform.get()));
    if (!transform_) throw Error("PROJ cannot normalise the axis order of " + names_);
  }

  void transform(double* xyz, std::size_t points) {
    constexpr std::size_t stride = 3 * sizeof(double);
    proj_errno_reset(transform_.get());
    // The batch as it came, to name a point PROJ fails on (it is overwritten in place).
    before_.assign(xyz, xyz + 3 * points);
    proj_trans_generic(transform_.get(), PJ_FWD, xyz, stride, points, xyz + 1, stride, points, xyz + 2, stride, points,
                       nullptr, 0, 0);
    for (std::size_t i = 0; i < points; ++i)
      if (!std::isfinite(xyz[3 * i]) || !std::isfinite(xyz[3 * i + 1]) || !std::isfinite(xyz[3 * i + 2])) {
        char at[128];
        std::snprintf(at, sizeof at, "(%.10g, %.10g, %.10g)", before_[3 * i], before_[3 * i + 1], before_[3 * i + 2]);
        throw Error("PROJ cannot transform the point " + std::string(at) + " from " + names_ +
                    " (outside the source CRS's area, or a CRS label that does not fit the coordinates?)");
      }
  }

 private:
  Context ctx_;
  Pj transform_;
  std::string names_;
  std::vector<double> before_;
};

// A CRS definition (code, WKT of any version, PROJ string) as WKT: WKT2 2019 as
// crs_wkt writes a code.
std::string crs_wkt_of(const std::string& definition) {
  Context ctx = make_context();
  const Pj crs = create_crs(ctx.get(), definition);
  const char* wkt = proj_as_wkt(ctx.get(), crs.get(), PJ_WKT2_2019, nullptr);
  if (!wkt) throw Error("PROJ cannot write " + definition.substr(0, 60) + " as WKT");
  return wkt;
}

// An EPSG length unit: its name and metres, or nothing (unknown code, not a length).
std::optional<std::pair<std::string, double>> length_unit(PJ_CONTEXT* ctx, std::uint32_t code) {
  const std::string text = std::to_string(code);
  const char* name = nullptr;
  const char* category = nullptr;
  double metres = 0;
  if (!proj_uom_get_info_from_database(ctx, "EPSG", text.c_str(), &name, &metres, &category) || !category ||
      std::string(category) != "linear" || !name || !(metres > 0))
    return std::nullopt;
  return std::make_pair(std::string(name), metres);
}

// Metres per unit of a CRS's first axis (0 when PROJ cannot say).
double axis_metres(PJ_CONTEXT* ctx, const PJ* crs) {
  const Pj cs(proj_crs_get_coordinate_system(ctx, crs));
  double metres = 0;
  if (!cs || !proj_cs_get_axis_info(ctx, cs.get(), 0, nullptr, nullptr, nullptr, &metres, nullptr, nullptr, nullptr))
    return 0;
  return metres;
}

bool same_length(double a, double b) { return std::abs(a - b) <= 1e-12 * std::max(a, b); }

// The projected (or geographic 2D) CRS EPSG:`epsg` as GeoTIFF keys qualify it
// (geo::keyed_projected_crs).
std::string keyed_projected_crs(std::uint32_t epsg, std::uint32_t linear_unit, std::uint32_t vertical_unit) {
  Context ctx = make_context();
  const std::string code = std::to_string(epsg);
  Pj crs(proj_create_from_database(ctx.get(), "EPSG", code.c_str(), PJ_CATEGORY_CRS, 0, nullptr));
  if (!crs) return {};
  const PJ_TYPE type = proj_get_type(crs.get());
  if (type != PJ_TYPE_PROJECTED_CRS && type != PJ_TYPE_GEOGRAPHIC_2D_CRS) return {};
  const bool geographic = type == PJ_TYPE_GEOGRAPHIC_2D_CRS;
  // Heights beside degrees are metres unless the keys say otherwise (GDAL reads a
  // geographic code with a VerticalUnitsGeoKey of feet as heights in feet).
  const double height_metres = geographic ? 1.0 : axis_metres(ctx.get(), crs.get());
  bool changed = false;
  if (const auto unit = length_unit(ctx.get(), linear_unit);
      !geographic && unit && !same_length(axis_metres(ctx.get(), crs.get()), unit->second)) {
    const std::string unit_code = std::to_string(linear_unit);
    Pj altered(proj_crs_alter_cs_linear_unit(ctx.get(), crs.get(), unit->first.c_str(), unit->second, "EPSG",
                                             unit_code.c_str()));
    if (!altered) return {};
    crs = std::move(altered);
    changed = true;
  }
  if (const auto unit = length_unit(ctx.get(), vertical_unit);
      unit && !same_length(changed ? axis_metres(ctx.get(), crs.get()) : height_metres, unit->second)) {
    // Heights in another unit than x and y, with no vertical CRS named: a vertical CRS of
    // unknown datum in that unit, as GDAL reads such keys (GTIFF_REPORT_COMPD_CS).
    const Pj vertical(proj_create_vertical_crs(ctx.get(), "unknown", "unknown", unit->first.c_str(), unit->second));
    if (!vertical) return {};
    const char* horizontal_name = proj_get_name(crs.get());
    const std::string name = std::string(horizontal_name ? horizontal_name : "unknown") + " + unknown";
    Pj compound(proj_create_compound_crs(ctx.get(), name.c_str(), crs.get(), vertical.get()));
    if (!compound) return {};
    crs = std::move(compound);
    changed = true;
  }
  if (!changed) return {};
  const char* wkt = proj_as_wkt(ctx.get(), crs.get(), PJ_WKT2_2019, nullptr);
  return wkt ? wkt : "";
}

using plugin::PluginFailure;
using vola::plugin::capture_failure;

const plugin::ProjEntries kEntries{
    [](const std::string& crs, const Box& bbox, std::pair<double, double>& out, PluginFailure& failure) {
      capture_failure(failure, [&] { out = centre_lat_lon(crs, bbox); });
    },
    [](std::uint32_t epsg, std::string& out, PluginFailure& failure) {
      capture_failure(failure, [&] { out = crs_wkt(epsg); });
    },
    [](const std::string& wkt, std::optional<std::uint32_t>& out, PluginFailure& failure) {
      capture_failure(failure, [&] { out = epsg_from_wkt(wkt); });
    },
    [](const std::string& definition, std::string& out, PluginFailure& failure) {
      capture_failure(failure, [&] { out = crs_wkt1(definition); });
    },
    [](const std::string& definition, void*& state, PluginFailure& failure) {
      capture_failure(failure, [&] { state = new Wgs84Transformation(definition); });
    },
    [](const void* state, const Point& in, Point& out, PluginFailure& failure) {
      capture_failure(failure, [&] { out = static_cast<const Wgs84Transformation*>(state)->transform(in); });
    },
    [](void* state) { delete static_cast<Wgs84Transformation*>(state); },
    [](const std::string& a, const std::string& b, bool& out, PluginFailure& failure) {
      capture_failure(failure, [&] { out = same_crs(a, b); });
    },
    [](const std::string& definition, EpsgLookup lookup, CrsDescription& out, PluginFailure& failure) {
      capture_failure(failure, [&] { out = describe_with_proj(definition, lookup); });
    },
    [](const std::string& from, const std::string& to, void*& state, PluginFailure& failure) {
      capture_failure(failure, [&] { state = new Reprojection(from, to); });
    },
    [](void* state, double* xyz, std::size_t points, PluginFailure& failure) {
      capture_failure(failure, [&] { static_cast<Reprojection*>(state)->transform(xyz, points); });
    },
    [](void* state) { delete static_cast<Reprojection*>(state); },
    [](const std::string& definition, std::string& out, PluginFailure& failure) {
      capture_failure(failure, [&] { out = crs_wkt_of(definition); });
    },
    [](std::uint32_t epsg, std::uint32_t unit, std::uint32_t vertical_unit, std::string& out, PluginFailure& failure) {
      capture_failure(failure, [&] { out = keyed_projected_crs(epsg, unit, vertical_unit); });
    },
};

}  // namespace
}  // namespace vola::geo

// The plugin's entry points (src/plugin/plugin.hpp, proj_plugin.hpp).
extern "C" {
const char* vola_plugin_version() { return vola::plugin::kPluginVersion; }
const vola::geo::plugin::ProjEntries* vola_plugin_proj_entries() { return &vola::geo::kEntries; }
}
static_assert(std::is_same_v<decltype(&vola_plugin_proj_entries), vola::geo::plugin::ProjEntriesEntry>);
