// vola generate: the project's own data, e.g. a city block as an XYZ point cloud.
#include <cmath>
#include <string>

#include "commands.hpp"
#include "number_checks.hpp"
#include "progress.hpp"
#include "text_output.hpp"
#include "vola/error.hpp"
#include "vola/output_file.hpp"
#include "vola/synth/city.hpp"

namespace vola::cli {

namespace {

struct GenerateArgs {
  std::string scene = "city", output;
  std::uint64_t points = 1'000'000;
  std::uint64_t seed = 1;
  double size = 200.0;
};

void run_generate(const GenerateArgs& a) {
  if (a.scene != "city") throw InvalidArgument("scene '" + a.scene + "' is not known (city)");
  OutputFile file(a.output);
  synth::CityOptions o;
  o.points = a.points;
  o.seed = a.seed;
  o.size = a.size;
  Progress progress("generating " + a.output);
  std::uint64_t done = 0;
  TextOutput out(file.stream(), a.output);
  // The names on a line of their own, so that readers take it for the header (a line with
  // numbers in it is a comment).
  out.text("# vola generate city; classification as ASPRS: 2 ground, 5 vegetation, 6 building\n");
  out.text("# x y z intensity classification\n");
  synth::generate_city(o, [&](const synth::CityPoint& p) {
    // Millimetre precision, as a LIDAR survey delivers.
    out.number(std::round(p.x * 1000.0) / 1000.0).ch(' ').number(std::round(p.y * 1000.0) / 1000.0).ch(' ');
    out.number(std::round(p.z * 1000.0) / 1000.0).ch(' ').number(std::uint64_t{p.intensity}).ch(' ');
    out.number(std::uint64_t{p.classification}).ch('\n');
    if ((++done & 0xFFFF) == 0) progress.update(done, a.points);
  });
  out.flush();
  file.commit();
  progress.update(a.points, a.points);
}

}  // namespace

void add_generate(CLI::App& app) {
  auto args = std::make_shared<GenerateArgs>();
  auto* cmd = app.add_subcommand("generate", "Write a generated scene as XYZ text (the project's own demo data)");
  cmd->footer(
      "city: ground, box buildings and trees over SIZE x SIZE metres at UTM-like coordinates\n"
      "(easting 500000, northing 5000000), columns x y z intensity classification, named in a\n"
      "header line (vola convert keeps both per voxel, as doubles: intensity mean, classification majority;\n"
      "--attribute gives them narrower types).\n"
      "Example: vola generate city city.xyz --points 2000000 && vola convert city.xyz city.vol --voxel-size 0.25 \\\n"
      "           --attribute intensity=4:u16:mean --attribute classification=5:u8:majority");
  cmd->add_option("scene", args->scene, "Scene: city")->required();
  cmd->add_option("output", args->output, "Output .xyz")->required();
  cmd->add_option("--points", args->points, "Number of points")->capture_default_str();
  cmd->add_option("--seed", args->seed, "Random seed")->capture_default_str();
  cmd->add_option("--size", args->size, "Side of the square area, metres")->check(positive_number())->capture_default_str();
  cmd->callback([args] { run_generate(*args); });
}

}  // namespace vola::cli
