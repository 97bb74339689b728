// A generated lidar drive through a generated city, for the occupancy-map benchmark
// (bench/map_peers.cpp, docs/BENCHMARKS.md): a KITTI-like spinning lidar (64 beams from
// -24.8 to +2 degrees, --azimuths columns a turn, --range metres) on a vehicle driving down
// one street of `vola generate city`, 1.8 m above the ground, every --step metres. Each
// beam is cast through the city's .vol with vola's ray caster; its hit voxel's centre
// (with up to a quarter voxel of deterministic jitter) is the return, beams that hit
// nothing within the range give none.
//
//   vola generate city city.xyz --points 4000000 && vola convert city.xyz city.vol --voxel-size 0.1
//   vola_lidar_sequence city.vol OUT_DIR [--scans 40] [--step 2] [--azimuths 1024] [--range 80]
//
// Writes OUT_DIR/NNNNNN.bin (KITTI float32 x y z intensity, sensor frame) and
// OUT_DIR/scans.txt (`vola map`'s scan list: FILE tx ty tz qx qy qz qw, identity rotation,
// translations relative to the city's corner (500000, 5000000, 100)).
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <optional>
#include <random>
#include <string>
#include <vector>

#include "vola/file.hpp"
#include "vola/raycast/ray_caster.hpp"

namespace {

struct Args {
  std::string city, out;
  int scans = 40, azimuths = 1024;
  double step = 2.0, range = 80.0;
};

Args parse(int argc, char** argv) {
  Args a;
  std::vector<std::string> positional;
  for (int i = 1; i < argc; ++i) {
    const std::string arg = argv[i];
    const auto value = [&] {
      if (i + 1 >= argc) throw std::runtime_error(arg + " needs a value");
      return std::string(argv[++i]);
    };
    if (arg == "--scans") a.scans = std::stoi(value());
    else if (arg == "--step") a.step = std::stod(value());
    else if (arg == "--azimuths") a.azimuths = std::stoi(value());
    else if (arg == "--range") a.range = std::stod(value());
    else positional.push_back(arg);
  }
  if (positional.size() != 2) throw std::runtime_error("usage: vola_lidar_sequence CITY.vol OUT_DIR [options]");
  a.city = positional[0];
  a.out = positional[1];
  return a;
}

}  // namespace

int main(int argc, char** argv) try {
  const Args a = parse(argc, argv);
  const vola::Tree city = vola::read(a.city);
  const vola::Frame frame = city.frame();
  const vola::raycast::RayCaster caster(city);
  const double voxel = frame.voxel_size;
  // The generator's layout (src/synth/city.cpp): blocks of 40 m from 6 m, streets of 12 m;
  // the street between the first two rows of blocks runs along x at local y = 52.
  const vola::Point local{500000.0, 5000000.0, 100.0};
  const double street_y = local[1] + 50.0;
  std::mt19937_64 rng(7);
  std::uniform_real_distribution<double> jitter(-0.25, 0.25);
  std::ofstream list(a.out + "/scans.txt");
  list.precision(12);
  std::size_t total = 0;
  for (int s = 0; s < a.scans; ++s) {
    const double x = local[0] + 10.0 + a.step * s;
    // The ground under the vehicle: the lowest hit of rays straight down from 60 m above
    // the city's base over a 1 m square (sampled ground has holes; tree crowns are higher).
    std::optional<std::uint32_t> ground;
    for (int dx = 0; dx < 5; ++dx)
      for (int dy = 0; dy < 5; ++dy) {
        const vola::raycast::Ray down{{(x + 0.2 * dx - frame.origin[0]) / voxel,
                                       (street_y + 0.2 * dy - frame.origin[1]) / voxel,
                                       (local[2] + 60.0 - frame.origin[2]) / voxel},
                                      {0, 0, -1}};
        if (const auto hit = caster.cast(down); hit && (!ground || hit->voxel.z < *ground)) ground = hit->voxel.z;
      }
    if (!ground) throw std::runtime_error("no ground under scan " + std::to_string(s));
    const vola::Point sensor{x, street_y, frame.origin[2] + (*ground + 1.0) * voxel + 1.8};
    std::vector<vola::raycast::Ray> rays;
    for (int beam = 0; beam < 64; ++beam) {
      const double elevation = (-24.8 + 26.8 * beam / 63.0) * M_PI / 180.0;
      for (int c = 0; c < a.azimuths; ++c) {
        const double azimuth = 2.0 * M_PI * c / a.azimuths;
        vola::raycast::Ray r;
        r.origin = {(sensor[0] - frame.origin[0]) / voxel, (sensor[1] - frame.origin[1]) / voxel,
                    (sensor[2] - frame.origin[2]) / voxel};
        r.direction = {std::cos(elevation) * std::cos(azimuth), std::cos(elevation) * std::sin(azimuth),
                       std::sin(elevation)};
        r.t_max = a.range / voxel;
        rays.push_back(r);
      }
    }
    std::vector<std::optional<vola::raycast::RayHit>> hits(rays.size());
    caster.cast(rays, hits);
    std::vector<float> records;
    for (const auto& h : hits) {
      if (!h) continue;
      const double index[3] = {static_cast<double>(h->voxel.x), static_cast<double>(h->voxel.y),
                               static_cast<double>(h->voxel.z)};
      for (int axis = 0; axis < 3; ++axis) {
        const double world = frame.origin[axis] + (index[axis] + 0.5 + jitter(rng)) * voxel;
        records.push_back(static_cast<float>(world - sensor[axis]));
      }
      records.push_back(0.5f);
    }
    char name[32];
    std::snprintf(name, sizeof name, "%06d.bin", s);
    std::ofstream(a.out + "/" + name, std::ios::binary)
        .write(reinterpret_cast<const char*>(records.data()), static_cast<std::streamsize>(records.size() * 4));
    // Poses relative to the city's corner: OctoMap's keys reach +-3276.8 m at 0.1 m voxels.
    list << name << ' ' << sensor[0] - local[0] << ' ' << sensor[1] - local[1] << ' ' << sensor[2] - local[2]
         << " 0 0 0 1\n";
    total += records.size() / 4;
  }
  std::printf("%d scans, %zu points, %s/scans.txt\n", a.scans, total, a.out.c_str());
  return 0;
} catch (const std::exception& e) {
  std::fprintf(stderr, "vola_lidar_sequence: %s\n", e.what());
  return 1;
}
