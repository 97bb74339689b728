// The paper's Table II (SonifEye on a Myriad 2: threshold environment 820 ms, create filter
// 0.3 ms, apply filter 4.05 ms for a 256^3 environment and a 1 s source) measured here:
// the same three steps for a 256^3 room with furniture and a 1 s, 48 kHz source, on one
// thread and on every core, against naive versions in the same run: thresholding that
// visits every cell of the dense 256^3 grid, and time-domain convolution. The naive
// thresholding must give the same bins (checked), so the comparison is like for like.
// Then the physical model (room_response.hpp) on the same room: image sources (order 3,
// with and without occlusion), the ray-traced tail (the default: rays until the
// histogram's error bound, and 20,000 and 2,000 rays without it), the whole response and
// its convolution with the source.
//
//   vola_audio_bench [--runs N]     (medians of N runs, default 7)
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <functional>
#include <numbers>
#include <random>
#include <string>
#include <thread>
#include <vector>

#include "vola/audio/convolve.hpp"
#include "vola/audio/response.hpp"
#include "vola/audio/room_response.hpp"
#include "vola/builder.hpp"

namespace {

using namespace vola;
using namespace vola::audio;

constexpr double kVoxel = 0.04;  // a 10.24 m room

double median_ms(int runs, const std::function<void()>& f) {
  std::vector<double> t;
  for (int i = 0; i < runs; ++i) {
    const auto a = std::chrono::steady_clock::now();
    f();
    t.push_back(std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - a).count());
  }
  std::sort(t.begin(), t.end());
  return t[t.size() / 2];
}

// A 256^3 room: walls on the grid's six outer planes, and 40 solid boxes of furniture.
Tree room() {
  std::vector<Voxel> v;
  for (std::uint32_t a = 0; a < 256; ++a)
    for (std::uint32_t b = 0; b < 256; ++b)
      for (const std::uint32_t w : {0u, 255u}) {
        v.push_back({w, a, b});
        v.push_back({a, w, b});
        v.push_back({a, b, w});
      }
  std::mt19937 rng(1);
  std::uniform_int_distribution<std::uint32_t> pos(20, 200), size(8, 40);
  for (int i = 0; i < 40; ++i) {
    const std::uint32_t x = pos(rng), y = pos(rng), sx = size(rng), sy = size(rng), sz = size(rng);
    for (std::uint32_t z = 1; z <= sz; ++z)
      for (std::uint32_t j = 0; j < sy; ++j)
        for (std::uint32_t k = 0; k < sx; ++k) v.push_back({x + k, y + j, z});
  }
  std::sort(v.begin(), v.end(), [](const Voxel& a, const Voxel& b) { return std::tie(a.x, a.y, a.z) < std::tie(b.x, b.y, b.z); });
  v.erase(std::unique(v.begin(), v.end()), v.end());
  Tree t = build_from_voxels(v, 4);
  t.set_frame(Frame{Quantization::grid, {0, 0, 0}, kVoxel});
  return t;
}

