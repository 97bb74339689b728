// Fuzz entry point of what vola does with a CRS read from a file (a LAS WKT record, a
// tile index's crs_wkt, a GeoTIFF's definition): the first byte picks the vola::geo entry
// point (modulo 6), the rest is the text, as vola convert, info, tile and the LAS writer
// hand it over: 0 epsg_from_wkt, 1 describe_crs and crs_summary, 2 crs_wkt1, 3 crs_wkt,
// 4 same_crs against EPSG:4326, 5 ToWgs84 and one point. (One entry point an input:
// each opens a PROJ context and searches its database, 0.1-0.5 s under ASan.) PROJ
// parses; vola walks what it made (bound and compound CRSs, identification candidates,
// axis units) and turns every failure into a vola::Error. Only vola::Error may escape; a
// description names a kind; a point that transforms is finite.
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <string>

#include "fuzz_seeds.hpp"
#include "vola/error.hpp"
#include "vola/geo/crs.hpp"

namespace {

using vola_fuzz::check;

template <class F>
bool accepted(F&& f) {
  try {
    f();
    return true;
  } catch (const vola::Error&) {
    return false;
  }
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  namespace geo = vola::geo;
  if (size == 0) return 0;
  const std::string text(reinterpret_cast<const char*>(data) + 1, size - 1);
  bool parsed = false;
  switch (data[0] % 6) {
    case 0: parsed = accepted([&] { (void)geo::epsg_from_wkt(text); }); break;
    case 1:
      parsed = accepted([&] {
        const geo::CrsDescription d = geo::describe_crs(text);
        check(!d.kind.empty() && !geo::crs_summary(d).empty());
      });
      break;
    case 2: parsed = accepted([&] { check(!geo::crs_wkt1(text).empty()); }); break;
    case 3: parsed = accepted([&] { check(!geo::crs_wkt(text).empty()); }); break;
    case 4: parsed = accepted([&] { (void)geo::same_crs(text, "EPSG:4326"); }); break;
    default:
      parsed = accepted([&] {
        const geo::ToWgs84 to(text);
        const vola::Point p = to.transform({500000.0, 4500000.0, 10.0});
        check(std::isfinite(p[0]) && std::isfinite(p[1]));
      });
      break;
  }
  ++(parsed ? vola_fuzz::stats().parsed : vola_fuzz::stats().refused);
  return 0;
}
