// vola map SCANLIST -o MAP.vol --voxel-size R: range scans with poses into a probabilistic
// occupancy map (OctoMap's insertion model), written as one state map (occupied, free and
// unknown, vola/map/state_map.hpp) with every known voxel's log-odds; --free also writes
// the free voxels as a plain tree, as before the state map.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <memory>
#include <string>

#include "commands.hpp"
#include "number_checks.hpp"
#include "output_checks.hpp"
#include "progress.hpp"
#include "text_output.hpp"
#include "vola/error.hpp"
#include "vola/file.hpp"
#include "vola/io/input.hpp"
#include "vola/map/occupancy_map.hpp"
#include "vola/map/scan_list.hpp"
#include "vola/map/state_map.hpp"

namespace vola::cli {

namespace {

struct MapArgs {
  std::string list, output, from;
  double voxel_size = 0.0;
  double max_range = 0.0;
  double max_ray_voxels = 2e8;  // per scan (at most ~8 GB of known voxels); 0: no limit
  bool free = false;
  bool quiet = false;
};

// MAP.vol -> MAP.free.vol (any other name gets .free.vol appended).
std::string free_path(const std::string& output) {
  const std::filesystem::path p(output);
  if (p.extension() == ".vol") return (p.parent_path() / (p.stem().string() + ".free.vol")).string();
  return output + ".free.vol";
}

// One scan's points in the world frame; errors name the list's line.
// The scan's points in world coordinates; `left_out` gets the points the reader left out
// for a coordinate that is not finite.
std::vector<double> world_points(const map::ScanEntry& scan, const std::string& list, std::uint64_t& left_out) {
  const std::string where = list + ": line " + std::to_string(scan.line) + ": " + scan.file + ": ";
  io::Input input;
  try {
    io::InputOptions options;
    options.attributes = false;
    input = io::read_input(scan.file, "auto", options);
  } catch (const Error& e) {
    throw InvalidArgument(where + e.what());
  }
  if (input.cloud.xyz.empty() && (input.grid || input.is_mesh() || input.build))
    throw InvalidArgument(where + "not a point file (" + input.format + "): a scan is points in the sensor frame");
  scan.pose.apply(input.cloud.xyz);
  left_out = input.not_finite;
  return std::move(input.cloud.xyz);
}

// Refuses a scan whose rays cross more than --max-ray-voxels (map::RayExtent says why:
// 20,000 points 1 km from the sensor at 5 cm were 4e8 voxel steps, 260 M free voxels,
// 9.8 GB and a minute), saying what the distances were.
void check_ray_lengths(const MapArgs& a, const map::ScanEntry& scan, std::span<const double> xyz) {
  if (a.max_ray_voxels <= 0) return;
  const Point& o = scan.pose.translation;
  const map::RayExtent e = map::ray_extent(xyz, o, a.voxel_size, a.max_range);
  if (e.voxel_steps <= a.max_ray_voxels) return;
  char text[600];
  std::snprintf(text, sizeof text,
                "%s: line %llu: %s: its rays cross up to %.3g voxels of %s, more than --max-ray-voxels %.3g (each may "
                "become a known voxel of ~40 bytes): its points lie %.6g on average and up to %.6g from the sensor at "
                "(%.10g, %.10g, %.10g). Check that the pose's translation is the sensor's position in the points' "
                "frame and the voxel size's unit; give --max-range, or a larger --max-ray-voxels for a scan that "
                "is this large",
                a.list.c_str(), static_cast<unsigned long long>(scan.line), scan.file.c_str(), e.voxel_steps,
                shortest_text(a.voxel_size).c_str(), a.max_ray_voxels, e.mean, e.longest, o[0], o[1], o[2]);
  throw InvalidArgument(text);
}

void add_up(map::ScanReport& total, const map::ScanReport& r) {
  total.points += r.points;
  total.not_finite += r.not_finite;
  total.outside += r.outside;
  total.cut += r.cut;
}

void print_summary(const MapArgs& a, const map::OccupancyMap& m, const map::ScanReport& total, std::size_t scans,
                   const map::StateCounts& states, double seconds, double insert_seconds) {
  std::printf("scans:   %zu, %llu points (%llu not finite, %llu more than 2^20 voxels from the world origin skipped; %llu beyond "
              "--max-range, free up to it)\n",
              scans, static_cast<unsigned long long>(total.points), static_cast<unsigned long long>(total.not_finite),
              static_cast<unsigned long long>(total.outside), static_cast<unsigned long long>(total.cut));
  std::printf("voxels:  %zu known, %llu occupied, %llu free (voxel size %.9g)\n", m.size(),
              static_cast<unsigned long long>(states.occupied), static_cast<unsigned long long>(states.free),
              a.voxel_size);
  std::printf("file:    %s%s\n", a.output.c_str(), a.free ? (" and " + free_path(a.output)).c_str() : "");
  std::printf("time:    %.3f s (ray insertion %.3f s, %.0f points/s)\n", seconds, insert_seconds,
              insert_seconds > 0 ? static_cast<double>(total.points) / insert_seconds : 0.0);
}

// --from: the saved map the scans go on updating, at the same voxel size.
map::OccupancyMap resumed_map(const MapArgs& a) {
  const Tree saved = open_mapped(a.from);
  map::OccupancyMap m = [&] {
    try {
      return map::thaw(saved);
    } catch (const InvalidArgument& e) {
      throw InvalidArgument(a.from + ": " + e.what());
    }
  }();
  if (m.voxel_size() != a.voxel_size)
    throw OptionError("voxel_size", std::to_string(a.voxel_size) + " differs from " + a.from + "'s voxel size " +
                                        std::to_string(m.voxel_size()));
  return m;
}

void run_map(const MapArgs& a) {
  const auto start = std::chrono::steady_clock::now();
  const std::vector<map::ScanEntry> scans = map::read_scan_list(a.list);
  std::vector<std::string> inputs{a.list};
  for (const map::ScanEntry& scan : scans) inputs.push_back(scan.file);
  refuse_outputs_over_inputs(inputs, {a.output, a.free ? free_path(a.output) : std::string()}, "vola map");
  map::OccupancyMap m = a.from.empty() ? map::OccupancyMap(a.voxel_size) : resumed_map(a);
  std::unique_ptr<Progress> progress;
  if (!a.quiet) progress = std::make_unique<Progress>("inserting scans");
  map::ScanReport total;
  double insert_seconds = 0;
  for (std::size_t n = 0; n < scans.size(); ++n) {
    std::uint64_t left_out = 0;
    const std::vector<double> xyz = world_points(scans[n], a.list, left_out);
    total.points += left_out;
    total.not_finite += left_out;
    check_ray_lengths(a, scans[n], xyz);
    const auto insert_start = std::chrono::steady_clock::now();
    try {
      add_up(total, m.insert_scan(xyz, scans[n].pose.translation, a.max_range));
    } catch (const InvalidArgument& e) {
      throw InvalidArgument(a.list + ": line " + std::to_string(scans[n].line) + ": " + e.what());
    }
    insert_seconds += std::chrono::duration<double>(std::chrono::steady_clock::now() - insert_start).count();
    if (progress) progress->update(n + 1, scans.size());
  }
  if (progress) progress->finish();
  // A map of nothing is a mistake (points in survey coordinates with a pose near 0, a
  // voxel size in the wrong unit), not a result.
  if (m.size() == 0)
    throw InvalidArgument(a.list + ": no point of the " + std::to_string(total.points) + " made a known voxel (" +
                          std::to_string(total.not_finite) + " not finite, " + std::to_string(total.outside) +
                          " more than " + std::to_string(map::kIndexLimit) + " voxels of " + shortest_text(a.voxel_size) +
                          " from the world origin); no map written");
  // Both trees are built before either file is written, so a failure leaves neither.
  const Tree states = map::freeze(m);
  if (a.free) {
    const Tree free = map::free_tree(states);
    write(states, a.output);
    write(free, free_path(a.output));
  } else {
    write(states, a.output);
  }
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  if (!a.quiet) print_summary(a, m, total, scans.size(), map::state_counts(states), seconds, insert_seconds);
}

}  // namespace

void add_map(CLI::App& app) {
  auto args = std::make_shared<MapArgs>();
  auto* cmd = app.add_subcommand("map", "Range scans with poses into a probabilistic occupancy map (as OctoMap)");
  cmd->footer(
      "SCANLIST has one scan per line: FILE tx ty tz qx qy qz qw. FILE holds the scan's points in\n"
      "the sensor frame, in any point format vola convert reads (KITTI .bin, PLY, PCD, XYZ, LAS, ...),\n"
      "relative to the list's folder; the pose (translation, unit quaternion) maps sensor to world\n"
      "and its translation is the sensor origin. Lines starting with # are skipped.\n"
      "Each point is a ray from the origin: the voxels it passes get a miss, its end voxel a hit\n"
      "(OctoMap's defaults: hit 0.7, miss 0.4, clamped to 0.1192..0.971, occupied at 0.5 and\n"
      "above); one scan updates each voxel once, a hit winning over a miss. Voxel (i,j,k) covers\n"
      "[i*R, (i+1)*R) per axis. Points farther than --max-range mark the ray free up to it, no hit;\n"
      "NaN and infinite points are skipped and counted.\n"
      "MAP.vol is a state map: every known voxel, occupied or free, with its log-odds (attribute\n"
      "log_odds, f32), and a state word per block (nbits 1: bit set = occupied); unknown space is not\n"
      "in the tree. Every vola command reads it as its occupied voxels; vola get --points prints\n"
      "occupied/free/unknown and the probability, vola info and vola census count the states, vola\n"
      "view --free shows the free voxels. --free also writes the free voxels to MAP.free.vol as a\n"
      "plain tree (as vola map did before the state map).\n"
      "--from MAP.vol continues a saved map: only the blocks the new scans touch change, and the file\n"
      "equals the one all the scans would give at once.\n"
      "A scan whose rays cross more than --max-ray-voxels voxels in all (2e8 by default: about 8 GB\n"
      "of known voxels at worst) is refused before it is inserted, with its points' distances from\n"
      "the sensor: most often the pose is not where the sensor was (survey coordinates, a pose at 0)\n"
      "or the voxel size is in another unit. Give --max-range, or raise the limit for a scan that\n"
      "is truly this large.\n"
      "Example:\n"
      "  printf 'velodyne/000000.bin 0 0 0 0 0 0 1\\n' > scans.txt\n"
      "  vola map scans.txt -o map.vol --voxel-size 0.2 --max-range 40 --free\n"
      "  vola map more_scans.txt --from map.vol -o map.vol --voxel-size 0.2 --max-range 40");
  cmd->add_option("scanlist", args->list, "Text file: FILE tx ty tz qx qy qz qw per line")->required()
      ->check(CLI::ExistingFile);
  cmd->add_option("-o,--output", args->output, "Output .vol (state map: occupied and free voxels)")->required();
  cmd->add_option("--voxel-size", args->voxel_size, "Voxel edge R in the points' unit")->required()
      ->check(positive_number());
  cmd->add_option("--from", args->from,
                  "Insert into this saved map (a state map from vola map, same --voxel-size) instead of an empty "
                  "one; -o may name the same file. The result equals inserting every scan at once")
      ->check(CLI::ExistingFile);
  cmd->add_option("--max-range", args->max_range, "Longest ray; farther points mark free space only (0: no limit)")
      ->check(non_negative_number());
  cmd->add_option("--max-ray-voxels", args->max_ray_voxels,
                  "Refuse a scan whose rays cross more voxels than this in all (a pose far from its points, a voxel "
                  "size in the wrong unit; 0: no limit)")
      ->capture_default_str()
      ->check(non_negative_number());
  cmd->add_flag("--free", args->free, "Also write the free voxels to MAP.free.vol as a plain tree");
  cmd->add_flag("-q,--quiet", args->quiet, "Print nothing on success but warnings (to stderr)");
  cmd->callback([args] { run_map(*args); });
}

}  // namespace vola::cli
