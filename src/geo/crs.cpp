#include "vola/geo/crs.hpp"

#include <proj.h>

#include <cmath>
#include <memory>

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

Context make_context() {
  Context ctx(proj_context_create());
  if (!ctx) throw Error("PROJ: cannot create a context");
  proj_log_level(ctx.get(), PJ_LOG_NONE);
  return ctx;
}

std::string last_error(PJ_CONTEXT* ctx) {
  const int code = proj_context_errno(ctx);
  return code ? proj_context_errno_string(ctx, code) : "unknown error";
}
}  // namespace

std::pair<double, double> centre_lat_lon(std::uint32_t epsg, const Box& bbox) {
  Context ctx = make_context();
  const std::string source = "EPSG:" + std::to_string(epsg);
  Pj transform(proj_create_crs_to_crs(ctx.get(), source.c_str(), "EPSG:4326", nullptr));
  if (!transform) throw Error("CRS " + source + " is not known to PROJ: " + last_error(ctx.get()));
  Pj normalized(proj_normalize_for_visualization(ctx.get(), transform.get()));
  if (!normalized) throw Error("PROJ cannot normalise the axis order of " + source);
  const double cx = (bbox.min[0] + bbox.max[0]) / 2.0;
  const double cy = (bbox.min[1] + bbox.max[1]) / 2.0;
  const PJ_COORD out = proj_trans(normalized.get(), PJ_FWD, proj_coord(cx, cy, 0, 0));
  if (!std::isfinite(out.xy.x) || !std::isfinite(out.xy.y))
    throw Error("PROJ cannot transform (" + std::to_string(cx) + ", " + std::to_string(cy) + ") from " + source +
                " to WGS84: " + last_error(ctx.get()));
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

}  // namespace vola::geo
