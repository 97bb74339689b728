#include "batch_producer.hpp"

#include <algorithm>
#include <random>

#include "vola/learn/occupancy.hpp"

namespace vola::learn {

BatchProducer::BatchProducer(const std::vector<Sample>& samples, std::vector<std::size_t> order,
                             std::size_t batch_size, int side, std::uint64_t seed, double max_rotation,
                             std::size_t ahead)
    : samples_(samples),
      order_(std::move(order)),
      batch_size_(std::max<std::size_t>(1, batch_size)),
      side_(side),
      seed_(seed),
      max_rotation_(max_rotation),
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
    std::uniform_real_distribution<double> angle(-max_rotation_, max_rotation_);
    const std::size_t cells = std::size_t(side_) * side_ * side_;
    for (std::size_t first = 0; first < order_.size(); first += batch_size_) {
      const std::size_t count = std::min(batch_size_, order_.size() - first);
      Batch batch;
      batch.inputs.resize(count * cells);
      for (std::size_t k = 0; k < count; ++k) {
        const std::size_t index = order_[first + k];
        const Sample& sample = samples_[index];
        const double turn = max_rotation_ > 0 ? angle(random) : 0.0;
        fill_occupancy(sample.tree, side_, turn, std::span<float>(batch.inputs.data() + k * cells, cells));
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
