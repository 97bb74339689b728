#include <chrono>
#include <cmath>
#include <filesystem>
#include <new>
#include <numbers>
#include <numeric>
#include <random>

#include "network.hpp"
#include "vola/error.hpp"

namespace vola::learn {

namespace {

// Seeds of one epoch's shuffle, rotations and dropout: a function of (seed, epoch)
// only, so that a resumed run repeats what an uninterrupted one does.
std::uint64_t epoch_seed(std::uint64_t seed, int epoch, std::uint32_t stream) {
  std::seed_seq sequence{std::uint32_t(seed), std::uint32_t(seed >> 32), std::uint32_t(epoch), stream};
  std::uint32_t words[2];
  sequence.generate(words, words + 2);
  return (std::uint64_t(words[0]) << 32) | words[1];
}

double learning_rate_at(const TrainOptions& options, int epoch) {
  // The last fifth of the epochs at a tenth of the rate.
  return epoch >= options.epochs - options.epochs / 5 ? options.learning_rate / 10 : options.learning_rate;
}

double accuracy(Network& network, const std::vector<Sample>& samples, int side, std::size_t batch_size) {
  if (samples.empty()) return -1;
  network.eval();
  torch::NoGradGuard no_grad;
  std::vector<std::size_t> order(samples.size());
  std::iota(order.begin(), order.end(), 0);
  BatchProducer producer(samples, std::move(order), batch_size, side, 0, 0.0);
  std::size_t correct = 0;
  while (auto batch = producer.next()) {
    const torch::Tensor predicted = network.forward(input_tensor(*batch, side)).argmax(1);
    const auto* p = predicted.data_ptr<std::int64_t>();
    for (std::size_t i = 0; i < batch->count(); ++i) correct += p[i] == batch->labels[i];
  }
  return double(correct) / double(samples.size());
}

// The auxiliary orientation output (TrainOptions::orientation_bins): a linear layer on
// the network's features, trained with it, kept in checkpoints but not in model files.
struct OrientationHead {
  torch::nn::Linear layer{nullptr};
  explicit operator bool() const { return !layer.is_empty(); }
};

void save_checkpoint(Network& network, const OrientationHead& head, torch::optim::Adam& optimizer,
                     Architecture architecture, int epochs_done, const std::string& path) {
  torch::serialize::OutputArchive archive, weights, optimizer_state;
  write_architecture(archive, architecture);
  network.save(weights);
  archive.write("model", weights);
  if (head) {
    torch::serialize::OutputArchive head_weights;
    head.layer->save(head_weights);
    archive.write("orientation_head", head_weights);
  }
  optimizer.save(optimizer_state);
  archive.write("optimizer", optimizer_state);
  archive.write("epochs_done", torch::tensor(static_cast<std::int64_t>(epochs_done)));
  save_archive(archive, path);
}

// Loads a checkpoint into network and optimizer; returns the epochs it had done.
int load_checkpoint(Network& network, OrientationHead& head, torch::optim::Adam& optimizer, Architecture architecture,
                    const std::string& path) {
  torch::serialize::InputArchive archive;
  const RecordSizes records = load_archive(archive, path);
  if (read_architecture(archive, path) != architecture)
    throw OptionError("architecture", path + ": checkpoint of another architecture than " +
                                          std::string(architecture_name(architecture)));
  read_weights(archive, network, path);
  try {
    torch::serialize::InputArchive optimizer_state, head_weights;
    torch::Tensor epochs_done;
    if (!archive.try_read("optimizer", optimizer_state)) throw FormatError(path, std::nullopt, "not a checkpoint: no optimizer state");
    const bool has_head = archive.try_read("orientation_head", head_weights);
    if (has_head != bool(head))
      throw OptionError(
          "orientation-bins",
          path + (has_head ? ": checkpoint trained with an orientation output; give its --orientation-bins"
                           : ": checkpoint trained without an orientation output"));
    if (head) {
      // load() takes the checkpoint's tensors whatever their shape: a head of other bins
      // would train on silently (or fail deep in libtorch).
      const std::int64_t bins = head.layer->weight.size(0);
      head.layer->load(head_weights);
      if (head.layer->weight.dim() != 2 || head.layer->weight.size(0) != bins)
        throw OptionError("orientation-bins",
                          path + ": checkpoint trained with " +
                              std::to_string(head.layer->weight.dim() == 2 ? head.layer->weight.size(0) : 0) +
                              " orientation bins, not " + std::to_string(bins) + "; give its count");
    }
    optimizer.load(optimizer_state);
    std::vector<torch::Tensor> tensors = network_tensors(network);
    if (head)
      for (const auto& t : head.layer->parameters()) tensors.push_back(t);
    for (const auto& [key, state] : optimizer.state()) {
      const auto& adam = static_cast<const torch::optim::AdamParamState&>(*state);
      for (const torch::Tensor& t : {adam.exp_avg(), adam.exp_avg_sq(), adam.max_exp_avg_sq()}) tensors.push_back(t);
    }
    check_tensor_records(tensors, records, path);
    archive.read("epochs_done", epochs_done);
    return static_cast<int>(epochs_done.item<std::int64_t>());
  } catch (const Error&) {
    throw;
  } catch (const std::bad_alloc&) {
    throw;
  } catch (const std::exception& failure) {  // c10::Error, and libtorch's std::runtime_errors
    const std::string what = failure.what();
    throw FormatError(path, std::nullopt, "damaged checkpoint: " + what.substr(0, what.find('\n')));
  }
}

}  // namespace

std::vector<EpochReport> train(const std::vector<Sample>& train_set, const std::vector<Sample>& validation_set,
                               const TrainOptions& options, const TrainCallbacks& callbacks) {
  if (train_set.empty()) throw InvalidArgument("no training samples");
  if (options.epochs < 1 || options.batch_size < 1 || !(options.learning_rate > 0))
    throw InvalidArgument("epochs, batch size and learning rate must be positive");
  for (const auto& sample : train_set)
    if (sample.label < 0 || sample.label >= kClassCount) throw InvalidArgument("training label out of 0..9");
  set_threads(options.threads);
  torch::manual_seed(options.seed);
  const int side = input_side(options.architecture);
  const std::shared_ptr<Network> network = make_network(options.architecture);
  std::vector<torch::Tensor> parameters = network->parameters();
  OrientationHead head;
  if (options.orientation_bins > 0) {
    if (options.quarter_turns)
      throw InvalidArgument("orientation bins and quarter turns both turn the samples: give one");
    if (options.architecture == Architecture::paper)
      throw InvalidArgument("the paper network has no orientation output (its last layer reads 1.3 M values)");
    if (options.orientation_bins > 360) throw InvalidArgument("orientation bins must be 1 to 360");
    head.layer = torch::nn::Linear(network->feature_size(), options.orientation_bins);
    for (const auto& p : head.layer->parameters()) parameters.push_back(p);
  }
  torch::optim::Adam optimizer(parameters,
                               torch::optim::AdamOptions(options.learning_rate).weight_decay(options.weight_decay));

  int first_epoch = 0;
  std::error_code error;
  if (options.resume && !options.checkpoint_path.empty() && std::filesystem::exists(options.checkpoint_path, error)) {
    first_epoch = load_checkpoint(*network, head, optimizer, options.architecture, options.checkpoint_path);
    if (callbacks.on_resume) callbacks.on_resume(first_epoch + 1);
  }

  std::vector<EpochReport> reports;
  Augmentation augmentation;
  augmentation.max_rotation = options.max_rotation_degrees * std::numbers::pi / 180;
  augmentation.max_scale = options.max_scale;
  augmentation.max_shift = options.max_shift;
  augmentation.hollow = options.hollow;
  augmentation.quarter_turns = options.quarter_turns;
  augmentation.orientation_bins = options.orientation_bins;
  // Class weights of the loss: 1 / sqrt(share of the class), normalised to a mean of 1
  // over the classes present, so rare classes (bathtub) count more without dominating.
  torch::Tensor class_weights;
  if (options.balanced) {
    std::vector<double> counts(kClassCount, 0);
    for (const auto& sample : train_set) ++counts[std::size_t(sample.label)];
    std::vector<float> weights(kClassCount, 0.0f);
    double total = 0;
    int present = 0;
    for (int k = 0; k < kClassCount; ++k)
      if (counts[std::size_t(k)] > 0) {
        weights[std::size_t(k)] = float(1 / std::sqrt(counts[std::size_t(k)] / double(train_set.size())));
        total += weights[std::size_t(k)];
        ++present;
      }
    for (float& w : weights) w = float(w * static_cast<float>(present) / total);
    class_weights = torch::tensor(weights);
  }
  for (int epoch = first_epoch; epoch < options.epochs; ++epoch) {
    if (options.max_epochs_this_run > 0 && epoch - first_epoch >= options.max_epochs_this_run) break;
    const auto start = std::chrono::steady_clock::now();
    EpochReport report;
    report.epoch = epoch + 1;
    report.learning_rate = learning_rate_at(options, epoch);
    for (auto& group : optimizer.param_groups())
      static_cast<torch::optim::AdamOptions&>(group.options()).lr(report.learning_rate);
    torch::manual_seed(epoch_seed(options.seed, epoch, 0));
    std::vector<std::size_t> order(train_set.size());
    std::iota(order.begin(), order.end(), 0);
    std::mt19937_64 shuffle_random(epoch_seed(options.seed, epoch, 1));
    std::shuffle(order.begin(), order.end(), shuffle_random);
    const std::size_t steps = (order.size() + std::size_t(options.batch_size) - 1) / std::size_t(options.batch_size);

    network->train();
    if (head) head.layer->train();
    BatchProducer producer(train_set, std::move(order), std::size_t(options.batch_size), side,
                           epoch_seed(options.seed, epoch, 2), augmentation);
    double loss_sum = 0;
    std::size_t seen = 0, correct = 0, step = 0;
    while (auto batch = producer.next()) {
      const torch::Tensor labels = torch::from_blob(batch->labels.data(), {static_cast<std::int64_t>(batch->count())},
                                                    torch::kInt64);
      optimizer.zero_grad();
      const torch::Tensor features = network->features(input_tensor(*batch, side));
      const torch::Tensor logits = network->last_layer(features);
      torch::Tensor loss = torch::nn::functional::cross_entropy(
          logits, labels, torch::nn::functional::CrossEntropyFuncOptions().weight(class_weights));
      if (head) {
        const torch::Tensor turns =
            torch::from_blob(batch->orientations.data(), {static_cast<std::int64_t>(batch->count())}, torch::kInt64);
        loss = loss + options.orientation_weight * torch::nn::functional::cross_entropy(head.layer(features), turns);
      }
      loss.backward();
      optimizer.step();
      const double value = loss.item<double>();
      loss_sum += value * double(batch->count());
      correct += static_cast<std::size_t>(logits.argmax(1).eq(labels).sum().item<std::int64_t>());
      seen += batch->count();
      if (callbacks.on_step) callbacks.on_step(epoch + 1, ++step, steps, value);
    }
    report.train_loss = loss_sum / double(seen);
    report.train_accuracy = double(correct) / double(seen);
    report.validation_accuracy = accuracy(*network, validation_set, side, std::size_t(options.batch_size));
    if (!options.model_path.empty()) save_model(*network, options.architecture, options.model_path);
    if (!options.checkpoint_path.empty())
      save_checkpoint(*network, head, optimizer, options.architecture, epoch + 1, options.checkpoint_path);
    report.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    reports.push_back(report);
    if (callbacks.on_epoch) callbacks.on_epoch(report);
  }
  return reports;
}

}  // namespace vola::learn
