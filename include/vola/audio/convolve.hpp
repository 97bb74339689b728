// FFT convolution (FFTW): the dry signal through an FIR filter, overlap-add in blocks.
#pragma once

#include <cstddef>
#include <cstdint>
#include <memory>
#include <span>
#include <vector>

namespace vola::audio {

// How FFTW plans a transform size: estimate (instant, for a one-off convolution) or
// measure (times candidate algorithms: a second or so once per size, then faster
// transforms, for a program that convolves many times). Plans are made once per size and
// planning per process, and shared.
enum class FftPlanning : std::uint8_t { estimate, measure };

// The arithmetic of a convolution's transforms: double (errors near 1e-15 of the
// output's scale) or single precision (near 1e-7, a few steps of a 24-bit sample, and a
// third faster: what an audio engine applies sound with).
enum class SamplePrecision : std::uint8_t { float64, float32 };

// A filter ready to apply: its spectrum is made once, the FFT plans once per size.
class Convolver {
 public:
  // The transform size is chosen for signals of about `signal_size` samples (0: long
  // signals, four times the filter); apply takes a signal of any length. The transforms
  // run in `precision`; signal and output are doubles either way. Throws
  // InvalidArgument for an empty filter.
  explicit Convolver(std::span<const double> filter, FftPlanning planning = FftPlanning::estimate,
                     std::size_t signal_size = 0, SamplePrecision precision = SamplePrecision::float64);
  ~Convolver();
  Convolver(const Convolver&) = delete;
  Convolver& operator=(const Convolver&) = delete;

  // The full linear convolution (signal.size() + filter size - 1 samples; empty for an
  // empty signal) on `threads` threads (0 = vola::thread_count()). The result does not depend on the
  // thread count: blocks are added in a fixed order.
  std::vector<double> apply(std::span<const double> signal, unsigned threads = 1) const;
  // The same into `out`, which must hold signal.size() + filter size - 1 samples (a
  // program that filters block after block reuses one buffer). Throws InvalidArgument for
  // another size.
  void apply_into(std::span<const double> signal, std::span<double> out, unsigned threads = 1) const;

  std::size_t fft_size() const noexcept { return fft_size_; }
  // The transform size the constructor picks for `taps` taps and signals of about
  // `signal_size` samples.
  static std::size_t transform_size(std::size_t taps, std::size_t signal_size);

 private:
  struct Plans;
  std::size_t filter_size_;
  std::size_t fft_size_;
  std::unique_ptr<Plans> plans_;
};

// A long filter (a reverberation tail of seconds) cut into partitions of `partition`
// samples (uniformly partitioned overlap-save): every block of the signal is transformed
// once, its spectrum multiplied by each partition's and accumulated per output block, one
// inverse transform per output block. The transforms stay 2 * partition long however long
// the filter is, where Convolver's grow with it (4x the filter: 2^21 points for a 10 s
// response at 48 kHz); the result is the same linear convolution.
class PartitionedConvolver {
 public:
  // Throws InvalidArgument for an empty filter or a partition that is not a power of two >= 64.
  explicit PartitionedConvolver(std::span<const double> filter, std::size_t partition = 8192,
                                FftPlanning planning = FftPlanning::estimate);
  ~PartitionedConvolver();
  PartitionedConvolver(const PartitionedConvolver&) = delete;
  PartitionedConvolver& operator=(const PartitionedConvolver&) = delete;

  // As Convolver::apply: signal.size() + filter size - 1 samples, the same on any thread count.
  std::vector<double> apply(std::span<const double> signal, unsigned threads = 1) const;
  std::size_t partitions() const noexcept;

 private:
  struct State;
  std::unique_ptr<State> state_;
};

// The minimum-phase FIR of `taps` taps whose magnitude response is `magnitude`, sampled
// at the n/2 + 1 frequencies k * rate / n, k = 0 .. n/2 (n = 2 * (magnitude.size() - 1), a
// power of two). Minimum phase: its energy comes as early as any causal filter's can, so a
// reflection through it starts at its arrival (no pre-echo). Real cepstrum method
// (Oppenheim and Schafer); magnitudes are floored at 1e-5 (-100 dB) for the logarithm.
// Throws InvalidArgument for a bad size.
std::vector<double> minimum_phase_fir(std::span<const double> magnitude, std::size_t taps);

// Convolver(filter).apply(signal) on one thread.
std::vector<double> convolve(std::span<const double> signal, std::span<const double> filter);

}  // namespace vola::audio
