// Fuzz entry point of what vola does with a CRS read from a file (a LAS WKT record, a
// tile index's crs_wkt, a GeoTIFF's definition): the input is the text, handed to every
// vola::geo entry point that takes one (epsg_from_wkt, describe_crs and crs_summary,
// crs_wkt1, crs_wkt, same_crs, ToWgs84), as vola convert, info, tile and the LAS writer
// do. PROJ parses; vola walks what it made (bound and compound CRSs, identification
// candidates, axis units) and turns every failure into a vola::Error. Only vola::Error
// may escape; a description names a kind; a point that transforms is finite.
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <string>

#include "fuzz_seeds.hpp"
#include "vola/error.hpp"
#include "vola/geo/crs.hpp"

namespace vola_fuzz {
Stats& stats() {
  static Stats s;
  return s;
}
}  // namespace vola_fuzz

namespace {

void check(bool invariant) {
  if (!invariant) std::abort();
}

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
  const std::string text(reinterpret_cast<const char*>(data), size);
  bool parsed = false;
  accepted([&] { (void)geo::epsg_from_wkt(text); });
  parsed |= accepted([&] {
    const geo::CrsDescription d = geo::describe_crs(text);
    check(!d.kind.empty() && !geo::crs_summary(d).empty());
  });
  accepted([&] { check(!geo::crs_wkt1(text).empty()); });
  accepted([&] { check(!geo::crs_wkt(text).empty()); });
  accepted([&] { (void)geo::same_crs(text, "EPSG:4326"); });
  accepted([&] {
    const geo::ToWgs84 to(text);
    const vola::Point p = to.transform({500000.0, 4500000.0, 10.0});
    check(std::isfinite(p[0]) && std::isfinite(p[1]));
  });
  ++(parsed ? vola_fuzz::stats().parsed : vola_fuzz::stats().refused);
  return 0;
}
