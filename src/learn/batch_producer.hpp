// Training and evaluation batches made in a thread while the network works on the
// previous one: each batch is the samples' trees filled straight into float grids
// (fill_occupancy), turned by a random angle when augmenting.
#pragma once

#include <condition_variable>
#include <cstddef>
#include <cstdint>
#include <deque>
#include <exception>
#include <mutex>
#include <optional>
#include <thread>
#include <vector>

#include "vola/learn/classifier.hpp"

namespace vola::learn {

// Random placement of training samples (radians, fraction of size, tree voxels).
struct Augmentation {
  double max_rotation = 0;
  double max_scale = 0;
  double max_shift = 0;
  double hollow = 0;  // probability of a sample's input being its surface shell (keep_surface)
  bool quarter_turns = false;  // a random multiple of 90 degrees added to the angle
  int orientation_bins = 0;    // > 0: a random multiple of 360 / bins degrees added, and kept
};

struct Batch {
  std::vector<float> inputs;          // count * side^3
  std::vector<std::int64_t> labels;   // count
  std::vector<std::size_t> indices;   // which samples, in order
  std::vector<std::int64_t> orientations;  // count, with Augmentation::orientation_bins: the step
  std::size_t count() const noexcept { return labels.size(); }
};

class BatchProducer {
 public:
  // Batches of `batch_size` (the last may be smaller) over samples[order[...]] at input
  // grid `side`. Angles are uniform in [-max_rotation, max_rotation] radians, drawn in
  // order from a generator seeded with `seed` (0 radians when max_rotation is 0), plus
  // a random quarter turn with `quarter_turns` or a random step of the full circle with
  // `orientation_bins` (the step kept in Batch::orientations); then,
  // when augmentation asks for them, a scale uniform in [1 - max_scale, 1 + max_scale]
  // and a shift uniform in [-max_shift, max_shift] tree voxels along each axis; then, with
  // probability `hollow`, only the input's surface shell (keep_surface). At most
  // `ahead` batches wait in the queue.
  BatchProducer(const std::vector<Sample>& samples, std::vector<std::size_t> order, std::size_t batch_size, int side,
                std::uint64_t seed, double max_rotation, std::size_t ahead = 2);
  BatchProducer(const std::vector<Sample>& samples, std::vector<std::size_t> order, std::size_t batch_size, int side,
                std::uint64_t seed, const Augmentation& augmentation, std::size_t ahead = 2);
  ~BatchProducer();
  BatchProducer(const BatchProducer&) = delete;
  BatchProducer& operator=(const BatchProducer&) = delete;

  // The next batch, or nullopt after the last; rethrows what the producer threw.
  std::optional<Batch> next();

 private:
  void run();

  const std::vector<Sample>& samples_;
  std::vector<std::size_t> order_;
  std::size_t batch_size_;
  int side_;
  std::uint64_t seed_;
  Augmentation augmentation_;
  std::size_t ahead_;

  std::mutex mutex_;
  std::condition_variable changed_;
  std::deque<Batch> ready_;
  bool done_ = false;       // the producer made its last batch (or failed)
  bool stopping_ = false;   // the consumer went away
  std::exception_ptr failure_;
  std::thread thread_;
};

}  // namespace vola::learn
