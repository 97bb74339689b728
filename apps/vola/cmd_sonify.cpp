// vola sonify: hear a scene. Sources and a listener inside a .vol scene; the impulse
// response filters the dry recording. Two models: the physical one (room_response.hpp:
// image sources over planar patches, occlusion, a ray-traced tail) by default, and the
// paper's SonifEye (section IV: every surface voxel reflects, binned) with --model paper.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <optional>
#include <string>
#include <vector>

#include "commands.hpp"
#include "ir_plot.hpp"
#include "open_voxels.hpp"
#include "output_checks.hpp"
#include "vola/audio/binaural.hpp"
#include "vola/audio/convolve.hpp"
#include "vola/audio/materials.hpp"
#include "vola/audio/response.hpp"
#include "vola/audio/room_response.hpp"
#include "vola/audio/wav.hpp"
#include "vola/error.hpp"
#include "vola/file.hpp"
#include "vola/filters/units.hpp"
#include "vola/geo/crs.hpp"

namespace vola::cli {

namespace {

struct SonifyArgs {
  std::string scene, materials, output, ir, plot, channels = "mix", format = "pcm16", model = "physical";
  std::vector<std::vector<double>> sources;
  std::vector<double> listener;
  std::vector<std::string> inputs;
  double reflection = 0.5, facing = 0.0;
  std::optional<double> absorption;
  bool binaural = false;
  std::string hrtf = "/usr/share/libmysofa/MIT_KEMAR_normal_pinna.sofa";
  bool payload_coefficients = false, no_normalize = false, quiet = false, no_occlusion = false;
  audio::ResponseOptions response;  // --model paper
  audio::RoomOptions room;          // --model physical
};

// The table of reflection coefficients the flags ask for. --absorption A is the pressure
// reflection coefficient sqrt(1 - A) for every surface a material table does not list.
audio::MaterialTable material_table(const SonifyArgs& a) {
  if (a.absorption && !(*a.absorption >= 0.0 && *a.absorption <= 1.0))
    throw InvalidArgument("--absorption must be in [0, 1] (got " + std::to_string(*a.absorption) + ")");
  audio::MaterialTable table = audio::scene_material(a.absorption ? std::sqrt(1.0 - *a.absorption) : a.reflection);
  if (!a.materials.empty()) {
    const audio::Material fallback = table.fallback;
    table = audio::read_material_table(a.materials);
    if (a.absorption) table.fallback = fallback;
  }
  if (a.payload_coefficients) table.source = audio::MaterialSource::payload_value;
  return table;
}

// One source's response by the chosen model, and its line of report.
struct SourceResponse {
  std::vector<double> ir;           // the left ear with --binaural
  std::vector<double> right;        // the right ear with --binaural, else empty
  std::int64_t direct_sample = -1;  // -1 when blocked
  std::string report;
};

SourceResponse physical_response(const audio::Room& room, const Point& source, const Point& listener, const SonifyArgs& a,
                                 const audio::Hrtf* hrtf) {
  const audio::RoomResponse r = audio::room_response(room, source, listener, a.room);
  const double fs = a.room.sample_rate;
  char tail[128] = "no tail";
  if (a.room.rays > 0)
    std::snprintf(tail, sizeof tail, "tail from %llu rays (relative error %.3f; receiver radius %.2f m)",
                  static_cast<unsigned long long>(r.late.rays), r.late.relative_error, r.late.receiver_radius);
  char line[512];
  std::snprintf(line, sizeof line,
                "direct %.3f m, %.2f ms (sample %u)%s; %zu image sources up to order %d of %zu patches; %s; response %.2f ms",
                r.direct_distance, r.direct_sample / fs * 1000.0, r.direct_sample,
                r.direct_blocked ? ", blocked by the scene" : "", r.early.images.size(), r.early.order,
                room.patches().patches().size(), tail, static_cast<double>(r.ir.size()) / fs * 1000.0);
  const std::int64_t direct = r.direct_blocked ? -1 : static_cast<std::int64_t>(r.direct_sample);
  if (!hrtf) return {r.ir, {}, direct, line};
  auto ears = audio::binaural_response(r, *hrtf, source, listener, a.facing, a.room);
  return {std::move(ears[0]), std::move(ears[1]), direct, line};
}

SourceResponse paper_response(const audio::AcousticScene& scene, const Point& source, const Point& listener, const SonifyArgs& a) {
  const audio::Thresholded binned = audio::threshold(scene, source, listener, a.response);
  std::vector<double> ir = audio::make_filter(scene, binned, a.response);
  const double fs = a.response.sample_rate;
  char line[512];
  std::snprintf(line, sizeof line,
                "direct %.3f scene units, %.2f ms (sample %u)%s; %llu reflecting voxels in %zu bins; response %.2f ms",
                binned.direct_distance, binned.direct_sample / fs * 1000.0, binned.direct_sample,
                binned.direct_blocked ? ", blocked by the scene" : "", static_cast<unsigned long long>(binned.reflectors),
                binned.bins.size(), static_cast<double>(ir.size()) / fs * 1000.0);
  const std::int64_t direct = binned.direct_blocked ? -1 : static_cast<std::int64_t>(binned.direct_sample);
  return {std::move(ir), {}, direct, line};
}

audio::SampleFormat sample_format(const std::string& name) {
  if (name == "pcm16") return audio::SampleFormat::pcm16;
  if (name == "pcm24") return audio::SampleFormat::pcm24;
  return audio::SampleFormat::float32;
}

// The dry recordings, checked before any work on the scene: one for all sources or one
// per source, each with samples, all at one rate.
std::vector<audio::Sound> read_dry(const SonifyArgs& a) {
  if (!a.inputs.empty() && a.inputs.size() != 1 && a.inputs.size() != a.sources.size())
    throw InvalidArgument("give one --in for all sources or one per --source (" + std::to_string(a.sources.size()) +
                          " sources, " + std::to_string(a.inputs.size()) + " inputs)");
  std::vector<audio::Sound> dry;
  for (const auto& path : a.inputs) dry.push_back(audio::read_sound(path));
  for (std::size_t i = 0; i < dry.size(); ++i) {
    if (dry[i].frames() == 0) throw FormatError(a.inputs[i], std::nullopt, "the recording has no samples");
    if (dry[i].sample_rate != dry[0].sample_rate)
      throw InvalidArgument(a.inputs[i] + " is at " + std::to_string(dry[i].sample_rate) + " Hz but " + a.inputs[0] +
                            " at " + std::to_string(dry[0].sample_rate) + " Hz: resample them to one rate");
  }
  return dry;
}

// The recording through a response: in one transform sized for the recording while that
// stays within 2^17 points (a 1 s recording through a 0.86 s response: two blocks of
// 65,536), in single precision (errors near 1e-7 of full scale, a few steps of a 24-bit
// sample); otherwise (a reverberation tail of seconds) in partitions of 8192 samples,
// whose transforms stay 16,384 points long however long the response is.
std::vector<double> filter_signal(const std::vector<double>& ir, const std::vector<double>& signal, unsigned threads) {
  constexpr std::size_t kPartition = 8192, kLargestTransform = std::size_t{1} << 17;
  if (audio::Convolver::transform_size(ir.size(), signal.size()) <= kLargestTransform)
    return audio::Convolver(ir, audio::FftPlanning::estimate, signal.size(), audio::SamplePrecision::float32)
        .apply(signal, threads);
  return audio::PartitionedConvolver(ir, kPartition).apply(signal, threads);
}

// The sources' wet signals into one sound: mixed to one channel or one channel each,
// normalised to -1 dBFS unless asked not to.
audio::Sound output_sound(const SonifyArgs& a, std::vector<std::vector<double>>& wet, std::vector<std::vector<double>>& wet_right,
                          int sample_rate) {
  audio::Sound out;
  out.sample_rate = sample_rate;
  std::size_t frames = 0;
  for (const auto& w : wet) frames = std::max(frames, w.size());
  for (const auto& w : wet_right) frames = std::max(frames, w.size());
  if (a.binaural) {  // left and right, every source mixed into each
    out.channels.assign(2, std::vector<double>(frames, 0.0));
    for (int ear = 0; ear < 2; ++ear)
      for (const auto& w : ear == 0 ? wet : wet_right)
        for (std::size_t i = 0; i < w.size(); ++i) out.channels[static_cast<std::size_t>(ear)][i] += w[i];
  } else if (a.channels == "mix") {
    out.channels.assign(1, std::vector<double>(frames, 0.0));
    for (const auto& w : wet)
      for (std::size_t i = 0; i < w.size(); ++i) out.channels[0][i] += w[i];
  } else {
    for (auto& w : wet) {
      w.resize(frames, 0.0);
      out.channels.push_back(std::move(w));
    }
  }
  if (!a.no_normalize) {
    double peak = 0.0;
    for (const auto& c : out.channels)
      for (const double v : c) peak = std::max(peak, std::abs(v));
    // -1 dBFS: loud enough to hear, with room for resampling overshoot downstream.
    const double gain = peak > 0.0 ? std::pow(10.0, -1.0 / 20.0) / peak : 1.0;
    for (auto& c : out.channels)
      for (double& v : c) v *= gain;
    if (!a.quiet) std::printf("output scaled by %+.1f dB to peak at -1 dBFS\n", 20.0 * std::log10(gain));
  }
  return out;
}

// The impulse responses, one channel per source, as a float WAV.
void write_responses(const std::string& path, const std::vector<std::vector<double>>& responses, int sample_rate) {
  audio::Sound irs;
  irs.sample_rate = sample_rate;
  std::size_t n = 0;
  for (const auto& r : responses) n = std::max(n, r.size());
  for (auto r : responses) {
    r.resize(n, 0.0);
    irs.channels.push_back(std::move(r));
  }
  audio::write_wav(path, irs, audio::SampleFormat::float32);
}

// The responses, the wet signal and the files, for a scene in metres (positions given in
// the scene's units, `metres` per unit).
void sonify_scene(const SonifyArgs& a, const Tree& tree, const audio::MaterialTable& table,
                  const std::vector<audio::Sound>& dry, double metres) {
  const bool physical = a.model == "physical";
  const audio::AcousticScene scene(tree, table);
  const Point listener{a.listener[0] * metres, a.listener[1] * metres, a.listener[2] * metres};
  // Patches depend on the scene only: found once for every source.
  std::optional<audio::Room> room;
  if (physical) room.emplace(scene);
  std::optional<audio::Hrtf> hrtf;
  if (a.binaural) hrtf.emplace(a.hrtf, a.room.sample_rate);

  std::vector<std::vector<double>> responses, wet, wet_right;
  std::vector<PlotPanel> panels;
  for (std::size_t s = 0; s < a.sources.size(); ++s) {
    const Point source{a.sources[s][0] * metres, a.sources[s][1] * metres, a.sources[s][2] * metres};
    const auto t0 = std::chrono::steady_clock::now();
    SourceResponse r = physical ? physical_response(*room, source, listener, a, hrtf ? &*hrtf : nullptr)
                                : paper_response(scene, source, listener, a);
    const auto t1 = std::chrono::steady_clock::now();
    const std::vector<double> signal = dry[dry.size() == 1 ? 0 : s].mono();
    wet.push_back(filter_signal(r.ir, signal, a.response.threads));
    if (!r.right.empty()) wet_right.push_back(filter_signal(r.right, signal, a.response.threads));
    const auto t2 = std::chrono::steady_clock::now();
    if (!a.quiet)
      std::printf("source %zu: %s; %.1f ms to build, %.1f ms to filter\n", s + 1, r.report.c_str(),
                  std::chrono::duration<double, std::milli>(t1 - t0).count(),
                  std::chrono::duration<double, std::milli>(t2 - t1).count());
    panels.push_back(PlotPanel{r.ir, r.direct_sample});
    responses.push_back(std::move(r.ir));
    if (!r.right.empty()) {  // the right ear next to the left, in the plot and the IR file
      panels.push_back(PlotPanel{r.right, r.direct_sample});
      responses.push_back(std::move(r.right));
    }
  }

  const audio::Sound out = output_sound(a, wet, wet_right, dry[0].sample_rate);
  audio::write_wav(a.output, out, sample_format(a.format));
  if (!a.ir.empty()) write_responses(a.ir, responses, out.sample_rate);
  if (!a.plot.empty()) write_response_plot(a.plot, panels, a.response.sample_rate);
  if (!a.quiet)
    std::printf("wrote %s (%zu channel%s, %.3f s at %d Hz)%s%s%s%s\n", a.output.c_str(), out.channels.size(),
                out.channels.size() == 1 ? "" : "s", static_cast<double>(out.frames()) / out.sample_rate,
                out.sample_rate, a.ir.empty() ? "" : ", ", a.ir.c_str(), a.plot.empty() ? "" : ", ", a.plot.c_str());
}

// Sound is computed in metres (the speed of sound, amplitude 1 at 1 m, air absorption,
// Fresnel zones): a scene whose CRS is in another length unit (a survey in feet) is
// scaled to metres, its frame and the flags' positions alike, so the positions stay in
// the file's own units. Returns the metres per unit (1 without a CRS).
double scale_scene_to_metres(Tree& tree, const SonifyArgs& a) {
  const Georef& georef = tree.georef();
  const std::optional<std::uint32_t> epsg =
      georef.epsg == geo::kUnsetEpsg ? std::nullopt : std::optional<std::uint32_t>(georef.epsg);
  filters::Units units;
  try {
    units = filters::units_of_crs(epsg, georef.crs_wkt);
  } catch (const InvalidArgument& e) {
    throw InvalidArgument(a.scene + ": " + e.what() + " (vola convert --target-crs, to a CRS in metres or feet)");
  }
  if (units.vertical != units.horizontal)
    throw InvalidArgument(a.scene + ": its CRS has heights in another unit than x and y (" +
                          std::to_string(units.horizontal) + " and " + std::to_string(units.vertical) +
                          " m per unit): sound needs one unit for all three axes (vola convert --target-crs)");
  if (units.horizontal == 1.0) return 1.0;
  Frame frame = tree.frame();
  for (double& c : frame.origin) c *= units.horizontal;
  frame.voxel_size *= units.horizontal;
  tree.set_frame(frame);
  if (!a.quiet)
    std::printf("%s is in units of %.10g m (its CRS): positions are read in those units, distances reported in metres\n",
                a.scene.c_str(), units.horizontal);
  return units.horizontal;
}

void run_sonify(SonifyArgs& a) {
  std::vector<std::string> inputs = a.inputs;
  inputs.insert(inputs.end(), {a.scene, a.materials, a.hrtf});
  refuse_outputs_over_inputs(inputs, {a.output, a.ir, a.plot}, "vola sonify");
  if (a.payload_coefficients && !a.materials.empty())
    throw InvalidArgument("--payload-coefficients and --materials both say where coefficients come from: give one");
  const bool physical = a.model == "physical";
  if (a.binaural && !physical) throw InvalidArgument("--binaural renders the physical model: drop --model paper");
  if (a.binaural && a.channels != "mix")
    throw InvalidArgument("--binaural writes two channels (left, right) with every source mixed: drop --channels per-source");
  const audio::MaterialTable table = material_table(a);
  const std::vector<audio::Sound> dry = read_dry(a);
  a.response.sample_rate = dry[0].sample_rate;
  a.response.check();
  a.room.sample_rate = dry[0].sample_rate;
  a.room.speed_of_sound = a.response.speed_of_sound;
  a.room.threads = a.response.threads;
  a.room.occlusion = !a.no_occlusion;
  a.room.check();

  Tree tree = open_voxels(a.scene);
  const double metres = scale_scene_to_metres(tree, a);
  try {
    sonify_scene(a, tree, table, dry, metres);
  } catch (const InvalidArgument& e) {
    if (metres == 1.0) throw;
    char units[160];
    std::snprintf(units, sizeof units, " (positions in metres here: the scene's units times %.10g)", metres);
    throw InvalidArgument(e.what() + std::string(units));
  }
}

}  // namespace

void add_sonify(CLI::App& app) {
  auto args = std::make_shared<SonifyArgs>();
  auto* cmd = app.add_subcommand("sonify", kSonifySummary);
  cmd->footer(
      "How it works (--model physical, the default): the scene's surface is split into planar patches\n"
      "(exposed voxel faces joined by a normal fitted to their neighbourhood). The impulse response is\n"
      "  direct:  amplitude 1/d (1 at 1 m) after d/c, silent when the line crosses an occupied voxel;\n"
      "  early:   image sources over the patches up to --order reflections, each kept only when its path\n"
      "           meets every patch it mirrors in and (unless --no-occlusion) every leg is free of voxels\n"
      "           (exact voxel ray casts); amplitude prod(R * sqrt(1 - s)) / path length, R the pressure\n"
      "           reflection coefficient, s = --scattering; a patch smaller than the 1 kHz Fresnel zone\n"
      "           reflects that fraction of it. A scene of very many patches (a survey) stops the search\n"
      "           at the order whose candidates would pass 2 million; the report says the order used;\n"
      "  late:    energy rays traced over the voxels, losing R^2 at each hit and going on\n"
      "           specularly or (probability s) diffusely; each hit sends its diffuse part straight to\n"
      "           the listener if it sees it, specular paths are heard by a sphere around the listener,\n"
      "           and the paths the image sources hold are left out. The energy per millisecond becomes\n"
      "           noise, so the decay follows the room (T30 within 10% of Eyring's formula in closed\n"
      "           rooms, tested). Rays are traced in rounds of 1024 (2048 at least) until the relative\n"
      "           standard error of the energy per 10 ms window, root mean square over the windows down\n"
      "           to 60 dB below the loudest, is at most --tail-error (0.1: about 0.4 dB; judged from\n"
      "           the spread between chunks of 128 rays), or --rays are traced; --tail-error 0: all\n"
      "           --rays. --rays 0: no tail.\n"
      "  bands:   amplitudes and energies are kept per octave band (125 Hz .. 4 kHz): per-band materials\n"
      "           and, with --air, air absorption (ISO 9613-1 at --temperature, --humidity). Bands that\n"
      "           differ are rendered each through an octave filter bank that sums to an impulse.\n"
      "  timing:  arrivals at their exact time as windowed sincs, 16 samples either side (flat to 0.1 dB,\n"
      "           the exact phase, up to 0.3 of the sample rate; tested); --nearest-sample puts each on\n"
      "           the nearest sample instead (no sound before the direct sound's sample).\n"
      "  --binaural: the direct sound and each image source through the HRTF pair (SOFA file, --hrtf) of\n"
      "           the direction it arrives from at a listener facing --facing degrees; the tail as a\n"
      "           diffuse field (its energy as an uncorrelated noise at each ear).\n"
      "--model paper: the VOLA paper's SonifEye: every surface voxel reflects through each exposed face that\n"
      "both ends are in front of, amplitude R * sqrt(A/pi) / (r1 * r2); paths binned by delay sample and\n"
      "attenuation (--bin-width), kept up to --window s after the direct time, --floor, --visibility.\n"
      "Its levels grow as the voxel size shrinks: it is the paper's timing reference, not physics.\n"
      "Positions are in the scene's world units; a scene whose CRS is in feet is scaled to metres for the\n"
      "sound (distances are reported in metres); without a CRS, world units are metres. The sample rate\n"
      "is the recording's.\n\n"
      "Reflection coefficients R (pressure, 0..1): --reflection R or --absorption A (R = sqrt(1 - A)) for the\n"
      "whole scene, or --materials m.json (--absorption then sets the classes the table does not list):\n"
      "  {\"attribute\": \"classification\", \"default\": 0.3,\n"
      "   \"materials\": {\"2\": 0.2, \"6\": [0.98, 0.97, 0.96, 0.95, 0.93, 0.90]}}\n"
      "mapping the value of a per-voxel attribute (or \"payload\": the payload's low byte) to one\n"
      "coefficient or six (octave bands 125..4000 Hz), or\n"
      "--payload-coefficients: payload byte / 255.\n\n"
      "Examples:\n"
      "  vola sonify room.vol --source 1 2 1.5 --listener 4 3 1.6 --in speech.wav --out wet.wav --ir ir.wav --plot ir.png\n"
      "  vola sonify room.vol --absorption 0.2 --order 4 --source 1 2 1.5 --listener 4 3 1.6 --in speech.wav --out wet.wav\n"
      "  vola sonify room.vol --binaural --facing 90 --air --source 1 2 1.5 --listener 4 3 1.6 --in speech.wav --out ears.wav\n"
      "  vola sonify scan.vol --materials m.json --source 1 2 1 --source 5 2 1 --listener 3 3 1 \\\n"
      "      --in violin.wav --in cello.wav --out duo.wav --channels per-source");
  cmd->add_option("scene", args->scene, "The scene (.vol)")->required()->check(CLI::ExistingFile);
  cmd->add_option("--source", args->sources, "Sound source X Y Z (the scene's world units); repeat for more sources")
      ->required()
      ->expected(3)
      ->take_all();
  cmd->add_option("--listener", args->listener, "Listener X Y Z")->required()->expected(3);
  cmd->add_option("--in", args->inputs, "Dry recording (WAV): one for all sources or one per source")
      ->required()
      ->check(CLI::ExistingFile);
  cmd->add_option("--out", args->output, "Wet result (WAV)")->required();
  cmd->add_option("--ir", args->ir, "Also write the impulse responses (32-bit float WAV, one channel per source; left and right with --binaural)");
  cmd->add_option("--plot", args->plot, "Also draw the impulse responses (PNG, dB against ms, direct sound in red)");
  cmd->add_option("--materials", args->materials, "Material table (JSON, see below)")->check(CLI::ExistingFile);
  cmd->add_option("--model", args->model, "physical: image sources, occlusion and a ray-traced tail; paper: SonifEye")
      ->capture_default_str()
      ->check(CLI::IsMember({"physical", "paper"}));
  cmd->add_option("--reflection", args->reflection, "Scene-wide pressure reflection coefficient (without --materials)")
      ->capture_default_str()
      ->check(CLI::Range(0.0, 1.0));
  cmd->add_option("--absorption", args->absorption,
                  "Scene-wide energy absorption coefficient in [0, 1], instead of --reflection (R = sqrt(1 - A))")
      ->excludes("--reflection");
  cmd->add_option("--order", args->room.order, "Image-source reflections at most (physical)")
      ->capture_default_str()
      ->check(CLI::Range(0, 64));
  cmd->add_flag("--no-occlusion", args->no_occlusion,
                "Physical: no ray casts (walls do not hide paths, the direct sound included); faster");
  cmd->add_option("--scattering", args->room.scattering, "Physical: energy fraction reflected diffusely, 0..1")
      ->capture_default_str()
      ->check(CLI::Range(0.0, 1.0));
  cmd->add_option("--rays", args->room.rays, "Physical: rays traced for the late tail at most (0 = no tail)")
      ->capture_default_str();
  cmd->add_option("--tail-error", args->room.tail_error,
                  "Physical: stop tracing once the tail's 10 ms windows have this relative standard error "
                  "(root mean square; 0 = all --rays)")
      ->capture_default_str()
      ->check(CLI::Range(0.0, 0.999));
  cmd->add_option("--length", args->room.max_length, "Physical: the response's longest length (s)")->capture_default_str();
  cmd->add_option("--receiver-radius", args->room.receiver_radius,
                  "Physical: the tail's receiver sphere (m), shrunk to clear the scene")
      ->capture_default_str();
  cmd->add_option("--seed", args->room.seed, "Physical: the tail's random numbers")->capture_default_str();
  cmd->add_flag("--fractional-delay,!--nearest-sample", args->room.fractional_delay,
                "Physical: each arrival at its exact time as a band-limited impulse, 16 samples either side (the "
                "default); --nearest-sample: at the nearest sample");
  cmd->add_flag("--binaural", args->binaural,
                "Physical: two channels, the listener's ears, through the HRTF of --hrtf (the IR file and plot "
                "get left and right per source)");
  cmd->add_option("--hrtf", args->hrtf, "With --binaural: the HRTF (SOFA file)")->capture_default_str();
  cmd->add_option("--facing", args->facing,
                  "With --binaural: the listener faces this azimuth (degrees counterclockwise from +x)")
      ->capture_default_str();
  cmd->add_flag("--air", args->room.air, "Physical: air absorption (ISO 9613-1) on every path, per octave band");
  cmd->add_option("--temperature", args->room.celsius, "Physical, with --air: the air's temperature (degrees C)")
      ->capture_default_str();
  cmd->add_option("--humidity", args->room.humidity, "Physical, with --air: relative humidity (percent)")
      ->capture_default_str();
  cmd->add_flag("--payload-coefficients", args->payload_coefficients, "Reflection coefficient = payload byte / 255");
  cmd->add_option("--speed-of-sound", args->response.speed_of_sound, "Speed of sound (m/s)")->capture_default_str();
  cmd->add_option("--window", args->response.reflection_window,
                  "Paper: reflections arriving up to this many seconds after the straight-line time")
      ->capture_default_str();
  cmd->add_option("--bin-width", args->response.bin_width_db, "Paper: attenuation bin width (dB)")->capture_default_str();
  cmd->add_option("--floor", args->response.floor_db, "Paper: drop reflections weaker than this (dB re 1 at 1 m)")
      ->capture_default_str();
  cmd->add_flag("--visibility", args->response.visibility,
                "Paper: keep only reflectors seen from both source and listener (two rays per voxel)");
  cmd->add_option("--channels", args->channels, "mix: one channel, all sources summed; per-source: a channel each")
      ->capture_default_str()
      ->check(CLI::IsMember({"mix", "per-source"}));
  cmd->add_option("--format", args->format, "Output samples")->capture_default_str()->check(CLI::IsMember({"pcm16", "pcm24", "float"}));
  cmd->add_flag("--no-normalize", args->no_normalize,
                "Keep the physical level (1 = the dry level at 1 m) instead of peaking at -1 dBFS");
  cmd->add_option("--threads", args->response.threads, "Threads (0 = all cores)")->capture_default_str();
  cmd->add_flag("-q,--quiet", args->quiet, "Print nothing on success but warnings (to stderr)");
  cmd->callback([args] { run_sonify(*args); });
}

}  // namespace vola::cli
