// The networks: a few training steps lower the loss, a resumed run repeats an
// uninterrupted one, the committed small model knows training samples, bad model files
// are refused.
#include <gtest/gtest.h>

#include <zip.h>

#include <algorithm>
#include <filesystem>
#include <numeric>

#include "learn_test_data.hpp"
#include "test_support.hpp"
#include "vola/error.hpp"
#include "vola/learn/classifier.hpp"
#include "vola/learn/npz.hpp"
#include "vola/learn/occupancy.hpp"

namespace {

using namespace vola::learn;
using vola_learn_test::shape_grid;

std::vector<Sample> shape_samples(int per_class, std::uint64_t seed) {
  std::vector<Sample> samples;
  for (int k = 0; k < kClassCount; ++k)
    for (int i = 0; i < per_class; ++i) samples.push_back({clean_scene(shape_grid(k, seed + std::uint64_t(i)), 32), k});
  return samples;
}

double mean(const std::vector<double>& v, std::size_t first, std::size_t count) {
  return std::accumulate(v.begin() + long(first), v.begin() + long(first + count), 0.0) / double(count);
}

TEST(Classifier, SmallModelLossFallsInAFewSteps) {
  const auto samples = shape_samples(1, 1);
  TrainOptions options;
  options.epochs = 12;  // one batch of ten samples per epoch: twelve steps
  options.batch_size = 10;
  options.learning_rate = 3e-3;
  options.max_rotation_degrees = 0;
  options.threads = 2;
  std::vector<double> losses;
  TrainCallbacks callbacks;
  callbacks.on_step = [&](int, std::size_t, std::size_t, double loss) { losses.push_back(loss); };
  const auto reports = train(samples, samples, options, callbacks);
  ASSERT_EQ(losses.size(), 12u);
  EXPECT_LT(mean(losses, 9, 3), 0.5 * mean(losses, 0, 3)) << "first " << losses.front() << " last " << losses.back();
  ASSERT_EQ(reports.size(), 12u);
  EXPECT_GT(reports.back().validation_accuracy, 0.5);
}

TEST(Classifier, ResumedRunRepeatsTheUninterruptedOne) {
  vola_test::TempDir dir;
  const auto samples = shape_samples(1, 5);
  TrainOptions options;
  options.epochs = 3;
  options.batch_size = 5;
  options.threads = 1;  // one thread: bit-for-bit repeatable sums
  options.max_rotation_degrees = 180;  // every augmentation draws from the seeded generator
  options.max_scale = 0.1;
  options.max_shift = 2;
  options.hollow = 0.5;
  options.quarter_turns = true;
  options.balanced = true;
  options.model_path = (dir / "whole.pt").string();
  options.checkpoint_path = (dir / "whole.ckpt").string();
  const auto whole = train(samples, samples, options);

  options.model_path = (dir / "parts.pt").string();
  options.checkpoint_path = (dir / "parts.ckpt").string();
  options.resume = true;
  options.max_epochs_this_run = 2;
  int resumed_at = 0;
  TrainCallbacks callbacks;
  callbacks.on_resume = [&](int first) { resumed_at = first; };
  const auto first = train(samples, samples, options, callbacks);
  ASSERT_EQ(first.size(), 2u);
  EXPECT_EQ(resumed_at, 0);
  const auto second = train(samples, samples, options, callbacks);
  ASSERT_EQ(second.size(), 1u);
  EXPECT_EQ(resumed_at, 3);
  EXPECT_EQ(second[0].epoch, 3);
  EXPECT_DOUBLE_EQ(second[0].train_loss, whole[2].train_loss);
  EXPECT_DOUBLE_EQ(first[1].train_loss, whole[1].train_loss);
  // The two model files classify alike.
  const Classifier a((dir / "whole.pt").string()), b((dir / "parts.pt").string());
  const vola::Tree* trees[] = {&samples[3].tree};
  EXPECT_EQ(a.classify(trees), b.classify(trees));
  // A checkpoint of another architecture is refused.
  options.architecture = Architecture::paper;
  EXPECT_THROW(train(samples, samples, options), vola::InvalidArgument);
}

// The auxiliary orientation output (ORION's): trained beside the classes, kept in the
// checkpoint (a resumed run repeats the uninterrupted one), left out of the model file.
TEST(Classifier, OrientationOutputResumesAndStaysOutOfTheModel) {
  vola_test::TempDir dir;
  const auto samples = shape_samples(1, 7);
  TrainOptions options;
  options.epochs = 2;
  options.batch_size = 5;
  options.threads = 1;
  options.max_rotation_degrees = 15;
  options.orientation_bins = 4;
  options.model_path = (dir / "whole.pt").string();
  options.checkpoint_path = (dir / "whole.ckpt").string();
  const auto whole = train(samples, samples, options);
  ASSERT_EQ(whole.size(), 2u);

  options.model_path = (dir / "parts.pt").string();
  options.checkpoint_path = (dir / "parts.ckpt").string();
  options.resume = true;
  options.max_epochs_this_run = 1;
  train(samples, samples, options);
  const auto second = train(samples, samples, options);
  ASSERT_EQ(second.size(), 1u);
  EXPECT_DOUBLE_EQ(second[0].train_loss, whole[1].train_loss);
  // The model file holds the classifier alone: it loads and classifies like any other.
  const Classifier a((dir / "whole.pt").string()), b((dir / "parts.pt").string());
  const vola::Tree* trees[] = {&samples[2].tree};
  EXPECT_EQ(a.classify(trees), b.classify(trees));
  // The model file holds no orientation output (its archive's pickle names no such key),
  // the checkpoint does.
  const auto pickle_names_head = [](const std::filesystem::path& file) {
    int zip_error = 0;
    zip_t* archive = zip_open(file.string().c_str(), ZIP_RDONLY, &zip_error);
    if (!archive) throw std::runtime_error("cannot open " + file.string());
    std::string pickle;
    for (zip_int64_t i = 0; i < zip_get_num_entries(archive, 0); ++i) {
      const std::string name = zip_get_name(archive, static_cast<zip_uint64_t>(i), 0);
      if (!name.ends_with("data.pkl")) continue;
      zip_file_t* f = zip_fopen_index(archive, static_cast<zip_uint64_t>(i), 0);
      char buffer[4096];
      for (zip_int64_t n; f && (n = zip_fread(f, buffer, sizeof buffer)) > 0;) pickle.append(buffer, std::size_t(n));
      if (f) zip_fclose(f);
    }
    zip_close(archive);
    return pickle.find("orientation_head") != std::string::npos;
  };
  EXPECT_FALSE(pickle_names_head(dir / "whole.pt"));
  EXPECT_TRUE(pickle_names_head(dir / "whole.ckpt"));
  // A checkpoint with the output does not resume a run without it, nor the other way, nor
  // one of another count of bins.
  options.epochs = 3;
  options.orientation_bins = 12;
  EXPECT_THROW(train(samples, samples, options), vola::OptionError);
  options.orientation_bins = 0;
  EXPECT_THROW(train(samples, samples, options), vola::OptionError);
  // Orientation bins turn the samples themselves: not with quarter turns, not for the
  // paper network (its last layer reads 1.3 M values).
  options.resume = false;
  options.checkpoint_path.clear();
  options.model_path.clear();
  options.orientation_bins = 4;
  options.quarter_turns = true;
  EXPECT_THROW(train(samples, samples, options), vola::InvalidArgument);
  options.quarter_turns = false;
  options.architecture = Architecture::paper;
  EXPECT_THROW(train(samples, samples, options), vola::InvalidArgument);
}

TEST(Classifier, CommittedModelKnowsTrainingSamples) {
  VOLA_REQUIRE_DATA(data);
  const Classifier classifier(vola_learn_test::committed_model_path());
  EXPECT_EQ(classifier.architecture(), Architecture::small);
  const auto grids = read_labelled_grids((data / "modelnet" / "modelnet10_32_train.npz").string());
  // Five samples of each class from the training part of the balanced split (vola dataset's
  // --validation-per-class 100 --seed 1): the model was trained on exactly these.
  const Split split = balanced_split(grids.labels, 100, 1);
  std::vector<vola::Tree> trees;
  std::vector<int> labels;
  std::vector<int> taken(kClassCount, 0);
  for (std::size_t i : split.train) {
    const int label = grids.labels[i];
    if (taken[std::size_t(label)]++ >= 5) continue;
    trees.push_back(clean_scene(grids.grid(i), grids.side));
    labels.push_back(label);
  }
  ASSERT_EQ(trees.size(), 50u);
  std::vector<const vola::Tree*> pointers;
  for (const auto& tree : trees) pointers.push_back(&tree);
  const auto probabilities = classifier.classify(pointers);
  int correct = 0;
  for (std::size_t i = 0; i < trees.size(); ++i) {
    const auto& p = probabilities[i];
    EXPECT_NEAR(std::accumulate(p.begin(), p.end(), 0.0), 1.0, 1e-4);
    correct += std::max_element(p.begin(), p.end()) - p.begin() == labels[i];
  }
  EXPECT_GE(correct, 48) << "of 50 training samples";
}

TEST(Classifier, RefusesFilesThatAreNotModels) {
  vola_test::TempDir dir;
  EXPECT_THROW(Classifier((dir / "missing.pt").string()), vola::IoError);
  vola_test::write_bytes(dir / "junk.pt", std::vector<std::uint8_t>(300, 'j'));
  try {
    Classifier classifier((dir / "junk.pt").string());
    ADD_FAILURE() << "junk accepted";
  } catch (const vola::FormatError& e) {
    EXPECT_NE(std::string(e.what()).find("junk.pt"), std::string::npos) << e.what();
  }
}


// Voting over 12 orientations 30 degrees apart: an input turned by a quarter turn (a
// multiple of 30 degrees that a voxel grid can be turned by exactly) sees the same 12
// inputs in another order, so the averaged probabilities agree. One vote does not.
// The surface shell of a solid: a cube of 8 in a grid of 16 keeps 8^3 - 6^3 cells, every one
// with an empty face neighbour; a grid full to its border keeps its outer layer.
TEST(Occupancy, KeepSurfaceLeavesTheShell) {
  const int side = 16;
  std::vector<float> cells(std::size_t(side) * side * side, 0.0f);
  auto at = [&](int x, int y, int z) -> float& { return cells[(std::size_t(z) * side + std::size_t(y)) * side + std::size_t(x)]; };
  for (int z = 4; z < 12; ++z)
    for (int y = 4; y < 12; ++y)
      for (int x = 4; x < 12; ++x) at(x, y, z) = 1.0f;
  vola::learn::keep_surface(cells, side);
  EXPECT_EQ(std::count(cells.begin(), cells.end(), 1.0f), 8 * 8 * 8 - 6 * 6 * 6);
  EXPECT_EQ(at(4, 7, 7), 1.0f);
  EXPECT_EQ(at(5, 7, 7), 0.0f);
  std::vector<float> full(64, 1.0f);
  vola::learn::keep_surface(full, 4);
  EXPECT_EQ(std::count(full.begin(), full.end(), 1.0f), 64 - 8);
  EXPECT_THROW(vola::learn::keep_surface(full, 5), vola::InvalidArgument);
}

TEST(Classifier, TwelveVotesAreInvariantToQuarterTurns) {
  const Classifier classifier(vola_learn_test::committed_model_path());
  double single_vote_change = 0;
  for (int shape = 0; shape < 4; ++shape) {
    const vola::Tree tree = clean_scene(shape_grid(shape, 40 + std::uint64_t(shape)), 32);
    const vola::Tree* original[] = {&tree};
    const auto votes = classifier.classify(original, 12).front();
    const auto single = classifier.classify(original, 1).front();
    EXPECT_NEAR(std::accumulate(votes.begin(), votes.end(), 0.0), 1.0, 1e-5);
    for (int quarters = 1; quarters < 4; ++quarters) {
      const vola::Tree turned = turn_quarters(tree, quarters);
      const vola::Tree* input[] = {&turned};
      const auto turned_votes = classifier.classify(input, 12).front();
      const auto turned_single = classifier.classify(input, 1).front();
      for (int k = 0; k < kClassCount; ++k) {
        EXPECT_NEAR(turned_votes[std::size_t(k)], votes[std::size_t(k)], 1e-5)
            << "shape " << shape << ", " << quarters << " quarter turns, class " << kClassNames[std::size_t(k)];
        single_vote_change = std::max(single_vote_change, double(std::abs(turned_single[std::size_t(k)] - single[std::size_t(k)])));
      }
    }
  }
  // The check can fail: without voting, turning the input moves the probabilities.
  EXPECT_GT(single_vote_change, 1e-3);
  const vola::Tree tree = clean_scene(shape_grid(0, 1), 32);
  const vola::Tree* input[] = {&tree};
  EXPECT_THROW(classifier.classify(input, 0), vola::InvalidArgument);
}

// The inference pass (oneDNN for every layer with weights, batch norm folded, fc1 as a
// convolution) computes the training-time forward pass's function: the probabilities of
// the committed models agree within float rounding, for one object and for a batch with
// votes, and the argmax is the same.
TEST(Classifier, InferencePassEqualsTheForwardPass) {
  for (const char* file : {"modelnet10-small.pt", "modelnet10-small-room.pt", "modelnet10-small-room-segmented.pt"}) {
    const std::filesystem::path model = std::filesystem::path(vola_learn_test::committed_model_path()).parent_path() / file;
    const Classifier classifier(model.string());
    std::vector<vola::Tree> trees;
    for (int shape = 0; shape < kClassCount; ++shape) trees.push_back(clean_scene(shape_grid(shape, 70 + std::uint64_t(shape)), 32));
    std::vector<const vola::Tree*> all;
    for (const auto& t : trees) all.push_back(&t);
    for (const int votes : {1, 12})
      for (const std::size_t batch : {std::size_t(1), all.size()}) {
        const std::span<const vola::Tree* const> input(all.data(), batch);
        const auto fast = classifier.classify_votes(input, votes);
        detail::reference_inference = true;
        const auto reference = classifier.classify_votes(input, votes);
        detail::reference_inference = false;
        ASSERT_EQ(fast.size(), reference.size());
        for (std::size_t i = 0; i < fast.size(); ++i) {
          for (int k = 0; k < kClassCount; ++k)
            EXPECT_NEAR(fast[i][std::size_t(k)], reference[i][std::size_t(k)], 2e-5)
                << file << ", " << votes << " votes, batch " << batch << ", input " << i << ", class " << k;
          EXPECT_EQ(std::max_element(fast[i].begin(), fast[i].end()) - fast[i].begin(),
                    std::max_element(reference[i].begin(), reference[i].end()) - reference[i].begin());
        }
      }
  }
}

// A model file damaged in storage (truncated, or one byte changed inside a record) is
// refused with a FormatError that names it, before libtorch reads it.
TEST(Classifier, RefusesDamagedModelFiles) {
  vola_test::TempDir dir;
  const std::vector<std::uint8_t> good = vola_test::read_bytes(vola_learn_test::committed_model_path());
  ASSERT_GT(good.size(), 100000u);
  const auto refused = [&](const std::vector<std::uint8_t>& bytes, const std::string& name) {
    vola_test::write_bytes(dir / name, bytes);
    try {
      Classifier classifier((dir / name).string());
      return std::string("accepted");
    } catch (const vola::FormatError& e) {
      return std::string(e.what()).find(name) != std::string::npos ? std::string() : std::string("unnamed: ") + e.what();
    }
  };
  EXPECT_EQ(refused(std::vector<std::uint8_t>(good.begin(), good.begin() + long(good.size() / 2)), "half.pt"), "");
  std::vector<std::uint8_t> flipped = good;
  flipped[good.size() / 2] ^= 0x40;  // inside the weights' record: its CRC no longer matches
  EXPECT_EQ(refused(flipped, "flipped.pt"), "");
  // The intact copy loads (the damage, not the copying, is what is refused).
  vola_test::write_bytes(dir / "intact.pt", good);
  EXPECT_NO_THROW(Classifier((dir / "intact.pt").string()));

  // The largest tensor record cut to half its bytes inside a valid zip (fresh CRCs): libtorch
  // sized the tensor by the pickle and the first forward pass read past its memory (a crash).
  vola_test::write_bytes(dir / "short.pt", good);
  int code = 0;
  zip_t* archive = zip_open((dir / "short.pt").c_str(), 0, &code);
  ASSERT_NE(archive, nullptr) << code;
  zip_int64_t largest = -1;
  zip_uint64_t largest_size = 0;
  for (zip_int64_t i = 0; i < zip_get_num_entries(archive, 0); ++i) {
    zip_stat_t stat;
    ASSERT_EQ(zip_stat_index(archive, zip_uint64_t(i), 0, &stat), 0);
    if (std::string(stat.name).find("/data/") != std::string::npos && stat.size > largest_size)
      largest = i, largest_size = stat.size;
  }
  ASSERT_GT(largest_size, 1000000u);
  static std::vector<char> half;  // libzip reads it at zip_close
  half.assign(largest_size / 2, 0);
  zip_source_t* source = zip_source_buffer(archive, half.data(), half.size(), 0);
  ASSERT_EQ(zip_file_replace(archive, zip_uint64_t(largest), source, 0), 0) << zip_strerror(archive);
  ASSERT_EQ(zip_close(archive), 0);
  try {
    Classifier classifier((dir / "short.pt").string());
    ADD_FAILURE() << "a model with a record cut short was accepted";
  } catch (const vola::FormatError& e) {
    EXPECT_NE(std::string(e.what()).find("has no record of that size: a record was cut short"), std::string::npos)
        << e.what();
  }
}


// A copy of `model` with the 8-byte record `<root>/data/<index>` (an int64 tensor)
// replaced by `value`; libzip writes fresh CRCs, so only the content is wrong.
void rewrite_int64_record(const std::filesystem::path& model, int index, std::int64_t value) {
  int code = 0;
  zip_t* archive = zip_open(model.c_str(), 0, &code);
  ASSERT_NE(archive, nullptr) << code;
  const std::string suffix = "/data/" + std::to_string(index);
  zip_int64_t found = -1;
  for (zip_int64_t i = 0; i < zip_get_num_entries(archive, 0); ++i) {
    const std::string name = zip_get_name(archive, zip_uint64_t(i), 0);
    if (name.size() > suffix.size() && name.compare(name.size() - suffix.size(), suffix.size(), suffix) == 0 &&
        name.find('/') == name.size() - suffix.size())
      found = i;
  }
  ASSERT_GE(found, 0) << "no record " << suffix;
  static std::int64_t buffer;  // libzip reads it at zip_close
  buffer = value;
  zip_source_t* source = zip_source_buffer(archive, &buffer, sizeof buffer, 0);
  ASSERT_EQ(zip_file_replace(archive, zip_uint64_t(found), source, 0), 0) << zip_strerror(archive);
  ASSERT_EQ(zip_close(archive), 0);
}

// A well-formed archive whose records say something this build cannot use: another model
// version, or an architecture whose network the weights do not fit.
TEST(Classifier, RefusesMismatchedModelFiles) {
  vola_test::TempDir dir;
  const auto good = vola_test::read_bytes(vola_learn_test::committed_model_path());
  const auto message = [&](const std::string& name) {
    try {
      Classifier classifier((dir / name).string());
      return std::string("accepted");
    } catch (const vola::FormatError& e) {
      return std::string(e.what());
    }
  };
  // Records 0 and 1 are the version and the architecture (write_architecture's order).
  vola_test::write_bytes(dir / "version.pt", good);
  rewrite_int64_record(dir / "version.pt", 0, 2);
  EXPECT_NE(message("version.pt").find("vola model version 2"), std::string::npos) << message("version.pt");
  vola_test::write_bytes(dir / "arch.pt", good);
  rewrite_int64_record(dir / "arch.pt", 1, 0);  // says paper, holds the small network's weights
  EXPECT_NE(message("arch.pt").find("weights do not fit"), std::string::npos) << message("arch.pt");
  EXPECT_NE(message("arch.pt").find("arch.pt"), std::string::npos);
  vola_test::write_bytes(dir / "unknown.pt", good);
  rewrite_int64_record(dir / "unknown.pt", 1, 9);
  EXPECT_NE(message("unknown.pt").find("unknown network architecture 9"), std::string::npos) << message("unknown.pt");
  // The unchanged record rewritten the same way still loads: the rewriting is sound.
  vola_test::write_bytes(dir / "same.pt", good);
  rewrite_int64_record(dir / "same.pt", 1, 1);
  EXPECT_EQ(message("same.pt"), "accepted");
}

}  // namespace
