#include "network.hpp"

#include <unistd.h>
#include <zip.h>

#include <algorithm>
#include <cstdlib>
#include <filesystem>
#include <new>
#include <numbers>
#include <vector>

#include "vola/error.hpp"
#include "vola/output_file.hpp"
#include "vola/learn/occupancy.hpp"

#ifndef VOLA_LEARN_SOURCE_MODELS
#define VOLA_LEARN_SOURCE_MODELS ""
#endif

namespace vola::learn {

namespace {

constexpr std::int64_t kModelVersion = 1;

struct PaperNet : Network {
  torch::nn::Conv3d conv1{torch::nn::Conv3dOptions(1, 8, 8)};
  torch::nn::Conv3d conv2{torch::nn::Conv3dOptions(8, 16, 8)};
  torch::nn::Conv3d conv3{torch::nn::Conv3dOptions(16, 16, 8)};
  torch::nn::Dropout dropout{torch::nn::DropoutOptions(0.5)};
  torch::nn::Linear fc{16 * 43 * 43 * 43, kClassCount};

  PaperNet() {
    register_module("conv1", conv1);
    register_module("conv2", conv2);
    register_module("conv3", conv3);
    register_module("dropout", dropout);
    register_module("fc", fc);
  }
  torch::Tensor features(torch::Tensor x) override {
    x = torch::relu(conv1(x));  // 57^3
    x = torch::relu(conv2(x));  // 50^3
    x = torch::relu(conv3(x));  // 43^3
    return dropout(x.flatten(1));
  }
  torch::Tensor last_layer(torch::Tensor x) override { return fc(x); }
  std::int64_t feature_size() const override { return 16 * 43 * 43 * 43; }
};

// Batch norm (eval mode) folded into the convolution before it: weights and bias of one
// convolution computing both.
void fold_norm(torch::nn::Conv3d& conv, torch::nn::BatchNorm3d& norm, torch::Tensor& weight, torch::Tensor& bias) {
  const torch::Tensor scale = norm->weight / torch::sqrt(norm->running_var + norm->options.eps());
  weight = (conv->weight * scale.view({-1, 1, 1, 1, 1})).contiguous();
  bias = ((conv->bias - norm->running_mean) * scale + norm->bias).contiguous();
}

struct SmallNet : Network {
  torch::nn::Conv3d conv1{torch::nn::Conv3dOptions(1, 32, 5).stride(2)};
  torch::nn::BatchNorm3d norm1{32};
  torch::nn::Conv3d conv2{torch::nn::Conv3dOptions(32, 32, 3)};
  torch::nn::BatchNorm3d norm2{32};
  torch::nn::Dropout dropout1{torch::nn::DropoutOptions(0.3)};
  torch::nn::Linear fc1{32 * 6 * 6 * 6, 128};
  torch::nn::Dropout dropout2{torch::nn::DropoutOptions(0.4)};
  torch::nn::Linear fc2{128, kClassCount};

  SmallNet() {
    register_module("conv1", conv1);
    register_module("norm1", norm1);
    register_module("conv2", conv2);
    register_module("norm2", norm2);
    register_module("dropout1", dropout1);
    register_module("fc1", fc1);
    register_module("dropout2", dropout2);
    register_module("fc2", fc2);
  }
  torch::Tensor features(torch::Tensor x) override {
    x = torch::leaky_relu(norm1(conv1(x)), 0.1);           // 14^3
    x = torch::max_pool3d(torch::relu(norm2(conv2(x))), 2);  // 12^3 -> 6^3
    x = torch::relu(fc1(dropout1(x.flatten(1))));
    return dropout2(x);
  }
  torch::Tensor last_layer(torch::Tensor x) override { return fc2(x); }
  std::int64_t feature_size() const override { return 128; }

