// vola sonify: hear a scene. Sources and a listener inside a .vol scene; every surface
// voxel reflects; the impulse response (direct sound + binned early reflections) filters
// the dry recording (the paper's SonifEye, section IV).
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

#include "commands.hpp"
#include "open_voxels.hpp"
#include "ir_plot.hpp"
#include "vola/audio/convolve.hpp"
#include "vola/audio/materials.hpp"
#include "vola/audio/response.hpp"
#include "vola/audio/wav.hpp"
#include "vola/error.hpp"
#include "vola/file.hpp"

namespace vola::cli {

namespace {

struct SonifyArgs {
  std::string scene, materials, output, ir, plot, channels = "mix", format = "pcm16";
  std::vector<std::vector<double>> sources;
  std::vector<double> listener;
  std::vector<std::string> inputs;
  double reflection = 0.5;
  bool payload_coefficients = false, no_normalize = false, quiet = false;
  audio::ResponseOptions response;
};

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

// The sources' wet signals into one sound: mixed to one channel or one channel each,
// normalised to -1 dBFS unless asked not to.
audio::Sound output_sound(const SonifyArgs& a, std::vector<std::vector<double>>& wet, int sample_rate) {
  audio::Sound out;
  out.sample_rate = sample_rate;
  std::size_t frames = 0;
  for (const auto& w : wet) frames = std::max(frames, w.size());
  if (a.channels == "mix") {
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

void run_sonify(SonifyArgs& a) {
  if (a.payload_coefficients && !a.materials.empty())
    throw InvalidArgument("--payload-coefficients and --materials both say where coefficients come from: give one");
  const std::vector<audio::Sound> dry = read_dry(a);
  a.response.sample_rate = dry[0].sample_rate;
  a.response.check();

  audio::MaterialTable table = audio::scene_material(a.reflection);
  if (!a.materials.empty()) table = audio::read_material_table(a.materials);
  if (a.payload_coefficients) table.source = audio::MaterialSource::payload_value;
  const Tree tree = open_voxels(a.scene);
  const audio::AcousticScene scene(tree, table);
  const Point listener{a.listener[0], a.listener[1], a.listener[2]};

  std::vector<std::vector<double>> responses, wet;
  std::vector<PlotPanel> panels;
  for (std::size_t s = 0; s < a.sources.size(); ++s) {
    const Point source{a.sources[s][0], a.sources[s][1], a.sources[s][2]};
    const auto t0 = std::chrono::steady_clock::now();
    const audio::Thresholded binned = audio::threshold(scene, source, listener, a.response);
    std::vector<double> ir = audio::make_filter(scene, binned, a.response);
    const auto t1 = std::chrono::steady_clock::now();
    const std::vector<double> signal = dry[dry.size() == 1 ? 0 : s].mono();
    wet.push_back(audio::Convolver(ir).apply(signal, a.response.threads));
    const auto t2 = std::chrono::steady_clock::now();
    if (!a.quiet) {
      const double fs = a.response.sample_rate;
      std::printf("source %zu: direct %.3f scene units, %.2f ms (sample %u)%s; %llu reflecting voxels in %zu bins; "
                  "response %.2f ms; %.1f ms to build, %.1f ms to filter\n",
                  s + 1, binned.direct_distance, binned.direct_sample / fs * 1000.0, binned.direct_sample,
                  binned.direct_blocked ? ", blocked by the scene" : "",
                  static_cast<unsigned long long>(binned.reflectors), binned.bins.size(), static_cast<double>(ir.size()) / fs * 1000.0,
                  std::chrono::duration<double, std::milli>(t1 - t0).count(),
                  std::chrono::duration<double, std::milli>(t2 - t1).count());
    }
    panels.push_back(PlotPanel{ir, binned.direct_blocked ? -1 : static_cast<std::int64_t>(binned.direct_sample)});
    responses.push_back(std::move(ir));
  }

  const audio::Sound out = output_sound(a, wet, dry[0].sample_rate);
  audio::write_wav(a.output, out, sample_format(a.format));
  if (!a.ir.empty()) write_responses(a.ir, responses, out.sample_rate);
  if (!a.plot.empty()) write_response_plot(a.plot, panels, a.response.sample_rate);
  if (!a.quiet)
    std::printf("wrote %s (%zu channel%s, %.3f s at %d Hz)%s%s%s%s\n", a.output.c_str(), out.channels.size(),
                out.channels.size() == 1 ? "" : "s", static_cast<double>(out.frames()) / out.sample_rate,
                out.sample_rate, a.ir.empty() ? "" : ", ", a.ir.c_str(), a.plot.empty() ? "" : ", ", a.plot.c_str());
}

}  // namespace

void add_sonify(CLI::App& app) {
  auto args = std::make_shared<SonifyArgs>();
  auto* cmd = app.add_subcommand("sonify", kSonifySummary);
  cmd->footer(
      "How it works (the VOLA paper's SonifEye): every occupied voxel with an empty 6-neighbour is a\n"
      "reflector. It reflects through each exposed face that both source and listener are in front of,\n"
      "at that face's centre, as a patch of one voxel face: amplitude R * sqrt(A/pi) / (r1 * r2), delay\n"
      "(r1 + r2) / c. The direct sound has amplitude 1/d (1 at 1 m) and is silent when the straight line\n"
      "crosses an occupied voxel. Paths with the same delay sample and the same attenuation bin\n"
      "(--bin-width dB) are counted together, and the bins make an FIR filter (the impulse response,\n"
      "--ir) through which the recording passes by FFT. Only early reflections are modelled: paths\n"
      "arriving more than --window seconds after the straight-line time are left out.\n"
      "World units are metres; the sample rate is the recording's.\n\n"
      "Reflection coefficients R (pressure, 0..1): --reflection for the whole scene, or --materials m.json:\n"
      "  {\"attribute\": \"classification\", \"default\": 0.3,\n"
      "   \"materials\": {\"2\": 0.2, \"6\": [0.98, 0.97, 0.96, 0.95, 0.93, 0.90]}}\n"
      "mapping the value of a per-voxel attribute (or \"payload\": the payload's low byte) to one\n"
      "coefficient or six (octave bands 125..4000 Hz), or --payload-coefficients: payload byte / 255.\n\n"
      "Examples:\n"
      "  vola sonify room.vol --source 1 2 1.5 --listener 4 3 1.6 --in speech.wav --out wet.wav --ir ir.wav --plot ir.png\n"
      "  vola sonify scan.vol --materials m.json --source 1 2 1 --source 5 2 1 --listener 3 3 1 \\\n"
      "      --in violin.wav --in cello.wav --out duo.wav --channels per-source");
  cmd->add_option("scene", args->scene, "The scene (.vol)")->required()->check(CLI::ExistingFile);
  cmd->add_option("--source", args->sources, "Sound source X Y Z (world units, metres); repeat for more sources")
      ->required()
      ->expected(3)
      ->take_all();
  cmd->add_option("--listener", args->listener, "Listener X Y Z")->required()->expected(3);
  cmd->add_option("--in", args->inputs, "Dry recording (WAV): one for all sources or one per source")
      ->required()
      ->check(CLI::ExistingFile);
  cmd->add_option("--out", args->output, "Wet result (WAV)")->required();
  cmd->add_option("--ir", args->ir, "Also write the impulse responses (32-bit float WAV, one channel per source)");
  cmd->add_option("--plot", args->plot, "Also draw the impulse responses (PNG, dB against ms, direct sound in red)");
  cmd->add_option("--materials", args->materials, "Material table (JSON, see below)")->check(CLI::ExistingFile);
  cmd->add_option("--reflection", args->reflection, "Scene-wide reflection coefficient (without --materials)")
      ->capture_default_str()
      ->check(CLI::Range(0.0, 1.0));
  cmd->add_flag("--payload-coefficients", args->payload_coefficients, "Reflection coefficient = payload byte / 255");
  cmd->add_option("--speed-of-sound", args->response.speed_of_sound, "Speed of sound (m/s)")->capture_default_str();
  cmd->add_option("--window", args->response.reflection_window,
                  "Reflections arriving up to this many seconds after the straight-line time")
      ->capture_default_str();
  cmd->add_option("--bin-width", args->response.bin_width_db, "Attenuation bin width (dB)")->capture_default_str();
  cmd->add_option("--floor", args->response.floor_db, "Drop reflections weaker than this (dB re 1 at 1 m)")
      ->capture_default_str();
  cmd->add_flag("--visibility", args->response.visibility,
                "Keep only reflectors seen from both source and listener (two rays per voxel)");
  cmd->add_option("--channels", args->channels, "mix: one channel, all sources summed; per-source: a channel each")
      ->capture_default_str()
      ->check(CLI::IsMember({"mix", "per-source"}));
  cmd->add_option("--format", args->format, "Output samples")->capture_default_str()->check(CLI::IsMember({"pcm16", "pcm24", "float"}));
  cmd->add_flag("--no-normalize", args->no_normalize,
                "Keep the physical level (1 = the dry level at 1 m) instead of peaking at -1 dBFS");
  cmd->add_option("--threads", args->response.threads, "Threads (0 = all cores)")->capture_default_str();
  cmd->add_flag("-q,--quiet", args->quiet, "Print nothing on success");
  cmd->callback([args] { run_sonify(*args); });
}

}  // namespace vola::cli
