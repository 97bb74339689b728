// The architectures themselves (network.hpp, torch's side of vola_learn): output shapes,
// weight counts, a model file's round trip through save_model and Classifier, and the
// inference pass against the training-time forward pass for a freshly trained network.
#include <gtest/gtest.h>

#include <algorithm>
#include <numeric>

#include "learn_test_data.hpp"
#include "network.hpp"
#include "test_support.hpp"
#include "vola/learn/classifier.hpp"

namespace {

using namespace vola::learn;
using vola_learn_test::shape_grid;

std::int64_t weight_count(const Network& network) {
  std::int64_t count = 0;
  for (const auto& p : network.parameters()) count += p.numel();
  return count;
}

TEST(Networks, NamesRoundTrip) {
  for (const Architecture a : {Architecture::paper, Architecture::small, Architecture::wide})
    EXPECT_EQ(parse_architecture(architecture_name(a)), a);
  EXPECT_EQ(parse_architecture("huge"), std::nullopt);
  EXPECT_EQ(input_side(Architecture::small), 32);
  EXPECT_EQ(input_side(Architecture::wide), 32);
  EXPECT_EQ(input_side(Architecture::paper), 64);
  // The values are what model files record: the committed models say 1 (small).
  EXPECT_EQ(static_cast<int>(Architecture::paper), 0);
  EXPECT_EQ(static_cast<int>(Architecture::small), 1);
  EXPECT_EQ(static_cast<int>(Architecture::wide), 2);
}

// (N, 1, 32, 32, 32) -> (N, 10) for the two 32^3 networks, in training and in eval mode;
// their weight counts (the model files' sizes follow: 4 bytes a weight).
TEST(Networks, OutputShapesAndWeights) {
  torch::manual_seed(3);
  for (const Architecture a : {Architecture::small, Architecture::wide}) {
    const auto network = make_network(a);
    const int side = input_side(a);
    const torch::Tensor input = (torch::rand({3, 1, side, side, side}) < 0.2).to(torch::kFloat32);
    network->train();
    EXPECT_EQ(network->forward(input).sizes(), (std::vector<std::int64_t>{3, kClassCount})) << architecture_name(a);
    network->eval();
    torch::NoGradGuard no_grad;
    EXPECT_EQ(network->forward(input.slice(0, 0, 1)).sizes(), (std::vector<std::int64_t>{1, kClassCount}));
  }
  EXPECT_EQ(weight_count(*make_network(Architecture::small)), 917'994);
  // wide: 4032 + 55360 + 110656 + 221312 (convolutions) + 576 (batch norms' scales and
  // shifts) + 262400 + 2570 (fully connected).
  EXPECT_EQ(weight_count(*make_network(Architecture::wide)), 656'906);
}

// A wide network trained for a few steps, saved, loaded by Classifier: the file says wide,
// the loaded network gives the probabilities the saved one gives (eval mode), and the
// inference pass (batch norm folded, oneDNN) agrees with the forward pass.
TEST(Networks, WideModelSavesAndLoads) {
  vola_test::TempDir dir;
  std::vector<Sample> samples;
  for (int k = 0; k < kClassCount; ++k) samples.push_back({clean_scene(shape_grid(k, 11), 32), k});
  TrainOptions options;
  options.architecture = Architecture::wide;
  options.epochs = 16;
  options.batch_size = 10;
  options.learning_rate = 1e-3;
  options.max_rotation_degrees = 0;
  options.threads = 2;
  options.model_path = (dir / "wide.pt").string();
  std::vector<double> losses;
  TrainCallbacks callbacks;
  callbacks.on_step = [&](int, std::size_t, std::size_t, double loss) { losses.push_back(loss); };
  const auto reports = train(samples, samples, options, callbacks);
  ASSERT_EQ(losses.size(), 16u);
  const double first = (losses[0] + losses[1] + losses[2]) / 3, last = (losses[13] + losses[14] + losses[15]) / 3;
  EXPECT_LT(last, first);
  ASSERT_EQ(reports.size(), 16u);

  const Classifier classifier(options.model_path);
  EXPECT_EQ(classifier.architecture(), Architecture::wide);
  std::vector<const vola::Tree*> trees;
  for (const auto& s : samples) trees.push_back(&s.tree);
  for (const int votes : {1, 12}) {
    const auto fast = classifier.classify_votes(trees, votes);
    vola::learn::detail::reference_inference = true;
    const auto reference = classifier.classify_votes(trees, votes);
    vola::learn::detail::reference_inference = false;
    ASSERT_EQ(fast.size(), trees.size() * std::size_t(votes));
    for (std::size_t i = 0; i < fast.size(); ++i) {
      EXPECT_NEAR(std::accumulate(fast[i].begin(), fast[i].end(), 0.0), 1.0, 1e-5);
      for (int c = 0; c < kClassCount; ++c)
        EXPECT_NEAR(fast[i][std::size_t(c)], reference[i][std::size_t(c)], 2e-5) << votes << " votes, input " << i << ", class " << c;
    }
  }

  // The same weights saved again through save_model load to the same probabilities.
  const auto network = make_network(Architecture::wide);
  torch::serialize::InputArchive archive;
  load_archive(archive, options.model_path);
  EXPECT_EQ(read_architecture(archive, options.model_path), Architecture::wide);
  read_weights(archive, *network, options.model_path);
  save_model(*network, Architecture::wide, (dir / "again.pt").string());
  const Classifier again((dir / "again.pt").string());
  EXPECT_EQ(again.architecture(), Architecture::wide);
  EXPECT_EQ(again.classify(trees), classifier.classify(trees));

  // Weights of one architecture under another's record are refused.
  // small's layer names are a subset of wide's: the shapes tell them apart.
  save_model(*network, Architecture::small, (dir / "mislabelled.pt").string());
  try {
    Classifier mislabelled((dir / "mislabelled.pt").string());
    ADD_FAILURE() << "wide weights accepted as small";
  } catch (const vola::FormatError& e) {
    EXPECT_NE(std::string(e.what()).find("weights do not fit the network: conv2.weight is [64, 32, 3, 3, 3]"), std::string::npos)
        << e.what();
  }
  save_model(*make_network(Architecture::small), Architecture::wide, (dir / "mislabelled2.pt").string());
  EXPECT_THROW(Classifier((dir / "mislabelled2.pt").string()), vola::FormatError);
}

}  // namespace
