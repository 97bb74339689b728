// 3D CNN classification of VOLA occupancy (libtorch, CPU). This header is free of
// torch: the networks live in two translation units of vola_learn.
//
// Architectures:
//   paper: the VOLA paper's network on 64^3 x 1 input: conv 8^3 -> 8 channels (57^3),
//          conv 8^3 -> 16 (50^3), conv 8^3 -> 16 (43^3), ReLU after each, dropout 0.5,
//          fully connected -> 10, softmax.
//   small: VoxNet-like on 32^3 (the 64^3 tree read at half resolution): conv 5^3 stride
//          2 -> 32 (14^3), conv 3^3 -> 32 (12^3), max pool 2 (6^3), fully connected
//          -> 128 -> 10 with batch norm and dropout; about 0.9 M weights, 3.6 MB.
//   wide:  deeper, on the same 32^3 input: conv 5^3 stride 2 -> 32 (14^3), conv 3^3 -> 64
//          (12^3), conv 3^3 -> 64 (10^3), max pool 2 (5^3), conv 3^3 padded -> 128 (5^3),
//          max pool 3 stride 2 (2^3), fully connected -> 256 -> 10, batch norm after every
//          convolution, dropout; about 0.66 M weights (2.6 MB), 4x small's multiply-adds.
#pragma once

#include <array>
#include <cstdint>
#include <functional>
#include <memory>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "vola/learn/dataset.hpp"
#include "vola/tree.hpp"

namespace vola::learn {

enum class Architecture { paper, small, wide };  // the values are the model files' records
std::string_view architecture_name(Architecture architecture) noexcept;
std::optional<Architecture> parse_architecture(std::string_view name) noexcept;
// Input grid side: 64 (paper), 32 (small, wide).
int input_side(Architecture architecture) noexcept;

struct Sample {
  Tree tree;
  int label = 0;
};

// The trees of a dataset folder (DIR/<class>/*.vol, see list_dataset) with their
// labels. Throws (naming the file) when a file is unreadable or its grid is coarser
// than `min_side` (the network input; 64 for both networks' datasets).
std::vector<Sample> load_samples(const std::vector<DatasetEntry>& entries, int min_side = kSceneSide);

struct TrainOptions {
  Architecture architecture = Architecture::small;
  int epochs = 30;             // total epochs of the run, counting resumed ones
  int batch_size = 32;
  double learning_rate = 1e-3;  // Adam; divided by 10 for the last fifth of the epochs
  double weight_decay = 1e-4;
  std::uint64_t seed = 1;        // weights, shuffling, augmentation, dropout
  double max_rotation_degrees = 15;  // augmentation: uniform angle in [-max, max] about z
  double max_scale = 0;              // augmentation: scale uniform in [1 - max, 1 + max] (0: none)
  double max_shift = 0;              // augmentation: shift uniform in [-max, max] tree voxels per axis
  double hollow = 0;                 // augmentation: probability of giving a sample as its surface
                                     // shell only (what a scan or a surface-voxelised mesh gives)
  bool quarter_turns = false;        // augmentation: a random multiple of 90 degrees about z on
                                     // top of the angle (for objects aligned to their footprint's
                                     // axes up to a quarter turn, as --segment gives them)
  int orientation_bins = 0;          // > 0: each training turn gets a random step of
                                     // 360 / bins degrees on top of the angle, and a second
                                     // output, trained beside the classes, names the step (an
                                     // auxiliary orientation target, as ORION's); the model
                                     // file holds the classifier alone
  double orientation_weight = 0.5;   // that output's share of the loss
  bool balanced = false;             // loss weights 1/sqrt(class share), normalised to mean 1
  int threads = 0;                  // torch intra-op threads; 0: all cores
  std::string model_path;           // the trained weights, written after every epoch
  std::string checkpoint_path;      // weights + optimizer + epoch, after every epoch
  bool resume = false;              // continue from checkpoint_path when it exists
  int max_epochs_this_run = 0;      // stop after this many epochs (0: run to `epochs`)
};

struct EpochReport {
  int epoch = 0;  // 1-based
  double train_loss = 0;
  double train_accuracy = 0;
  double validation_accuracy = -1;  // -1 without a validation set
  double learning_rate = 0;
  double seconds = 0;
};

struct TrainCallbacks {
  std::function<void(int epoch, std::size_t step, std::size_t steps, double loss)> on_step;
  std::function<void(const EpochReport&)> on_epoch;
  std::function<void(int first_epoch)> on_resume;  // called when a checkpoint was loaded
};

// Trains and writes options.model_path (and checkpoint_path). Batches are made from
// the trees by a producer thread while the network trains on the previous batch.
// Every epoch's shuffle, rotations and dropout come from (seed, epoch), so a resumed
// run repeats the epochs an uninterrupted one would have run. Returns this run's epochs.
std::vector<EpochReport> train(const std::vector<Sample>& train_set, const std::vector<Sample>& validation_set,
                               const TrainOptions& options, const TrainCallbacks& callbacks = {});

// A trained network loaded from a model file (written by train).
class Classifier {
 public:
  // Throws FormatError naming the file when it is not a vola model.
  explicit Classifier(const std::string& model_path);
  ~Classifier();
  Classifier(Classifier&&) noexcept;
  Classifier& operator=(Classifier&&) noexcept;

  Architecture architecture() const noexcept;
  // Class probabilities (softmax) of each tree, in one batch. With votes > 1, each tree
  // is seen turned about z by 360 * k / votes degrees (k = 0..votes-1) and the votes'
  // probabilities are averaged: turning the input by a multiple of 360 / votes degrees
  // only permutes the votes (exactly so for quarter turns, see fill_occupancy).
  std::vector<std::array<float, kClassCount>> classify(std::span<const Tree* const> trees, int votes = 1) const;
  // Every vote's probabilities, tree after tree: element i * votes + k is tree i turned
  // by 360 * k / votes degrees. classify() is their mean per tree.
  std::vector<std::array<float, kClassCount>> classify_votes(std::span<const Tree* const> trees, int votes) const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

namespace detail {
// Test hook: when true, classify() runs the network's training-time forward pass (torch's
// own layer choices) instead of the inference pass, which computes the same function up
// to float rounding in oneDNN. Not thread-safe; for tests and benchmarks only.
extern bool reference_inference;
}  // namespace detail

// Torch's intra-op thread count (0: leave torch's default of all cores).
void set_threads(int threads);

// Where a committed model (by default the small clean one) is looked for, in order:
// $VOLA_MODEL (the model file itself, or a folder holding `file`; a name that is neither
// throws IoError); next to the executable's prefix, <exe dir>/../share/vola/models/
// (install) and <exe dir>/../models/, ../../models/ and ../../../models/ (a build folder
// inside the source tree: build/apps/vola/vola); the source tree the library was built
// from. Returns the first that exists, or throws IoError listing where it looked.
inline constexpr std::string_view kDefaultModelFile = "modelnet10-small.pt";
// The model for objects found in rooms (`classify --segment`): trained on what
// segment_object and normalise_object give.
inline constexpr std::string_view kSegmentedRoomModelFile = "modelnet10-small-room-segmented.pt";
// `named`: `file` was asked for by name (--model NAME): a $VOLA_MODEL that is a model file
// of another name lends its folder only, not itself.
std::string default_model_path(std::string_view file = kDefaultModelFile, bool named = false);

}  // namespace vola::learn
