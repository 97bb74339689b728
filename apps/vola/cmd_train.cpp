// vola train: a 3D CNN on a dataset folder made by `vola dataset`; seeded, resumable,
// with a JSON record of the run.
#include <nlohmann/json.hpp>

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <set>
#include <string>

#include "commands.hpp"
#include "number_checks.hpp"
#include "progress.hpp"
#include "vola/error.hpp"
#include "vola/output_stream.hpp"
#include "vola/learn/classifier.hpp"

namespace vola::cli {

namespace {

namespace fs = std::filesystem;

struct TrainArgs {
  std::string train_dir, validation_dir, output = "model.pt", checkpoint, json, architecture = "small";
  learn::TrainOptions options;
};

nlohmann::json epoch_json(const learn::EpochReport& r) {
  return {{"epoch", r.epoch},
          {"train_loss", r.train_loss},
          {"train_accuracy", r.train_accuracy},
          {"validation_accuracy", r.validation_accuracy},
          {"learning_rate", r.learning_rate},
          {"seconds", r.seconds}};
}

// `vola dataset` names each object by its class and row, so a file name in both folders is
// one object in both: its validation figure would be a training figure.
void refuse_shared_samples(const std::vector<learn::DatasetEntry>& train, const std::string& train_dir,
                           const std::vector<learn::DatasetEntry>& validation, const std::string& validation_dir) {
  if (validation.empty()) return;
  const auto name = [](const learn::DatasetEntry& e) {
    const fs::path p(e.path);
    return (p.parent_path().filename() / p.filename()).string();
  };
  std::set<std::string> trained;
  for (const auto& e : train) trained.insert(name(e));
  std::size_t shared = 0;
  std::string example;
  for (const auto& e : validation)
    if (trained.count(name(e)) && shared++ == 0) example = name(e);
  if (shared)
    throw InvalidArgument(std::to_string(shared) + " of the " + std::to_string(validation.size()) + " samples of " +
                          validation_dir + " are also in " + train_dir + " (" + example +
                          ", ...): a model cannot be validated on what it trains on; make the two with one `vola "
                          "dataset` run (into an empty folder, or with --overwrite)");
}

void run_train(TrainArgs& a) {
  const auto architecture = learn::parse_architecture(a.architecture);
  if (!architecture) throw InvalidArgument("--arch must be small, wide or paper, not " + a.architecture);
  learn::TrainOptions options = a.options;
  options.architecture = *architecture;
  options.model_path = a.output;
  options.checkpoint_path = a.checkpoint.empty() ? a.output + ".ckpt" : a.checkpoint;
  const std::string json_path = a.json.empty() ? a.output + ".json" : a.json;

  // A folder holding train/ and val/ (as `vola dataset` writes) stands for both.
  std::string train_dir = a.train_dir, validation_dir = a.validation_dir;
  if (validation_dir.empty() && fs::is_directory(fs::path(train_dir) / "train") && fs::is_directory(fs::path(train_dir) / "val")) {
    validation_dir = (fs::path(train_dir) / "val").string();
    train_dir = (fs::path(train_dir) / "train").string();
  }
  const auto train_entries = learn::list_dataset(train_dir);
  const auto validation_entries =
      validation_dir.empty() ? std::vector<learn::DatasetEntry>{} : learn::list_dataset(validation_dir);
  refuse_shared_samples(train_entries, train_dir, validation_entries, validation_dir);
  const auto train_set = learn::load_samples(train_entries);
  const auto validation_set =
      validation_dir.empty() ? std::vector<learn::Sample>{} : learn::load_samples(validation_entries);
  std::printf("training %s (%d^3 input) on %zu samples of %s, validating on %zu%s\n", a.architecture.c_str(),
              learn::input_side(*architecture), train_set.size(), train_dir.c_str(), validation_set.size(),
              validation_dir.empty() ? "" : (" of " + validation_dir).c_str());

  nlohmann::json run;
  if (options.resume) {
    std::ifstream previous(json_path);
    if (previous) run = nlohmann::json::parse(previous, nullptr, false);
    if (run.is_discarded() || !run.is_object()) run = nlohmann::json::object();
  }
  nlohmann::json epochs = run.contains("epochs") ? run["epochs"] : nlohmann::json::array();

  Progress progress("epoch");
  learn::TrainCallbacks callbacks;
  callbacks.on_resume = [&](int first) {
    std::printf("resuming from %s at epoch %d\n", options.checkpoint_path.c_str(), first);
    // Keep the record of the epochs the checkpoint holds, drop any later ones.
    nlohmann::json kept = nlohmann::json::array();
    for (const auto& e : epochs)
      if (e.value("epoch", 0) < first) kept.push_back(e);
    epochs = kept;
  };
  callbacks.on_step = [&](int, std::size_t step, std::size_t steps, double) { progress.update(step, steps); };
  callbacks.on_epoch = [&](const learn::EpochReport& r) {
    progress.finish();
    std::printf("epoch %d/%d  loss %.4f  train accuracy %.4f", r.epoch, options.epochs, r.train_loss, r.train_accuracy);
    if (r.validation_accuracy >= 0) std::printf("  validation accuracy %.4f", r.validation_accuracy);
    std::printf("  lr %.1e  %.1f s\n", r.learning_rate, r.seconds);
    std::fflush(stdout);
    epochs.push_back(epoch_json(r));
    run["architecture"] = a.architecture;
    run["input_side"] = learn::input_side(*architecture);
    run["train_dir"] = train_dir;
    run["validation_dir"] = validation_dir;
    run["train_samples"] = train_set.size();
    run["validation_samples"] = validation_set.size();
    run["classes"] = std::vector<std::string>(learn::kClassNames.begin(), learn::kClassNames.end());
    run["options"] = {{"epochs", options.epochs},
                      {"batch_size", options.batch_size},
                      {"learning_rate", options.learning_rate},
                      {"weight_decay", options.weight_decay},
                      {"seed", options.seed},
                      {"max_rotation_degrees", options.max_rotation_degrees},
                      {"max_scale", options.max_scale},
                      {"max_shift", options.max_shift},
                      {"hollow", options.hollow},
                      {"quarter_turns", options.quarter_turns},
                      {"orientation_bins", options.orientation_bins},
                      {"orientation_weight", options.orientation_weight},
                      {"balanced", options.balanced},
                      {"threads", options.threads}};
    run["model"] = options.model_path;
    run["checkpoint"] = options.checkpoint_path;
    run["epochs_done"] = r.epoch;
    run["epochs"] = epochs;
    OutputStream out(json_path);
    out << run.dump(2) << '\n';
    out.commit();
  };
  const auto reports = learn::train(train_set, validation_set, options, callbacks);
  if (reports.empty())
    std::printf("nothing to do: the checkpoint has all %d epochs\n", options.epochs);
  else if (reports.back().epoch < options.epochs)
    std::printf("stopped after epoch %d of %d; continue with the same command and --resume\n", reports.back().epoch,
                options.epochs);
  std::printf("model: %s  checkpoint: %s  run: %s\n", options.model_path.c_str(), options.checkpoint_path.c_str(),
              json_path.c_str());
}

}  // namespace

void add_train(CLI::App& app) {
  auto args = std::make_shared<TrainArgs>();
  auto* cmd = app.add_subcommand("train", kTrainSummary);
  cmd->footer(
      "TRAIN is a folder of <class>/*.vol files, or a folder holding train/ and val/ (then val/ is the\n"
      "validation set). Architectures: small (VoxNet-like, 32^3 input read at half resolution from the\n"
      "64^3 trees, ~0.9 M weights), wide (deeper on the same 32^3 input: four convolutions to 32, 64,\n"
      "64, 128 channels with batch norm, two max pools, fully connected 256 -> 10; ~0.66 M weights, about\n"
      "4x small's arithmetic) and paper (the VOLA paper's 64^3 network: three 8^3 convolutions to 8, 16,\n"
      "16 channels, dropout 0.5, one fully connected layer, softmax; ~13 M weights, slow on a CPU).\n"
      "Inputs are filled straight from the VOLA bits by a producer thread while the network trains;\n"
      "each training sample is turned by a random angle in [-max, max] about the vertical axis, and\n"
      "with --max-scale / --max-shift scaled and moved at random. The validation accuracy printed per\n"
      "epoch is of one orientation; `vola evaluate --votes 12` gives the voted figure.\n"
      "After every epoch the model (OUTPUT), a checkpoint (OUTPUT.ckpt: weights, optimizer, epoch) and\n"
      "a JSON record of the run (OUTPUT.json) are written. With --resume a run continues from the\n"
      "checkpoint and repeats exactly what an uninterrupted run would have done (same seed per epoch);\n"
      "--epochs-this-run N trains at most N epochs, for long runs done in pieces.\n"
      "Examples:\n"
      "  vola train data/clean -o small.pt --epochs 30 --max-rotation 180 --max-shift 2 --max-scale 0.1 --balanced\n"
      "  vola train data/clean -o paper.pt --arch paper --epochs 20 --epochs-this-run 1 --resume");
  cmd->add_option("train", args->train_dir, "Training folder (or a folder with train/ and val/)")->required()->check(CLI::ExistingDirectory);
  cmd->add_option("--validation", args->validation_dir, "Validation folder")->check(CLI::ExistingDirectory);
  cmd->add_option("-o,--output", args->output, "Model file to write")->capture_default_str();
  cmd->add_option("--arch", args->architecture, "small, wide or paper")->capture_default_str();
  cmd->add_option("--epochs", args->options.epochs, "Total epochs")->capture_default_str()->check(CLI::Range(1, 100000));
  cmd->add_option("--batch", args->options.batch_size, "Batch size")->capture_default_str()->check(CLI::Range(1, 4096));
  cmd->add_option("--lr", args->options.learning_rate, "Adam learning rate (a tenth of it for the last fifth of the epochs)")
      ->capture_default_str()
      ->check(positive_number());
  cmd->add_option("--weight-decay", args->options.weight_decay, "Adam weight decay")->capture_default_str()->check(non_negative_number());
  cmd->add_option("--seed", args->options.seed, "Seed of weights, shuffling, rotations, dropout")->capture_default_str();
  cmd->add_option("--max-rotation", args->options.max_rotation_degrees, "Augmentation: largest turn about z, degrees")
      ->capture_default_str()
      ->check(CLI::Range(0.0, 180.0));
  cmd->add_option("--max-scale", args->options.max_scale,
                  "Augmentation: scale uniform in [1 - S, 1 + S] about the grid's centre (0: none)")
      ->capture_default_str()
      ->check(CLI::Range(0.0, 0.5));
  cmd->add_option("--max-shift", args->options.max_shift,
                  "Augmentation: shift uniform in [-V, V] voxels of the 64^3 tree along each axis (0: none)")
      ->capture_default_str()
      ->check(CLI::Range(0.0, 16.0));
  cmd->add_option("--hollow", args->options.hollow,
                  "Augmentation: probability P that a training object is given as its surface shell only, as "
                  "a scan or a surface-voxelised mesh gives it (0: never)")
      ->capture_default_str()
      ->check(CLI::Range(0.0, 1.0));
  cmd->add_flag("--quarter-turns", args->options.quarter_turns,
                "Augmentation: turn each object by a random multiple of 90 degrees as well (for data from "
                "vola dataset --segment, aligned to the object's footprint up to a quarter turn)");
  cmd->add_option("--orientation-bins", args->options.orientation_bins,
                  "Auxiliary orientation target: turn each object by a random one of N equal steps of the "
                  "full circle as well (on top of --max-rotation) and train a second output to name the step, "
                  "as ORION (Sedaghat et al. 2017) does; the model file keeps the classifier alone (0: none)")
      ->capture_default_str()
      ->check(CLI::Range(0, 360));
  cmd->add_option("--orientation-weight", args->options.orientation_weight,
                  "The orientation output's weight in the loss (with --orientation-bins)")
      ->capture_default_str()
      ->check(non_negative_number());
  cmd->add_flag("--balanced", args->options.balanced,
                "Weigh the loss by 1/sqrt(class share) so rare classes count more");
  cmd->add_option("--threads", args->options.threads, "Threads (0: all cores)")->capture_default_str()->check(non_negative_number());
  cmd->add_option("--checkpoint", args->checkpoint, "Checkpoint file (default OUTPUT.ckpt)");
  cmd->add_option("--json", args->json, "Run record (default OUTPUT.json)");
  cmd->add_flag("--resume", args->options.resume, "Continue from the checkpoint if it exists");
  cmd->add_option("--epochs-this-run", args->options.max_epochs_this_run, "Stop after this many epochs (0: all)")
      ->capture_default_str()
      ->check(non_negative_number());
  cmd->callback([args] { run_train(*args); });
}

}  // namespace vola::cli