  // Inference (eval mode, no autograd): the same function as forward() up to float
  // rounding, computed faster on one core (bench/learn_inference: 13 ms -> about 1.3 ms
  // for one object). Where the time went: torch sends a batch of one through conv2 as
  // im2col + sgemm (its rule prefers that for small 3^3 inputs), and fc1 through sgemm
  // too, and Debian's libtorch calls the reference BLAS for sgemm: 10 of the 13 ms. Here
  // every layer with weights runs in oneDNN whatever the batch (as conv1 and, for batches
  // of two or more, conv2 already did): batch norm folded into the convolutions' weights,
  // fc1 as a convolution whose kernel covers the whole 6^3 map (its weight rows are the
  // (channel, z, y, x) order x.flatten(1) gives), and ReLU after the max pool, which
  // commutes with it exactly, on an eighth of the values.
  void prepare_inference() override {
    torch::NoGradGuard no_grad;
    fold_norm(conv1, norm1, folded1_weight, folded1_bias);
    fold_norm(conv2, norm2, folded2_weight, folded2_bias);
    fc1_as_conv = fc1->weight.view({fc1->weight.size(0), 32, 6, 6, 6}).contiguous();
    inference_ready = at::hasMKLDNN() && at::globalContext().userEnabledMkldnn();
  }
  torch::Tensor infer(torch::Tensor x) override {
    if (!inference_ready) return forward(x);
    x = at::mkldnn_convolution(x, folded1_weight, folded1_bias, {0, 0, 0}, {2, 2, 2}, {1, 1, 1}, 1);
    torch::leaky_relu_(x, 0.1);  // 14^3
    x = at::mkldnn_convolution(x, folded2_weight, folded2_bias, {0, 0, 0}, {1, 1, 1}, {1, 1, 1}, 1);
    x = torch::max_pool3d(x, 2);  // 12^3 -> 6^3
    x.relu_();
    x = at::mkldnn_convolution(x, fc1_as_conv, fc1->bias, {0, 0, 0}, {1, 1, 1}, {1, 1, 1}, 1);
    x = x.flatten(1);
    return fc2(x.relu_());
  }
  torch::Tensor folded1_weight, folded1_bias, folded2_weight, folded2_bias, fc1_as_conv;
  bool inference_ready = false;
};

// Deeper and wider than SmallNet, still CPU-trainable (about 4x its multiply-adds, 0.66 M
// weights): conv 5^3 stride 2 -> 32 (14^3), conv 3^3 -> 64 (12^3), conv 3^3 -> 64 (10^3),
// max pool 2 (5^3), conv 3^3 padded -> 128 (5^3), max pool 3 stride 2 (2^3: overlapping
// windows that cover the whole 5^3 map), FC 1024 -> 256, FC -> 10. Batch norm after every
// convolution; dropout 0.3 before the first fully connected layer, 0.5 before the second.
struct WideNet : Network {
  torch::nn::Conv3d conv1{torch::nn::Conv3dOptions(1, 32, 5).stride(2)};
  torch::nn::BatchNorm3d norm1{32};
  torch::nn::Conv3d conv2{torch::nn::Conv3dOptions(32, 64, 3)};
  torch::nn::BatchNorm3d norm2{64};
  torch::nn::Conv3d conv3{torch::nn::Conv3dOptions(64, 64, 3)};
  torch::nn::BatchNorm3d norm3{64};
  torch::nn::Conv3d conv4{torch::nn::Conv3dOptions(64, 128, 3).padding(1)};
  torch::nn::BatchNorm3d norm4{128};
  torch::nn::Dropout dropout1{torch::nn::DropoutOptions(0.3)};
  torch::nn::Linear fc1{128 * 2 * 2 * 2, 256};
  torch::nn::Dropout dropout2{torch::nn::DropoutOptions(0.5)};
  torch::nn::Linear fc2{256, kClassCount};

