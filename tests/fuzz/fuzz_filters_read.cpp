// Fuzz entry point of the point filters' parsers of outside text: a `--where` expression
// (then evaluated on a few points with the usual LAS columns), a GeoJSON or WKT polygon
// file (then asked about a few points) and a PDAL-style JSON pipeline. The first byte
// picks which; the rest is the text. Only vola::Error may escape; what parses must answer
// one bool per point.
#include <cstddef>
#include <cstdint>
#include <string>

#include "fuzz_seeds.hpp"
#include "vola/error.hpp"
#include "vola/filters/crop.hpp"
#include "vola/filters/expression.hpp"
#include "vola/filters/pipeline.hpp"

namespace {

using vola_fuzz::check;

// Four points with the columns a LAS file gives the filters.
const vola::PointCloud& points() {
  static const vola::PointCloud cloud = [] {
    vola::PointCloud c;
    c.xyz = {0, 0, 0, 1.5, -2, 400, 1e6, 1e6, -1e3, 0.25, 0.5, 0.75};
    for (const char* name : {"classification", "intensity", "return_number", "number_of_returns"})
      c.attributes.push_back({name, vola::ValueType::f32, vola::Reduction::mean, {2, 1, 7, 18}});
    return c;
  }();
  return cloud;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  if (size == 0) return 0;
  const std::string text(reinterpret_cast<const char*>(data) + 1, size - 1);
  try {
    switch (data[0] % 3) {
      case 0: {
        const vola::filters::Expression expression(text);
        check(expression.evaluate(points()).size() == points().size());
        break;
      }
      case 1: {
        const vola::filters::PolygonSet polygons = vola::filters::parse_polygons(text, "input");
        check(vola::filters::inside_polygons(points().xyz, polygons).size() == points().size());
        break;
      }
      default: {
        const vola::filters::Pipeline pipeline = vola::filters::parse_pipeline(text, "input");
        check(!pipeline.input.empty());
        break;
      }
    }
    ++vola_fuzz::stats().parsed;
  } catch (const vola::Error&) {
    ++vola_fuzz::stats().refused;
  }
  return 0;
}