// The naive thresholding: every cell of the dense grid, asked of the tree, the model of
// response.hpp written out per cell.
std::vector<Bin> naive_threshold(const Tree& tree, const Point& s, const Point& l, double coefficient,
                                 const ResponseOptions& o) {
  const Point sg{s[0] / kVoxel, s[1] / kVoxel, s[2] / kVoxel}, lg{l[0] / kVoxel, l[1] / kVoxel, l[2] / kVoxel};
  const double direct = std::hypot(s[0] - l[0], s[1] - l[1], s[2] - l[2]);
  const double last = std::ceil((direct / o.speed_of_sound + o.reflection_window) * o.sample_rate);
  std::vector<std::pair<std::uint32_t, std::int32_t>> keys;
  const std::uint32_t side = tree.side();
  for (std::uint32_t z = 0; z < side; ++z)
    for (std::uint32_t y = 0; y < side; ++y)
      for (std::uint32_t x = 0; x < side; ++x) {
        if (!tree.contains(x, y, z)) continue;
        const double c[3] = {double(x), double(y), double(z)};
        Point p{c[0] + 0.5, c[1] + 0.5, c[2] + 0.5};
        bool reflects = false;
        for (int a = 0; a < 3; ++a) {
          std::uint32_t lo[3] = {x, y, z}, hi[3] = {x, y, z};
          lo[a] -= 1;
          hi[a] += 1;
          if (!tree.contains(lo[0], lo[1], lo[2]) && sg[a] < c[a] && lg[a] < c[a]) {
            p[a] = c[a];
            reflects = true;
          } else if (!tree.contains(hi[0], hi[1], hi[2]) && sg[a] > c[a] + 1 && lg[a] > c[a] + 1) {
            p[a] = c[a] + 1;
            reflects = true;
          }
        }
        if (!reflects) continue;
        const double d1 = std::sqrt((p[0] - sg[0]) * (p[0] - sg[0]) + (p[1] - sg[1]) * (p[1] - sg[1]) + (p[2] - sg[2]) * (p[2] - sg[2]));
        const double d2 = std::sqrt((p[0] - lg[0]) * (p[0] - lg[0]) + (p[1] - lg[1]) * (p[1] - lg[1]) + (p[2] - lg[2]) * (p[2] - lg[2]));
        const double sample = std::nearbyint((d1 + d2) * (kVoxel / o.speed_of_sound * o.sample_rate));
        if (sample > last) continue;
        const double amplitude = coefficient * (1.0 / (std::sqrt(std::numbers::pi) * kVoxel)) / (d1 * d2);
        keys.emplace_back(static_cast<std::uint32_t>(sample),
                          static_cast<std::int32_t>(std::llround(-20.0 * std::log10(amplitude) * (1.0 / o.bin_width_db))));
      }
  std::sort(keys.begin(), keys.end());
  std::vector<Bin> bins;
  for (const auto& [sample, level] : keys) {
    if (!bins.empty() && bins.back().sample == sample && bins.back().level == level) ++bins.back().count;
    else bins.push_back(Bin{0, sample, level, 1});
  }
  return bins;
}

std::vector<double> naive_convolution(const std::vector<double>& x, const std::vector<double>& h) {
  std::vector<double> y(x.size() + h.size() - 1, 0.0);
  for (std::size_t i = 0; i < x.size(); ++i)
    for (std::size_t j = 0; j < h.size(); ++j) y[i + j] += x[i] * h[j];
  return y;
}

}  // namespace