  WideNet() {
    register_module("conv1", conv1);
    register_module("norm1", norm1);
    register_module("conv2", conv2);
    register_module("norm2", norm2);
    register_module("conv3", conv3);
    register_module("norm3", norm3);
    register_module("conv4", conv4);
    register_module("norm4", norm4);
    register_module("dropout1", dropout1);
    register_module("fc1", fc1);
    register_module("dropout2", dropout2);
    register_module("fc2", fc2);
  }
  torch::Tensor features(torch::Tensor x) override {
    x = torch::leaky_relu(norm1(conv1(x)), 0.1);             // 14^3
    x = torch::relu(norm2(conv2(x)));                        // 12^3
    x = torch::max_pool3d(torch::relu(norm3(conv3(x))), 2);  // 10^3 -> 5^3
    x = torch::max_pool3d(torch::relu(norm4(conv4(x))), 3, 2);  // 5^3 -> 2^3
    x = torch::relu(fc1(dropout1(x.flatten(1))));
    return dropout2(x);
  }
  torch::Tensor last_layer(torch::Tensor x) override { return fc2(x); }
  std::int64_t feature_size() const override { return 256; }

  // As SmallNet's: batch norm folded into the convolutions, every layer with weights in
  // oneDNN (fc1 as a convolution over the whole 2^3 map), ReLU after the max pools.
  void prepare_inference() override {
    torch::NoGradGuard no_grad;
    fold_norm(conv1, norm1, folded_weight[0], folded_bias[0]);
    fold_norm(conv2, norm2, folded_weight[1], folded_bias[1]);
    fold_norm(conv3, norm3, folded_weight[2], folded_bias[2]);
    fold_norm(conv4, norm4, folded_weight[3], folded_bias[3]);
    fc1_as_conv = fc1->weight.view({fc1->weight.size(0), 128, 2, 2, 2}).contiguous();
    inference_ready = at::hasMKLDNN() && at::globalContext().userEnabledMkldnn();
  }
  torch::Tensor infer(torch::Tensor x) override {
    if (!inference_ready) return forward(x);
    x = at::mkldnn_convolution(x, folded_weight[0], folded_bias[0], {0, 0, 0}, {2, 2, 2}, {1, 1, 1}, 1);
    torch::leaky_relu_(x, 0.1);  // 14^3
    x = at::mkldnn_convolution(x, folded_weight[1], folded_bias[1], {0, 0, 0}, {1, 1, 1}, {1, 1, 1}, 1);
    x.relu_();  // 12^3
    x = at::mkldnn_convolution(x, folded_weight[2], folded_bias[2], {0, 0, 0}, {1, 1, 1}, {1, 1, 1}, 1);
    x = torch::max_pool3d(x, 2);  // 10^3 -> 5^3
    x.relu_();
    x = at::mkldnn_convolution(x, folded_weight[3], folded_bias[3], {1, 1, 1}, {1, 1, 1}, {1, 1, 1}, 1);
    x = torch::max_pool3d(x, 3, 2);  // 5^3 -> 2^3
    x.relu_();
    x = at::mkldnn_convolution(x, fc1_as_conv, fc1->bias, {0, 0, 0}, {1, 1, 1}, {1, 1, 1}, 1);
    x = x.flatten(1);
    return fc2(x.relu_());
  }
  torch::Tensor folded_weight[4], folded_bias[4], fc1_as_conv;
  bool inference_ready = false;
};

// The first line of libtorch's message that says something (some begin with a newline).
std::string first_line(const std::string& text) {
  const auto begin = text.find_first_not_of(" \t\r\n");
  if (begin == std::string::npos) return "(libtorch gave no reason)";
  return text.substr(begin, text.find('\n', begin) - begin);
}

}  // namespace

std::string_view architecture_name(Architecture architecture) noexcept {
  switch (architecture) {
    case Architecture::paper: return "paper";
    case Architecture::small: return "small";
    case Architecture::wide: return "wide";
  }
  return "small";
}

std::optional<Architecture> parse_architecture(std::string_view name) noexcept {
  if (name == "paper") return Architecture::paper;
  if (name == "small") return Architecture::small;
  if (name == "wide") return Architecture::wide;
  return std::nullopt;
}

int input_side(Architecture architecture) noexcept { return architecture == Architecture::paper ? 64 : 32; }

std::shared_ptr<Network> make_network(Architecture architecture) {
  if (architecture == Architecture::paper) return std::make_shared<PaperNet>();
  if (architecture == Architecture::wide) return std::make_shared<WideNet>();
  return std::make_shared<SmallNet>();
}

void set_threads(int threads) {
  if (threads > 0) torch::set_num_threads(threads);
}

void write_architecture(torch::serialize::OutputArchive& archive, Architecture architecture) {
  archive.write("vola_model_version", torch::tensor(kModelVersion));
  archive.write("vola_architecture", torch::tensor(static_cast<std::int64_t>(architecture)));
}

Architecture read_architecture(torch::serialize::InputArchive& archive, const std::string& path) {
  try {
    torch::Tensor version, architecture;
    archive.read("vola_model_version", version);
    archive.read("vola_architecture", architecture);
    if (version.numel() != 1 || version.item<std::int64_t>() != kModelVersion)
      throw FormatError(path, std::nullopt, "vola model version " + std::to_string(version.item<std::int64_t>()) +
                                                " (this build reads " + std::to_string(kModelVersion) + ")");
    const std::int64_t value = architecture.numel() == 1 ? architecture.item<std::int64_t>() : -1;
    if (value != static_cast<std::int64_t>(Architecture::paper) && value != static_cast<std::int64_t>(Architecture::small) &&
        value != static_cast<std::int64_t>(Architecture::wide))
      throw FormatError(path, std::nullopt, "unknown network architecture " + std::to_string(value));
    return static_cast<Architecture>(value);
  } catch (const Error&) {
    throw;
  } catch (const std::bad_alloc&) {
    throw;
  } catch (const std::exception& error) {  // c10::Error, and libtorch's std::runtime_errors
    throw FormatError(path, std::nullopt, "not a vola model (no architecture record): " + first_line(error.what()));
  }
}

// libtorch (1.13) reads a model's zip without checking its records' CRC-32s or that the
// local headers agree with the central directory, then compiles the TorchScript and
// unpickles what the records hold; on damaged records it has freed invalid pointers
// (docs/SECURITY.md). So the archive is checked first with libzip: consistent headers,
// every record read through to the end (libzip compares its CRC there), no record
// stating more bytes than the file holds. A damaged model is then a FormatError before
// libtorch sees it; a deliberately crafted one (valid CRCs) still reaches libtorch.
RecordSizes check_model_archive(const std::string& path) {
  std::error_code error;
  const std::uint64_t file_bytes = std::filesystem::file_size(path, error);
  if (error) throw IoError("cannot open model " + path + ": " + error.message());
  int code = 0;
  std::unique_ptr<zip_t, void (*)(zip_t*)> archive(zip_open(path.c_str(), ZIP_RDONLY | ZIP_CHECKCONS, &code),
                                                   [](zip_t* z) { zip_discard(z); });
  if (!archive) {
    zip_error_t reason;
    zip_error_init_with_code(&reason, code);
    const std::string message = zip_error_strerror(&reason);
    zip_error_fini(&reason);
    throw FormatError(path, std::nullopt, "not a torch model archive (zip): " + message);
  }
  const zip_int64_t count = zip_get_num_entries(archive.get(), 0);
  std::vector<char> sink(64 * 1024);
  RecordSizes tensor_records;
  for (zip_int64_t i = 0; i < count; ++i) {
    zip_stat_t stat;
    zip_stat_init(&stat);
    if (zip_stat_index(archive.get(), static_cast<zip_uint64_t>(i), 0, &stat) != 0)
      throw FormatError(path, std::nullopt, "zip record " + std::to_string(i) + ": " + zip_strerror(archive.get()));
    const std::string name = stat.valid & ZIP_STAT_NAME ? stat.name : "record " + std::to_string(i);
    if ((stat.valid & ZIP_STAT_COMP_SIZE) && stat.comp_size > file_bytes)
      throw FormatError(path, std::nullopt, name + ": states " + std::to_string(stat.comp_size) +
                                                " stored bytes, more than the file's " + std::to_string(file_bytes));
    std::unique_ptr<zip_file_t, int (*)(zip_file_t*)> member(zip_fopen_index(archive.get(), static_cast<zip_uint64_t>(i), 0),
                                                             zip_fclose);
    if (!member) throw FormatError(path, std::nullopt, name + ": " + zip_strerror(archive.get()));
    zip_int64_t got = 0;
    std::uint64_t bytes = 0;
    while ((got = zip_fread(member.get(), sink.data(), sink.size())) > 0) bytes += static_cast<std::uint64_t>(got);
    if (got < 0) throw FormatError(path, std::nullopt, name + ": " + zip_file_strerror(member.get()));
    // libtorch names a tensor's storage "<archive>/data/<key>".
    const auto data = name.rfind("/data/");
    if (data != std::string::npos && name.find('/', data + 6) == std::string::npos) tensor_records.insert(bytes);
  }
  return tensor_records;
}

void check_tensor_records(const std::vector<torch::Tensor>& tensors, RecordSizes records, const std::string& path) {
  std::set<const void*> seen;  // tensors may share a storage, which then has one record
  for (const torch::Tensor& t : tensors) {
    if (!t.defined() || !seen.insert(t.storage().unsafeGetStorageImpl()).second) continue;
    const std::uint64_t bytes = t.storage().nbytes();
    if (bytes == 0) continue;
    const auto record = records.find(bytes);
    if (record == records.end())
      throw FormatError(path, std::nullopt,
                        "a tensor of " + std::to_string(bytes) + " bytes (" + c10::str(t.sizes(), " ", t.scalar_type()) +
                            ") has no record of that size: a record was cut short or damaged");
    records.erase(record);
  }
}

RecordSizes load_archive(torch::serialize::InputArchive& archive, const std::string& path) {
  std::error_code error;
  if (std::filesystem::is_directory(path, error))
    throw IoError("cannot open model " + path + ": a folder, not a model file (vola train writes one, e.g. model.pt)");
  if (!std::filesystem::is_regular_file(path, error)) throw IoError("cannot open model " + path + ": no such file");
  RecordSizes records = check_model_archive(path);
  try {
    archive.load_from(path);
  } catch (const std::bad_alloc&) {
    throw;
  } catch (const std::exception& failure) {
    // c10::Error, and what libtorch's TorchScript and pickle readers throw as plain
    // std::runtime_error ("expected a valid token but found ''").
    throw FormatError(path, std::nullopt, "not a torch archive: " + first_line(failure.what()));
  }
  return records;
}

std::vector<torch::Tensor> network_tensors(const Network& network) {
  std::vector<torch::Tensor> out;
  for (const auto& item : network.named_parameters()) out.push_back(item.value());
  for (const auto& item : network.named_buffers()) out.push_back(item.value());
  return out;
}

void read_weights(torch::serialize::InputArchive& archive, Network& network, const std::string& path) {
  try {
    torch::serialize::InputArchive weights;
    if (!archive.try_read("model", weights)) throw FormatError(path, std::nullopt, "no network weights ('model')");
    // libtorch replaces each tensor by the one it reads, whatever its shape: weights of a
    // network whose layers share names with this one (small's are a subset of wide's)
    // would load and fail later. So every shape and type is compared with the network's.
    std::vector<std::pair<std::string, torch::Tensor>> expected;
    for (const auto& item : network.named_parameters()) expected.emplace_back(item.key(), item.value().detach().clone());
    for (const auto& item : network.named_buffers()) expected.emplace_back(item.key(), item.value().detach().clone());
    network.load(weights);
    const auto parameters = network.named_parameters();
    const auto buffers = network.named_buffers();
    for (const auto& [name, before] : expected) {
      const torch::Tensor* now = parameters.find(name);
      if (!now) now = buffers.find(name);
      if (!now || now->sizes() != before.sizes() || now->scalar_type() != before.scalar_type())
        throw FormatError(path, std::nullopt,
                          "weights do not fit the network: " + name + " is " +
                              (now ? c10::str(now->sizes(), " ", now->scalar_type()) : std::string("missing")) +
                              ", the network's is " + c10::str(before.sizes(), " ", before.scalar_type()));
    }
  } catch (const Error&) {
    throw;
  } catch (const std::bad_alloc&) {
    throw;
  } catch (const std::exception& failure) {  // c10::Error, and libtorch's std::runtime_errors
    throw FormatError(path, std::nullopt, "weights do not fit the network: " + first_line(failure.what()));
  }
}

void save_archive(torch::serialize::OutputArchive& archive, const std::string& path) {
  OutputFile out(path);
  archive.save_to([&](const void* data, std::size_t size) {
    out.write(data, size);
    return size;
  });
  out.commit();
}

void save_model(const Network& network, Architecture architecture, const std::string& path) {
  torch::serialize::OutputArchive archive, weights;
  write_architecture(archive, architecture);
  network.save(weights);
  archive.write("model", weights);
  save_archive(archive, path);
}

torch::Tensor input_tensor(Batch& batch, int side) {
  return torch::from_blob(batch.inputs.data(), {static_cast<std::int64_t>(batch.count()), 1, side, side, side},
                          torch::kFloat32);
}

struct Classifier::Impl {
  Architecture architecture = Architecture::small;
  std::shared_ptr<Network> network;
};

Classifier::Classifier(const std::string& model_path) : impl_(std::make_unique<Impl>()) {
  torch::serialize::InputArchive archive;
  const RecordSizes records = load_archive(archive, model_path);
  impl_->architecture = read_architecture(archive, model_path);
  impl_->network = make_network(impl_->architecture);
  read_weights(archive, *impl_->network, model_path);
  check_tensor_records(network_tensors(*impl_->network), records, model_path);
  impl_->network->eval();
  impl_->network->prepare_inference();
}

Classifier::~Classifier() = default;
Classifier::Classifier(Classifier&&) noexcept = default;
Classifier& Classifier::operator=(Classifier&&) noexcept = default;

Architecture Classifier::architecture() const noexcept { return impl_->architecture; }

namespace detail {
bool reference_inference = false;
}

namespace {
// Measured on one core (bench/learn_inference, CPU ms per object with 12 votes, batch 1 /
// 32): slices of 3: 11.5 / 12.3, 4: 11.2 / 12.0, 6: 10.9 / 11.5, 8: 10.8-14.5 / 11.3-16.5,
// 12: 14.5-15.3 / 15-17, none: 10.8 / 18.5-19.
constexpr std::int64_t kInferenceSlice = 6;
}

std::vector<std::array<float, kClassCount>> Classifier::classify_votes(std::span<const Tree* const> trees, int votes) const {
  if (votes < 1) throw InvalidArgument("votes must be at least 1, got " + std::to_string(votes));
  std::vector<std::array<float, kClassCount>> result;
  if (trees.empty()) return result;
  const int side = input_side(impl_->architecture);
  const std::size_t cells = std::size_t(side) * side * side;
  // The inputs are filled a group of trees at a time, about kInputBytes of them (at least
  // one tree's votes): a batch of 4096 objects with 360 votes would otherwise take 190 GB
  // at once. Each input's result does not depend on its neighbours, so groups change nothing.
  constexpr std::size_t kInputBytes = std::size_t{64} << 20;
  const std::size_t per_group = std::max<std::size_t>(1, kInputBytes / (cells * sizeof(float) * std::size_t(votes)));
  result.reserve(trees.size() * std::size_t(votes));
  Batch batch;
  for (std::size_t first = 0; first < trees.size(); first += per_group) {
    const std::size_t count = std::min(per_group, trees.size() - first);
    const std::size_t n = count * std::size_t(votes);
    batch.inputs.assign(n * cells, 0.0f);
    batch.labels.assign(n, 0);
    for (std::size_t i = 0; i < count; ++i)
      for (int k = 0; k < votes; ++k) {
        const double angle = 2 * std::numbers::pi * k / votes;
        fill_occupancy(
            *trees[first + i], side, angle,
            std::span<float>(batch.inputs.data() + (i * std::size_t(votes) + std::size_t(k)) * cells, cells));
      }
    torch::Tensor logits;
    if (detail::reference_inference) {
      torch::NoGradGuard no_grad;
      logits = impl_->network->forward(input_tensor(batch, side));
    } else {
      c10::InferenceMode inference;  // no autograd records, no version counters
      // In slices of at most kInferenceSlice inputs: a slice's layers stay in the caches
      // (6 inputs' first layer output is 2 MB, 384's 135 MB), so large batches are no slower
      // per input than small ones.
      const torch::Tensor all = input_tensor(batch, side);
      std::vector<torch::Tensor> parts;
      for (std::int64_t at = 0; at < all.size(0); at += kInferenceSlice)
        parts.push_back(impl_->network->infer(all.slice(0, at, std::min(all.size(0), at + kInferenceSlice))));
      logits = parts.size() == 1 ? parts.front() : torch::cat(parts, 0);
    }
    const torch::Tensor probabilities = torch::softmax(logits, 1).contiguous();
    const float* p = probabilities.data_ptr<float>();
    for (std::size_t j = 0; j < n; ++j) {
      std::array<float, kClassCount>& row = result.emplace_back();
      for (std::size_t c = 0; c < std::size_t(kClassCount); ++c) row[c] = p[j * kClassCount + c];
    }
  }
  return result;
}

std::vector<std::array<float, kClassCount>> Classifier::classify(std::span<const Tree* const> trees, int votes) const {
  const auto each = classify_votes(trees, votes);
  std::vector<std::array<float, kClassCount>> result(trees.size());
  for (std::size_t i = 0; i < trees.size(); ++i)
    for (int c = 0; c < kClassCount; ++c) {
      // Summed in double over the votes in order: a permutation of the votes changes the
      // result only by float rounding of each vote (well below 1e-6).
      double sum = 0;
      for (int k = 0; k < votes; ++k) sum += each[i * std::size_t(votes) + std::size_t(k)][std::size_t(c)];
      result[i][std::size_t(c)] = static_cast<float>(sum / votes);
    }
  return result;
}

std::string default_model_path(std::string_view file, bool named) {
  namespace fs = std::filesystem;
  std::vector<fs::path> candidates;
  std::error_code error;
  // $VOLA_MODEL names the model itself, or a folder holding the committed ones; a name
  // that is neither is an error, not a reason to fall back on another model unseen.
  if (const char* env = std::getenv("VOLA_MODEL"); env && *env) {
    if (fs::is_directory(env, error))
      candidates.push_back(fs::path(env) / file);
    else if (fs::is_regular_file(env, error) && named && fs::path(env).filename() != file)
      candidates.push_back(fs::path(env).parent_path() / file);
    else if (fs::is_regular_file(env, error))
      return fs::path(env).lexically_normal().string();
    else
      throw IoError(std::string("VOLA_MODEL=") + env + ": no such model file or folder");
  }
  const fs::path exe = fs::read_symlink("/proc/self/exe", error);
  if (!error) {
    const fs::path dir = exe.parent_path();
    candidates.push_back(dir / ".." / "share" / "vola" / "models" / file);
    candidates.push_back(dir / ".." / "models" / file);
    candidates.push_back(dir / ".." / ".." / "models" / file);
    candidates.push_back(dir / ".." / ".." / ".." / "models" / file);  // build/apps/vola/vola
  }
  if (*VOLA_LEARN_SOURCE_MODELS) candidates.push_back(fs::path(VOLA_LEARN_SOURCE_MODELS) / file);
  std::string looked;
  for (const auto& candidate : candidates) {
    if (fs::is_regular_file(candidate, error)) return candidate.lexically_normal().string();
    looked += "\n  " + candidate.lexically_normal().string();
  }
  throw IoError("no model given and the default " + std::string(file) +
                " is in none of:" + looked);
}

}  // namespace vola::learn
