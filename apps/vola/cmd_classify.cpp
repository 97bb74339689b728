// vola classify / vola evaluate: a trained 3D CNN (the committed small model unless
// --model) on one .vol file or on a labelled dataset folder.
#include <nlohmann/json.hpp>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "commands.hpp"
#include "number_checks.hpp"
#include "png_writer.hpp"
#include "progress.hpp"
#include "vola/error.hpp"
#include "vola/file.hpp"
#include "vola/output_stream.hpp"
#include "vola/learn/classifier.hpp"
#include "vola/learn/segment.hpp"

namespace vola::cli {

namespace {

using learn::kClassCount;
using learn::kClassNames;

struct ClassifyArgs {
  std::vector<std::string> inputs;
  std::string model, png = "confusion.png", json;
  int threads = 0, batch = 32, votes = 1;
  bool segment = false;
  std::string orientations = "best";
  learn::SegmentOptions segment_options;
  CLI::Option* votes_option = nullptr;
  CLI::Option* plane_fill_option = nullptr;
  CLI::Option* orientations_option = nullptr;
  // With --segment: the votes given, or the four quarter turns of the object's footprint.
  int segment_votes() const { return votes_option && votes_option->count() ? votes : 4; }
  std::string vote_key() const {
    return std::string(segment ? "evaluation_segment_votes_" : "evaluation_votes_") +
           std::to_string(segment ? segment_votes() : votes);
  }
};

void check_segment_args(const ClassifyArgs& a) {
  if (!a.segment) {
    for (const CLI::Option* o : {a.plane_fill_option, a.orientations_option})
      if (o && o->count()) throw InvalidArgument(o->get_name() + " applies only with --segment");
    return;
  }
  if (a.orientations != "best" && a.orientations != "mean")
    throw InvalidArgument("--orientations must be best or mean, got '" + a.orientations + "'");
}

const char* axis_name(int axis) { return axis == 0 ? "x" : axis == 1 ? "y" : "z"; }

void print_segmentation(const learn::Segmentation& s, double vote_degrees) {
  std::printf("removed planes:");
  if (s.removal.planes.empty()) std::printf(" none");
  for (const auto& p : s.removal.planes)
    std::printf(" %s %s (%s = %u, %d layer%s, %llu voxels);", axis_name(p.axis), p.at_max ? "max" : "min", axis_name(p.axis),
                p.first, p.layers, p.layers == 1 ? "" : "s", static_cast<unsigned long long>(p.voxels));
  std::printf("\npieces left: %zu\n", s.components);
  if (s.found())
    std::printf("object: %llu voxels, box (%u %u %u)-(%u %u %u), footprint turned %.0f degrees, classified "
                "turned %.0f more\n",
                static_cast<unsigned long long>(s.object.voxel_count()), s.min.x, s.min.y, s.min.z, s.max.x, s.max.y, s.max.z,
                s.footprint_angle * 180 / 3.14159265358979323846, vote_degrees);
}

// The model file --model names (a path, or a committed model's name such as
// modelnet10-small-room, looked for where the default is), else the committed one for
// the task.
std::string model_path(const ClassifyArgs& a) {
  if (a.model.empty())
    return learn::default_model_path(a.segment ? learn::kSegmentedRoomModelFile : learn::kDefaultModelFile);
  std::error_code error;
  if (std::filesystem::exists(a.model, error) || a.model.find('/') != std::string::npos) return a.model;
  const std::string file = a.model.ends_with(".pt") ? a.model : a.model + ".pt";
  try {
    return learn::default_model_path(file, true);
  } catch (const IoError& e) {
    throw IoError("--model " + a.model + ": no such file here, nor a committed model of that name (" + e.what() + ")");
  }
}

learn::Classifier load_classifier(const ClassifyArgs& a, const std::string& path) {
  learn::set_threads(a.threads);
  return learn::Classifier(path);
}

std::size_t best_class(const std::array<float, kClassCount>& p) {
  return std::size_t(std::max_element(p.begin(), p.end()) - p.begin());
}

void run_classify(const ClassifyArgs& a) {
  check_segment_args(a);
  const learn::Classifier classifier = load_classifier(a, model_path(a));
  const int side = learn::input_side(classifier.architecture());
  for (const auto& input : a.inputs) {
    const Tree tree = read(input);
    if (tree.side() < std::uint32_t(side))
      throw InvalidArgument(input + ": a " + std::to_string(tree.side()) + "^3 grid; the model reads " +
                            std::to_string(side) + "^3 or finer");
    if (tree.voxel_count() == 0) throw InvalidArgument(input + ": holds no voxels: nothing to classify");
    const Tree* trees[] = {&tree};
    std::array<float, kClassCount> p;
    learn::SegmentedClassification found;
    if (a.segment) {
      learn::SegmentOptions options = a.segment_options;
      options.average_orientations = a.orientations == "mean";
      found = learn::classify_segmented(classifier, trees, options, a.segment_votes()).front();
      if (!found.segmentation.found())
        throw InvalidArgument(input + ": no object left once the bounding planes were removed (" +
                              std::to_string(found.segmentation.removal.planes.size()) + " planes, no piece of " +
                              std::to_string(options.min_voxels) + " voxels or more)");
      p = found.probabilities;
    } else {
      p = classifier.classify(trees, a.votes).front();
    }
    const std::size_t best = best_class(p);
    if (a.inputs.size() > 1) std::printf("%s: ", input.c_str());
    std::printf("%s %.4f\n", std::string(kClassNames[best]).c_str(), p[best]);
    for (int k = 0; k < kClassCount; ++k)
      std::printf("  %-12s %.4f\n", std::string(kClassNames[std::size_t(k)]).c_str(), p[std::size_t(k)]);
    if (a.segment) print_segmentation(found.segmentation, 360.0 * found.vote / a.segment_votes());
  }
}

// The confusion matrix as a heat map: 10 x 10 squares of 24 pixels, row = true class,
// column = predicted, white (none of the row) to dark blue (all of it); the diagonal
// framed in grey.
void write_confusion_png(const std::string& path, const std::vector<std::vector<std::size_t>>& confusion) {
  constexpr std::uint32_t cell = 24, size = cell * kClassCount;
  std::vector<std::uint8_t> rgb(std::size_t(size) * size * 3);
  for (std::uint32_t py = 0; py < size; ++py)
    for (std::uint32_t px = 0; px < size; ++px) {
      const std::size_t row = py / cell, column = px / cell;
      std::size_t total = 0;
      for (std::size_t c : confusion[row]) total += c;
      const double f = total ? double(confusion[row][column]) / double(total) : 0.0;
      const bool frame = row == column && (px % cell == 0 || py % cell == 0 || px % cell == cell - 1 || py % cell == cell - 1);
      std::uint8_t* out = &rgb[(std::size_t(py) * size + px) * 3];
      if (frame) {
        out[0] = out[1] = out[2] = 128;
      } else {
        out[0] = std::uint8_t(255 - 247 * f);
        out[1] = std::uint8_t(255 - 207 * f);
        out[2] = std::uint8_t(255 - 148 * f);
      }
    }
  write_png_rgb8(path, size, size, rgb);
}

void run_evaluate(const ClassifyArgs& a) {
  check_segment_args(a);
  const std::string path = model_path(a);
  const learn::Classifier classifier = load_classifier(a, path);
  learn::SegmentOptions segment_options = a.segment_options;
  segment_options.average_orientations = a.orientations == "mean";
  std::size_t not_found = 0;
  std::vector<std::size_t> missed(kClassCount, 0);  // per true class: scenes where no object was found
  const auto entries = learn::list_dataset(a.inputs.front());
  const auto samples = learn::load_samples(entries, learn::input_side(classifier.architecture()));
  std::vector<std::vector<std::size_t>> confusion(kClassCount, std::vector<std::size_t>(kClassCount, 0));
  std::size_t correct = 0;
  Progress progress("evaluate");
  const auto start = std::chrono::steady_clock::now();
  for (std::size_t first = 0; first < samples.size(); first += std::size_t(a.batch)) {
    const std::size_t count = std::min(std::size_t(a.batch), samples.size() - first);
    std::vector<const Tree*> trees;
    for (std::size_t i = 0; i < count; ++i) trees.push_back(&samples[first + i].tree);
    std::vector<std::array<float, kClassCount>> probabilities;
    std::vector<bool> found(count, true);
    if (a.segment) {
      const auto segmented = learn::classify_segmented(classifier, trees, segment_options, a.segment_votes());
      for (std::size_t i = 0; i < count; ++i) {
        probabilities.push_back(segmented[i].probabilities);
        found[i] = segmented[i].segmentation.found();
      }
    } else {
      probabilities = classifier.classify(trees, a.votes);
    }
    for (std::size_t i = 0; i < count; ++i) {
      const std::size_t truth = std::size_t(samples[first + i].label);
      if (!found[i]) {  // no object: wrong, and outside the confusion matrix
        ++not_found;
        ++missed[truth];
        continue;
      }
      const std::size_t predicted = best_class(probabilities[i]);
      ++confusion[truth][predicted];
      correct += truth == predicted;
    }
    progress.update(first + count, samples.size());
  }
  progress.finish();
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  std::printf("model: %s\n", path.c_str());
  if (a.segment)
    std::printf("%zu samples, %s model, %.2f ms per sample (batch %d, segmented, %d votes, %s, "
                "segmentation + fill + network)\nno object found in %zu (counted as wrong, not in the matrix)\n\n",
                samples.size(), std::string(learn::architecture_name(classifier.architecture())).c_str(),
                1000 * seconds / double(samples.size()), a.batch, a.segment_votes(),
                a.orientations == "mean" ? "their mean" : "the most confident kept", not_found);
  else
    std::printf("%zu samples, %s model, %.2f ms per sample (batch %d, %d vote%s, fill + network)\n\n", samples.size(),
                std::string(learn::architecture_name(classifier.architecture())).c_str(),
                1000 * seconds / double(samples.size()), a.batch, a.votes, a.votes == 1 ? "" : "s");
  std::printf("per-class accuracy:\n");
  double class_accuracy_sum = 0;
  int classes_seen = 0;
  for (int k = 0; k < kClassCount; ++k) {
    std::size_t total = 0;
    for (std::size_t c : confusion[std::size_t(k)]) total += c;
    total += missed[std::size_t(k)];
    if (total == 0) continue;
    class_accuracy_sum += double(confusion[std::size_t(k)][std::size_t(k)]) / double(total);
    ++classes_seen;
    std::printf("  %-12s %.4f  (%zu of %zu)\n", std::string(kClassNames[std::size_t(k)]).c_str(),
                double(confusion[std::size_t(k)][std::size_t(k)]) / double(total), confusion[std::size_t(k)][std::size_t(k)], total);
  }
  std::printf("\nconfusion matrix (rows: true class, columns: predicted):\n%12s", "");
  for (int k = 0; k < kClassCount; ++k) std::printf(" %5.5s", std::string(kClassNames[std::size_t(k)]).c_str());
  std::printf("\n");
  for (int r = 0; r < kClassCount; ++r) {
    std::printf("%-12s", std::string(kClassNames[std::size_t(r)]).c_str());
    for (int c = 0; c < kClassCount; ++c) std::printf(" %5zu", confusion[std::size_t(r)][std::size_t(c)]);
    std::printf("\n");
  }
  if (!a.png.empty()) {
    write_confusion_png(a.png, confusion);
    std::printf("confusion matrix image: %s\n", a.png.c_str());
  }
  if (!a.json.empty()) {
    // Merged into the file (a model's run record, say) under "evaluation_votes_<N>"
    // ("evaluation_segment_votes_<N>" with --segment).
    nlohmann::json record = nlohmann::json::object();
    if (std::ifstream previous(a.json); previous) {
      record = nlohmann::json::parse(previous, nullptr, false);
      if (record.is_discarded() || !record.is_object()) throw FormatError(a.json, std::nullopt, "not a JSON object");
    }
    nlohmann::json per_class = nlohmann::json::object();
    for (int k = 0; k < kClassCount; ++k) {
      std::size_t total = 0;
      for (std::size_t c : confusion[std::size_t(k)]) total += c;
      total += missed[std::size_t(k)];
      if (total) per_class[std::string(kClassNames[std::size_t(k)])] = double(confusion[std::size_t(k)][std::size_t(k)]) / double(total);
    }
    record[a.vote_key()] = {
        {"dir", a.inputs.front()},
        {"samples", samples.size()},
        {"votes", a.segment ? a.segment_votes() : a.votes},
        {"segment", a.segment},
        {"not_found", not_found},
        {"accuracy", double(correct) / double(samples.size())},
        {"mean_per_class_accuracy", class_accuracy_sum / classes_seen},
        {"per_class_accuracy", per_class},
        {"confusion_rows_true_columns_predicted", confusion}};
    OutputStream out(a.json);
    out << record.dump(2) << '\n';
    out.commit();
  }
  std::printf("mean per-class accuracy: %.4f (%d classes)\n", class_accuracy_sum / classes_seen, classes_seen);
  std::printf("accuracy: %.4f\n", double(correct) / double(samples.size()));
}

void add_model_options(CLI::App* cmd, ClassifyArgs& args) {
  cmd->add_option("--model", args.model, "Model file written by `vola train` (default: the committed small model)");
  cmd->add_option("--threads", args.threads, "Threads (0: all cores)")->capture_default_str()->check(non_negative_number());
  args.votes_option = cmd->add_option("--votes", args.votes,
                  "Test-time voting: see each object turned about z by 360*k/N degrees (k = 0..N-1) and "
                  "average the N softmax outputs (for models trained with --max-rotation 180); with --segment: the "
                  "turns of the found object, 4 by default")
      ->capture_default_str()
      ->check(CLI::Range(1, 360));
  cmd->add_flag("--segment", args.segment,
                "Find the object first: remove the floor, walls and ceiling (layers at the scene's bounds that fill at "
                "least --plane-fill of its cross-section, up to 4 deep), group the 26-connected components whose boxes "
                "touch into pieces (16 voxels or more), keep the piece with the largest bounding box and the pieces "
                "standing in its footprint, turn it to the axes of its horizontal layers, scale its longest extent to "
                "64 voxels, centre it, and classify that with a model of clean objects (the default model), turned by "
                "the --votes (4: the quarter turns); --orientations says how the votes are combined");
  args.plane_fill_option =
      cmd->add_option("--plane-fill", args.segment_options.plane_fill,
                      "With --segment: the share of the scene's cross-section a bounding layer must fill to be a plane")
          ->capture_default_str()
          ->check(CLI::Range(0.01, 1.0));
  args.orientations_option =
      cmd->add_option("--orientations", args.orientations,
                      "With --segment: 'best' keeps the most confident vote (models trained on aligned objects, as the "
                      "default), 'mean' averages them (models trained with --max-rotation 180)")
          ->capture_default_str()
          ->check(CLI::IsMember({"best", "mean"}));
}

constexpr const char* kModelFooter =
    "Without --model the committed small model models/modelnet10-small.pt is used (with --segment\n"
    "models/modelnet10-small-room-segmented.pt, trained on the objects --segment finds in rooms), looked for in\n"
    "$VOLA_MODEL (the model file, or a folder holding it; a name that is neither is an error),\n"
    "<vola's folder>/../share/vola/models/ (installed), <vola's folder>/../models/, ../../models/ and\n"
    "../../../models/ (a build folder in the source tree), then the source tree vola was built from.\n"
    "--model takes a file, or a committed model's name (modelnet10-small-room), looked for in the same places.\n"
    "`vola evaluate` prints the model file it used.\n";

}  // namespace

void add_classify(CLI::App& app) {
  auto args = std::make_shared<ClassifyArgs>();
  auto* classify = app.add_subcommand("classify", kClassifySummary);
  classify->footer(
      std::string(kModelFooter) +
      "Prints the most likely class and its probability, then all ten probabilities.\n"
      "Files are 64^3 trees as `vola dataset` writes (finer grids are read at 64^3 or 32^3).\n"
      "With --segment the object is first found in a scene (a room with floor, walls, clutter: `vola\n"
      "dataset --background`, or a voxelised scan): the class lines come first, then the planes removed,\n"
      "the pieces left and the object kept (voxels, box, the turn of its footprint, the vote kept).\n"
      "A scene with no object left once its planes are removed is an error.\n"
      "Examples:\n  vola classify data/clean/val/chair/chair_01234.vol\n"
      "  vola classify data/room/val/chair/chair_01234.vol --model modelnet10-small-room --votes 12\n"
      "  vola classify data/room/val/chair/chair_01234.vol --segment        # the room-segmented model\n"
      "  vola classify data/room/val/chair/chair_01234.vol --segment --model modelnet10-small-full-circle \\\n"
      "    --votes 12 --orientations mean");
  classify->add_option("file", args->inputs, ".vol files")->required()->check(CLI::ExistingFile);
  add_model_options(classify, *args);
  classify->callback([args] { run_classify(*args); });

  auto eargs = std::make_shared<ClassifyArgs>();
  auto* evaluate = app.add_subcommand("evaluate", kEvaluateSummary);
  evaluate->footer(
      std::string(kModelFooter) +
      "DIR holds <class>/*.vol (as `vola dataset` writes). Prints the speed, per-class accuracy and\n"
      "the confusion matrix, writes it as a PNG heat map (rows true, columns predicted), and ends\n"
      "with the lines `mean per-class accuracy: 0.xxxx (N classes)` and `accuracy: 0.xxxx`.\n"
      "With --segment each scene's object is found first (see `vola classify --help`); scenes where none\n"
      "is found count as wrong and are said.\n"
      "Examples:\n  vola evaluate data/clean/val --png val_confusion.png\n"
      "  vola evaluate data/room/val --model modelnet10-small-room --votes 12\n"
      "  vola evaluate data/room/val --segment                 # the room-segmented model, 4 votes\n"
      "  vola evaluate data/room/val --segment --model modelnet10-small-full-circle --votes 12 --orientations mean");
  evaluate->add_option("dir", eargs->inputs, "Dataset folder")->required()->expected(1)->check(CLI::ExistingDirectory);
  evaluate->add_option("--png", eargs->png, "Confusion matrix image ('' for none)")->capture_default_str();
  evaluate->add_option("--json", eargs->json,
                       "Also write the figures and confusion matrix into this JSON file (e.g. the model's run record), "
                       "under \"evaluation_votes_<N>\" (\"evaluation_segment_votes_<N>\" with --segment); other keys are kept");
  evaluate->add_option("--batch", eargs->batch, "Samples per batch")->capture_default_str()->check(CLI::Range(1, 4096));
  add_model_options(evaluate, *eargs);
  evaluate->callback([eargs] { run_evaluate(*eargs); });
}

}  // namespace vola::cli
