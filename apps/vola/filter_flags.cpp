#include "filter_flags.hpp"

#include <sstream>

namespace vola::cli {

const char* const kFilterHelp =
    "Point filters run in the order given, before anything is written:\n"
    "  --where EXPR          keep the points EXPR holds for: == != < <= > >= on x, y, z and every\n"
    "                        field (classification, intensity, return_number, number_of_returns,\n"
    "                        red, ..., extra bytes by name; PDAL's spellings too: Classification,\n"
    "                        ReturnNumber, HeightAboveGround), joined by && || ! and parentheses\n"
    "  --filter smrf         ground classification (SMRF, Pingel et al. 2013): class 2 ground, 1 the\n"
    "                        rest; smrf:cell=1,slope=0.15,window=18,threshold=0.5,scalar=1.25 in\n"
    "                        metres whatever the CRS's unit (feet are converted)\n"
    "  --filter hag          height_above_ground: z minus the nearest ground (class 2) point's z\n"
    "  --filter outlier      drop points whose mean distance to their 8 nearest neighbours exceeds\n"
    "                        the mean by 2 standard deviations (outlier:k=8,multiplier=2)\n"
    "  --filter voxel:R      one point per R-cube, the nearest its centre\n"
    "  --filter poisson:R    no two points closer than R, in file order\n"
    "  --crop MINX MINY MAXX MAXY  (or MINX MINY MINZ MAXX MAXY MAXZ) keep a box\n"
    "  --crop-polygon FILE   keep the points inside a GeoJSON or WKT polygon (holes, multipolygons)\n";

void add_filter_options(CLI::App& cmd, std::vector<std::string>& stages, bool neighbour_stages) {
  cmd.add_option_function<std::string>(
         "--where", [&stages](const std::string& expr) { stages.push_back("where:" + expr); },
         "Keep the points EXPR holds for, e.g. \"Classification == 2 && z < 500\" (see below)")
      ->trigger_on_parse()
      ->multi_option_policy(CLI::MultiOptionPolicy::TakeLast);
  cmd.add_option_function<std::string>(
         "--filter", [&stages](const std::string& stage) { stages.push_back(stage); },
         neighbour_stages
             ? "A filter stage: smrf[:PARAMS], hag, outlier[:k=K,multiplier=M], voxel:R, poisson:R (repeatable, in "
               "order)"
             : "A filter stage needing no neighbours (crop:..., polygon:FILE, where:EXPR); smrf, hag, outlier, "
               "voxel:R and poisson:R are refused here: run them with vola translate first")
      ->trigger_on_parse()
      ->multi_option_policy(CLI::MultiOptionPolicy::TakeLast);
  cmd.add_option_function<std::vector<double>>(
         "--crop",
         [&stages](const std::vector<double>& v) {
           if (v.size() != 4 && v.size() != 6)
             throw CLI::ValidationError("--crop", "takes MINX MINY MAXX MAXY or MINX MINY MINZ MAXX MAXY MAXZ");
           std::ostringstream spec;
           spec.precision(17);
           spec << "crop:";
           for (std::size_t i = 0; i < v.size(); ++i) spec << (i ? "," : "") << v[i];
           stages.push_back(spec.str());
         },
         "Keep the points in a box: MINX MINY MAXX MAXY, or MINX MINY MINZ MAXX MAXY MAXZ")
      ->expected(4, 6)
      ->trigger_on_parse();
  cmd.add_option_function<std::string>(
         "--crop-polygon", [&stages](const std::string& file) { stages.push_back("polygon:" + file); },
         "Keep the points inside the polygons of a GeoJSON or WKT file")
      ->check(CLI::ExistingFile)
      ->trigger_on_parse()
      ->multi_option_policy(CLI::MultiOptionPolicy::TakeLast);
}

}  // namespace vola::cli
