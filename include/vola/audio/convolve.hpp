// FFT convolution (FFTW): the dry signal through an FIR filter, overlap-add in blocks.
#pragma once

#include <cstddef>
#include <memory>
#include <span>
#include <vector>

namespace vola::audio {

// A filter ready to apply: its spectrum and the FFT plans are made once.
class Convolver {
 public:
  // Throws InvalidArgument for an empty filter.
  explicit Convolver(std::span<const double> filter);
  ~Convolver();
  Convolver(const Convolver&) = delete;
  Convolver& operator=(const Convolver&) = delete;

  // The full linear convolution (signal.size() + filter size - 1 samples; empty for an
  // empty signal) on `threads` threads (0 = all). The result does not depend on the
  // thread count: blocks are added in a fixed order.
  std::vector<double> apply(std::span<const double> signal, unsigned threads = 1) const;

  std::size_t fft_size() const noexcept { return fft_size_; }

 private:
  struct Plans;
  std::size_t filter_size_;
  std::size_t fft_size_;
  std::size_t block_;  // input samples per block: fft_size - filter size + 1
  std::unique_ptr<Plans> plans_;
};

// Convolver(filter).apply(signal) on one thread.
std::vector<double> convolve(std::span<const double> signal, std::span<const double> filter);

}  // namespace vola::audio