int main(int argc, char** argv) {
  int runs = 7;
  for (int i = 1; i < argc; ++i)
    if (!std::strcmp(argv[i], "--runs") && i + 1 < argc) runs = std::max(1, std::atoi(argv[++i]));
  const unsigned cores = std::max(1u, std::thread::hardware_concurrency());
  const Tree tree = room();
  // Once per scene, not per response: leaf blocks and their exposed faces (timed apart).
  const auto prepare_start = std::chrono::steady_clock::now();
  const AcousticScene scene(tree, scene_material(0.8));
  const double prepare = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - prepare_start).count();
  const Point source{3.1, 4.2, 1.7}, listener{7.3, 6.6, 1.6};
  ResponseOptions one;
  one.threads = 1;
  ResponseOptions all = one;
  all.threads = cores;
  std::printf("scene: 256^3 grid, %llu voxels, %zu leaf blocks; source 1 s at 48 kHz; %d runs, medians\n",
              static_cast<unsigned long long>(tree.voxel_count()), scene.blocks().size(), runs);

  Thresholded t;
  const double th1 = median_ms(runs, [&] { t = threshold(scene, source, listener, one); });
  const double thn = median_ms(runs, [&] { t = threshold(scene, source, listener, all); });
  std::vector<Bin> naive;
  const double th_naive = median_ms(std::min(runs, 3), [&] { naive = naive_threshold(tree, source, listener, 0.8, one); });
  if (naive != t.bins) {
    std::fprintf(stderr, "naive thresholding disagrees: %zu bins against %zu\n", naive.size(), t.bins.size());
    return 1;
  }
  std::vector<double> ir;
  // The first call also makes the scene's table of level amplitudes (once per bin width).
  const double first_filter = median_ms(1, [&] { ir = make_filter(scene, t, one); });
  const double filter = median_ms(runs, [&] { ir = make_filter(scene, t, one); });
  std::vector<double> dry(48000);
  std::mt19937 rng(5);
  std::normal_distribution<double> noise(0.0, 0.1);
  for (double& v : dry) v = noise(rng);
  std::vector<double> wet;
  // FFTW plans its transform size once per process (FFTW_MEASURE), outside the timed step;
  // the step is then the filter's spectrum and the overlap-add of the source.
  const double planning = median_ms(1, [&] { Convolver(ir, FftPlanning::measure, dry.size()); });
  const double apply1 = median_ms(runs, [&] { wet = Convolver(ir, FftPlanning::measure, dry.size()).apply(dry, 1); });
  const double applyn = median_ms(runs, [&] { wet = Convolver(ir, FftPlanning::measure, dry.size()).apply(dry, cores); });
  std::vector<double> slow;
  const double apply_naive = median_ms(std::min(runs, 3), [&] { slow = naive_convolution(dry, ir); });
  double worst = 0.0;
  for (std::size_t i = 0; i < wet.size(); ++i) worst = std::max(worst, std::abs(wet[i] - slow[i]));

  std::printf("%llu reflecting voxels in %zu bins; response %zu samples (%.1f ms); FFT size %zu; max |fft - direct| %.2g\n\n",
              static_cast<unsigned long long>(t.reflectors), t.bins.size(), ir.size(), static_cast<double>(ir.size()) / 48.0,
              Convolver(ir, FftPlanning::estimate, dry.size()).fft_size(), worst);
  std::printf("%-22s %12s %12s %12s %14s %12s %12s\n", "step", "paper (ms)", "1 thread", "threads", "naive (ms)",
              "vs paper", "vs naive");
  auto row = [&](const char* name, double paper, double a, double b, double naive_ms) {
    const double best = std::min(a, b);
    std::printf("%-22s %12.3f %12.3f %9.3f (%u) %14.3f %11.0fx %11.1fx\n", name, paper, a, b, cores, naive_ms, paper / best,
                naive_ms / a);
  };
  row("threshold environment", 820.0, th1, thn, th_naive);
  row("create filter", 0.3, filter, filter, filter);
  row("apply filter", 4.05, apply1, applyn, apply_naive);
  std::printf("\n(vs naive: the naive single-threaded time over ours on one thread; create filter has no naive variant)\n");
  std::printf("once, not in the steps: scene preparation (surface faces) %.1f ms, first create filter (with the level table) "
              "%.3f ms, FFTW_MEASURE planning of size %zu %.1f ms\n",
              prepare, first_filter, Convolver(ir, FftPlanning::estimate, dry.size()).fft_size(), planning);

  // The physical model (room_response.hpp) on the same room and positions: the equivalent
  // of "threshold environment" is the image-source search plus the traced tail, of "create
  // filter" the response's assembly, of "apply filter" the convolution with the whole
  // (long) response.
  const auto patches_start = std::chrono::steady_clock::now();
  const Room physical(scene);
  const double patches_ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - patches_start).count();
  RoomOptions room_one;
  room_one.threads = 1;
  RoomOptions room_all = room_one;
  room_all.threads = cores;
  RoomOptions no_occlusion = room_one;
  no_occlusion.occlusion = false;
  ImageSearch early;
  const double images1 = median_ms(runs, [&] { early = image_sources(physical, source, listener, room_one); });
  const double imagesn = median_ms(runs, [&] { early = image_sources(physical, source, listener, room_all); });
  const double images_open = median_ms(runs, [&] { early = image_sources(physical, source, listener, no_occlusion); });
  early = image_sources(physical, source, listener, room_one);  // the default's images, reported below
  LateEnergy late;
  const double tail1 = median_ms(runs, [&] { late = late_energy(physical, source, listener, early.order, room_one); });
  const double tailn = median_ms(runs, [&] { late = late_energy(physical, source, listener, early.order, room_all); });
  const LateEnergy default_late = late;
  RoomOptions few_one = room_one, few_all = room_all;
  few_one.rays = few_all.rays = 2000;
  few_one.tail_error = few_all.tail_error = 0.0;
  RoomOptions fixed_one = room_one, fixed_all = room_all;
  fixed_one.tail_error = fixed_all.tail_error = 0.0;
  const double fixed1 = median_ms(runs, [&] { late_energy(physical, source, listener, early.order, fixed_one); });
  const double fixedn = median_ms(runs, [&] { late_energy(physical, source, listener, early.order, fixed_all); });
  const double few1 = median_ms(runs, [&] { late_energy(physical, source, listener, early.order, few_one); });
  const double fewn = median_ms(runs, [&] { late_energy(physical, source, listener, early.order, few_all); });
  RoomResponse response;
  const double whole1 = median_ms(runs, [&] { response = room_response(physical, source, listener, room_one); });
  const double wholen = median_ms(runs, [&] { response = room_response(physical, source, listener, room_all); });
  // The response's spectrum, at the transform size chosen for the 1 s source, belongs to
  // making the filter (the paper's "create filter"); applying it is the overlap-add.
  const double long_planning = median_ms(1, [&] { Convolver(response.ir, FftPlanning::measure, dry.size()); });
  const double spectrum = median_ms(runs, [&] { Convolver(response.ir, FftPlanning::measure, dry.size()); });
  const Convolver sized(response.ir, FftPlanning::measure, dry.size());
  // Into one output buffer reused from call to call, as a program filtering sound after
  // sound would; the row after it makes a new output vector and the spectrum every time.
  std::vector<double> reused(dry.size() + response.ir.size() - 1);
  const double long1 = median_ms(runs, [&] { sized.apply_into(dry, reused, 1); });
  const double longn = median_ms(runs, [&] { sized.apply_into(dry, reused, cores); });
  const double both1 = median_ms(runs, [&] { wet = Convolver(response.ir, FftPlanning::measure, dry.size()).apply(dry, 1); });
  const double bothn = median_ms(runs, [&] { wet = Convolver(response.ir, FftPlanning::measure, dry.size()).apply(dry, cores); });
  // Single precision, as vola sonify applies a response (the same transform size).
  const Convolver single(response.ir, FftPlanning::measure, dry.size(), SamplePrecision::float32);
  const double single1 = median_ms(runs, [&] { single.apply_into(dry, reused, 1); });
  const double singlen = median_ms(runs, [&] { single.apply_into(dry, reused, cores); });
  const double single_both1 = median_ms(runs, [&] {
    wet = Convolver(response.ir, FftPlanning::measure, dry.size(), SamplePrecision::float32).apply(dry, 1);
  });
  double single_apart = 0.0, scale = 0.0;
  {
    const std::vector<double> exact = sized.apply(dry, 1), rounded = single.apply(dry, 1);
    for (std::size_t i = 0; i < exact.size(); ++i) {
      single_apart = std::max(single_apart, std::abs(exact[i] - rounded[i]));
      scale = std::max(scale, std::abs(exact[i]));
    }
  }
  // One transform four times the response (the size for long signals).
  const double longest1 = median_ms(runs, [&] { wet = Convolver(response.ir, FftPlanning::measure).apply(dry, 1); });
  // The same response in partitions of 8192 samples (what vola sonify uses past 32,768 taps).
  const double part1 = median_ms(runs, [&] { wet = PartitionedConvolver(response.ir, 8192, FftPlanning::measure).apply(dry, 1); });
  const double partn = median_ms(runs, [&] { wet = PartitionedConvolver(response.ir, 8192, FftPlanning::measure).apply(dry, cores); });
  double apart = 0.0;
  const std::vector<double> one_transform = sized.apply(dry, 1);
  for (std::size_t i = 0; i < wet.size(); ++i) apart = std::max(apart, std::abs(wet[i] - one_transform[i]));
  // A 10 s response (a large hall's tail): one transform of 2^21 points against partitions.
  std::vector<double> hall(480000);
  for (std::size_t i = 0; i < hall.size(); ++i) hall[i] = noise(rng) * std::exp(-6.9 * static_cast<double>(i) / 48000.0 / 2.0);
  const double hall_one = median_ms(std::min(runs, 3), [&] { wet = Convolver(hall).apply(dry, 1); });
  const double hall_part = median_ms(std::min(runs, 3), [&] { wet = PartitionedConvolver(hall, 8192).apply(dry, 1); });
  std::printf("\nphysical model: %zu patches (found once: %.1f ms); order %d searched, %llu images tried, %zu valid; "
              "tail %llu rays (relative error %.3f, at most %.2f), scattering %.2f, receiver %.2f m; response %zu samples (%.1f ms); "
              "FFT size %zu for the 1 s source (planning %.0f ms); max |one transform - partitioned| %.2g\n\n",
              physical.patches().patches().size(), patches_ms, early.order,
              static_cast<unsigned long long>(early.candidates), early.images.size(),
              static_cast<unsigned long long>(default_late.rays), default_late.relative_error, room_one.tail_error, room_one.scattering, late.receiver_radius, response.ir.size(),
              static_cast<double>(response.ir.size()) / 48.0, sized.fft_size(), long_planning, apart);
  std::printf("%-34s %12s %12s %12s %12s\n", "physical step", "paper (ms)", "1 thread", "threads", "vs paper");
  auto physical_row = [&](const char* name, double paper, double a, double b) {
    std::printf("%-34s %12.3f %12.3f %9.3f (%u) %11.1fx\n", name, paper, a, b, cores, paper / std::min(a, b));
  };
  physical_row("image sources, order 3", 820.0, images1, imagesn);
  physical_row("  the same, --no-occlusion", 820.0, images_open, images_open);
  physical_row("late tail (default: to the error)", 820.0, tail1, tailn);
  physical_row("late tail, 20000 rays (no bound)", 820.0, fixed1, fixedn);
  physical_row("late tail, 2000 rays (no bound)", 820.0, few1, fewn);
  // The whole response: both searches and the assembly (threshold and create filter).
  physical_row("whole response", 820.0 + 0.3, whole1, wholen);
  physical_row("  its spectrum (for the 1 s source)", 0.3, spectrum, spectrum);
  physical_row("apply whole response (reused output)", 4.05, long1, longn);
  physical_row("  the same, new output and spectrum", 4.05, both1, bothn);
  physical_row("  single precision (as vola sonify)", 4.05, single1, singlen);
  physical_row("  single, new output and spectrum", 4.05, single_both1, single_both1);
  physical_row("  one transform of 4x the response", 4.05, longest1, longest1);
  physical_row("  the same, partitioned (8192)", 4.05, part1, partn);
  std::printf("\nsingle precision: max |single - double| %.2g, %.2g of the output's peak\n", single_apart,
              single_apart / scale);
  std::printf("\na 10 s response (480,000 taps) on a 1 s source, FFTW_ESTIMATE plans as in vola sonify, 1 thread: one "
              "transform %.1f ms, partitioned (8192) %.1f ms\n", hall_one, hall_part);
  return 0;
}
