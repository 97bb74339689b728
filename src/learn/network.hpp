// The torch side of vola_learn (included only by network.cpp and train.cpp, so that
// torch's slow headers stay in two translation units).
#pragma once

#include <torch/torch.h>

#include <memory>
#include <cstdint>
#include <set>
#include <string>

#include "batch_producer.hpp"
#include "vola/learn/classifier.hpp"

namespace vola::learn {

// A classification network: (N, 1, S, S, S) occupancy -> (N, 10) logits.
struct Network : torch::nn::Module {
  // forward(x) is last_layer(features(x)): `features` is what the last fully connected
  // layer reads (after its dropout), feature_size() values a sample, so that another
  // output (train.cpp's orientation head) can read them too.
  torch::Tensor forward(torch::Tensor input) { return last_layer(features(input)); }
  virtual torch::Tensor features(torch::Tensor input) = 0;
  virtual torch::Tensor last_layer(torch::Tensor features) = 0;
  virtual std::int64_t feature_size() const = 0;
  // For a network that will only infer (eval mode, weights fixed from here on): computes
  // what infer() needs. infer() is forward() up to float rounding, for InferenceMode.
  virtual void prepare_inference() {}
  virtual torch::Tensor infer(torch::Tensor input) { return forward(input); }
};

std::shared_ptr<Network> make_network(Architecture architecture);

// A model file: an archive holding "vola_model_version", "vola_architecture" and the
// network's weights under "model". A checkpoint adds "optimizer" and "epochs_done".
void write_architecture(torch::serialize::OutputArchive& archive, Architecture architecture);
Architecture read_architecture(torch::serialize::InputArchive& archive, const std::string& path);
void save_model(const Network& network, Architecture architecture, const std::string& path);
// The byte sizes of an archive's tensor records ("data/N" members), as the zip holds them.
using RecordSizes = std::multiset<std::uint64_t>;
// Loads the archive at `path`, or throws FormatError naming it; returns its tensor records' sizes.
RecordSizes load_archive(torch::serialize::InputArchive& archive, const std::string& path);
// Throws FormatError unless every tensor's storage has a record of its own of that many
// bytes. libtorch sizes a storage by what the archive's pickle says and reads the record
// into it without comparing: a record cut short (a full disk, a copy cut off) inside a
// valid zip gave tensors reaching past their memory, and the first forward pass crashed.
void check_tensor_records(const std::vector<torch::Tensor>& tensors, RecordSizes records, const std::string& path);
// Every parameter and buffer of the network.
std::vector<torch::Tensor> network_tensors(const Network& network);
// Reads weights from the "model" member into `network`; FormatError when they do not fit.
void read_weights(torch::serialize::InputArchive& archive, Network& network, const std::string& path);

// The batch as an (N, 1, S, S, S) tensor viewing batch.inputs (no copy).
torch::Tensor input_tensor(Batch& batch, int side);

// Writes the archive to `path` through vola::OutputFile: a reader (or a killed run) never
// sees half a file, and a failed write leaves the old one.
void save_archive(torch::serialize::OutputArchive& archive, const std::string& path);

}  // namespace vola::learn
