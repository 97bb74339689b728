#include "batch_producer.hpp"

#include <algorithm>
#include <numbers>
#include <random>

#include "vola/learn/occupancy.hpp"

namespace vola::learn {

BatchProducer::BatchProducer(const std::vector<Sample>& samples, std::vector<std::size_t> order,
                             std::size_t batch_size, int side, std::uint64_t seed, double max_rotation,
                             std::size_t ahead)
    : BatchProducer(samples, std::move(order), batch_size, side, seed, Augmentation{max_rotation, 0, 0}, ahead) {}

BatchProducer::BatchProducer(const std::vector<Sample>& samples, std::vector<std::size_t> order,
                             std::size_t batch_size, int side, std::uint64_t seed, const Augmentation& augmentation,
                             std::size_t ahead)
    : samples_(samples),
      order_(std::move(order)),
      batch_size_(std::max<std::size_t>(1, batch_size)),
      side_(side),
      seed_(seed),
      augmentation_(augmentation),
      ahead_(std::max<std::size_t>(1, ahead)) {
  thread_ = std::thread([this] { run(); });
}

BatchProducer::~BatchProducer() {
  {
    std::lock_guard lock(mutex_);
    stopping_ = true;
  }
  changed_.notify_all();
  thread_.join();
}

void BatchProducer::run() {
  try {
    std::mt19937_64 random(seed_);
    const Augmentation& a = augmentation_;
    std::uniform_real_distribution<double> angle(-a.max_rotation, a.max_rotation);
    std::uniform_real_distribution<double> scale(1 - a.max_scale, 1 + a.max_scale);
    std::uniform_real_distribution<double> shift(-a.max_shift, a.max_shift);
    std::bernoulli_distribution hollow(a.hollow);
    std::uniform_int_distribution<int> quarter(0, 3);
    std::uniform_int_distribution<int> step(0, std::max(1, a.orientation_bins) - 1);
    const std::size_t cells = std::size_t(side_) * side_ * side_;
    for (std::size_t first = 0; first < order_.size(); first += batch_size_) {
      const std::size_t count = std::min(batch_size_, order_.size() - first);
      Batch batch;
      batch.inputs.resize(count * cells);
      for (std::size_t k = 0; k < count; ++k) {
        const std::size_t index = order_[first + k];
        const Sample& sample = samples_[index];
        Placement placement;
        placement.angle_radians = a.max_rotation > 0 ? angle(random) : 0.0;
        // Drawn only when asked for, as hollow below.
        if (a.quarter_turns) placement.angle_radians += quarter(random) * std::numbers::pi / 2;
        if (a.orientation_bins > 0) {
          const int turn = step(random);
          placement.angle_radians += turn * 2 * std::numbers::pi / a.orientation_bins;
          batch.orientations.push_back(turn);
        }
        if (a.max_scale > 0) placement.scale = scale(random);
        if (a.max_shift > 0)
          for (double& d : placement.shift) d = shift(random);
        const std::span<float> input(batch.inputs.data() + k * cells, cells);
        fill_occupancy(sample.tree, side_, placement, input);
        // Drawn only when asked for, so that runs without it keep their random sequence.
        if (a.hollow > 0 && hollow(random)) keep_surface(input, side_);
        batch.labels.push_back(sample.label);
        batch.indices.push_back(index);
      }
      std::unique_lock lock(mutex_);
      changed_.wait(lock, [&] { return stopping_ || ready_.size() < ahead_; });
      if (stopping_) return;
      ready_.push_back(std::move(batch));
      changed_.notify_all();
    }
  } catch (...) {
    std::lock_guard lock(mutex_);
    failure_ = std::current_exception();
  }
  std::lock_guard lock(mutex_);
  done_ = true;
  changed_.notify_all();
}

std::optional<Batch> BatchProducer::next() {
  std::unique_lock lock(mutex_);
  changed_.wait(lock, [&] { return !ready_.empty() || done_; });
  if (!ready_.empty()) {
    Batch batch = std::move(ready_.front());
    ready_.pop_front();
    changed_.notify_all();
    return batch;
  }
  if (failure_) std::rethrow_exception(failure_);
  return std::nullopt;
}

}  // namespace vola::learn
