#include "vola/audio/convolve.hpp"

#include <fftw3.h>

#include <algorithm>
#include <cmath>
#include <numbers>
#include <complex>
#include <limits>
#include <mutex>
#include <string>

#include "vola/error.hpp"
#include "vola/parallel.hpp"

namespace vola::audio {

namespace {

// FFTW's planner is not thread-safe; executing plans on new arrays is.
std::mutex& planner_mutex() {
  static std::mutex m;
  return m;
}

// FFTW's double and single precision interfaces under one name.
template <typename Real>
struct Fftw;
template <>
struct Fftw<double> {
  using Complex = fftw_complex;
  using Plan = fftw_plan;
  static double* alloc_real(std::size_t n) { return fftw_alloc_real(n); }
  static Complex* alloc_complex(std::size_t n) { return fftw_alloc_complex(n); }
  static void free(void* p) { fftw_free(p); }
  static Plan plan_r2c(int n, double* in, Complex* out, unsigned flags) { return fftw_plan_dft_r2c_1d(n, in, out, flags); }
  static Plan plan_c2r(int n, Complex* in, double* out, unsigned flags) { return fftw_plan_dft_c2r_1d(n, in, out, flags); }
  static void r2c(Plan p, double* in, Complex* out) { fftw_execute_dft_r2c(p, in, out); }
  static void c2r(Plan p, Complex* in, double* out) { fftw_execute_dft_c2r(p, in, out); }
};
template <>
struct Fftw<float> {
  using Complex = fftwf_complex;
  using Plan = fftwf_plan;
  static float* alloc_real(std::size_t n) { return fftwf_alloc_real(n); }
  static Complex* alloc_complex(std::size_t n) { return fftwf_alloc_complex(n); }
  static void free(void* p) { fftwf_free(p); }
  static Plan plan_r2c(int n, float* in, Complex* out, unsigned flags) { return fftwf_plan_dft_r2c_1d(n, in, out, flags); }
  static Plan plan_c2r(int n, Complex* in, float* out, unsigned flags) { return fftwf_plan_dft_c2r_1d(n, in, out, flags); }
  static void r2c(Plan p, float* in, Complex* out) { fftwf_execute_dft_r2c(p, in, out); }
  static void c2r(Plan p, Complex* in, float* out) { fftwf_execute_dft_c2r(p, in, out); }
};

template <typename Real>
struct FftwFree {
  void operator()(void* p) const noexcept { Fftw<Real>::free(p); }
};
template <typename Real>
using RealBufferOf = std::unique_ptr<Real[], FftwFree<Real>>;
template <typename Real>
using ComplexBufferOf = std::unique_ptr<typename Fftw<Real>::Complex[], FftwFree<Real>>;

template <typename Real>
RealBufferOf<Real> real_buffer_of(std::size_t n) {
  auto* p = Fftw<Real>::alloc_real(n);
  if (!p) throw std::bad_alloc();
  return RealBufferOf<Real>(p);
}
template <typename Real>
ComplexBufferOf<Real> complex_buffer_of(std::size_t n) {
  auto* p = Fftw<Real>::alloc_complex(n);
  if (!p) throw std::bad_alloc();
  return ComplexBufferOf<Real>(p);
}

using RealBuffer = RealBufferOf<double>;
using ComplexBuffer = ComplexBufferOf<double>;
RealBuffer real_buffer(std::size_t n) { return real_buffer_of<double>(n); }
ComplexBuffer complex_buffer(std::size_t n) { return complex_buffer_of<double>(n); }

// Plans for one transform size, made once per process, precision and size (under the
// planner mutex) and kept: planning, above all with FFTW_MEASURE, costs far more than one
// execution.
template <typename Real>
struct SizePlansOf {
  typename Fftw<Real>::Plan forward = nullptr;
  typename Fftw<Real>::Plan inverse = nullptr;
};
using SizePlans = SizePlansOf<double>;

template <typename Real>
SizePlansOf<Real> plans_of(std::size_t n, FftPlanning planning) {
  static std::vector<std::pair<std::pair<std::size_t, FftPlanning>, SizePlansOf<Real>>> cache;
  std::lock_guard lock(planner_mutex());
  for (const auto& [key, plans] : cache)
    if (key == std::pair{n, planning}) return plans;
  // Scratch arrays from fftw_malloc: plans then run on any fftw_malloc'ed arrays (same
  // alignment) through the new-array execute functions.
  RealBufferOf<Real> time = real_buffer_of<Real>(n);
  ComplexBufferOf<Real> spectrum = complex_buffer_of<Real>(n / 2 + 1);
  const unsigned flags = planning == FftPlanning::measure ? FFTW_MEASURE : FFTW_ESTIMATE;
  SizePlansOf<Real> p;
  p.forward = Fftw<Real>::plan_r2c(static_cast<int>(n), time.get(), spectrum.get(), flags);
  p.inverse = Fftw<Real>::plan_c2r(static_cast<int>(n), spectrum.get(), time.get(), flags);
  if (!p.forward || !p.inverse) throw Error("convolution: FFTW could not plan a transform");
  cache.emplace_back(std::pair{n, planning}, p);
  return p;
}
SizePlans plans_for(std::size_t n, FftPlanning planning) { return plans_of<double>(n, planning); }

// The transform size for a filter of `taps` taps and signals of about `signal` samples.
// For long signals (0), the power of two at least four times the filter: the FFT work per
// output sample is then near its minimum. For a known signal, the size from the filter's
// length up that minimises blocks * n log n: a 1 s signal through a 0.86 s response takes
// two blocks of 65,536 points instead of one of 262,144, of which most would be padding.
std::size_t best_transform_size(std::size_t taps, std::size_t signal) {
  std::size_t longest = 4096;
  while (longest < 4 * taps) longest *= 2;
  if (signal == 0) return longest;
  std::size_t best = longest;
  double best_cost = std::numeric_limits<double>::infinity();
  for (std::size_t n = 4096; n <= longest; n *= 2) {
    if (n < taps) continue;
    const std::size_t block = n - taps + 1;
    const double blocks = static_cast<double>((signal + block - 1) / block);
    const double cost = blocks * static_cast<double>(n) * std::log2(static_cast<double>(n));
    if (cost < best_cost) {
      best_cost = cost;
      best = n;
    }
  }
  return best;
}

// Convolver's work in one precision: the filter's spectrum and the overlap-add.
class BlockEngine {
 public:
  virtual ~BlockEngine() = default;
  virtual void apply_into(std::span<const double> signal, std::span<double> out, unsigned threads) = 0;
};

template <typename Real>
class Engine final : public BlockEngine {
 public:
  Engine(std::span<const double> filter, std::size_t n, FftPlanning planning)
      : n_(n), block_(n - filter.size() + 1), plans_(plans_of<Real>(n, planning)),
        filter_spectrum_(complex_buffer_of<Real>(n / 2 + 1)) {
    RealBufferOf<Real> time = real_buffer_of<Real>(n);
    // The inverse transform's 1 / n is folded into the filter, once.
    const double scale = 1.0 / static_cast<double>(n);
    std::fill(time.get(), time.get() + n, Real{0});
    std::transform(filter.begin(), filter.end(), time.get(), [scale](double v) { return static_cast<Real>(v * scale); });
    Fftw<Real>::r2c(plans_.forward, time.get(), filter_spectrum_.get());
  }

  void apply_into(std::span<const double> signal, std::span<double> out, unsigned threads) override {
    const std::size_t blocks = (signal.size() + block_ - 1) / block_;
    const std::size_t bins = n_ / 2 + 1;
    ParallelOptions parallel;
    parallel.threads = static_cast<unsigned>(std::min<std::size_t>(resolve_thread_count(threads), blocks));
    parallel.name = "audio.convolve";
    // Blocks are filtered in rounds of one per thread, each into its own buffer, then added
    // to the output in block order: every sample gets its contributions in the same order
    // whatever the thread count, and however far a block's tail reaches.
    const std::size_t round = parallel.threads;
    std::vector<Scratch> scratch = take(round);
    struct GiveBack {
      Engine& engine;
      std::vector<Scratch>& buffers;
      ~GiveBack() { engine.give_back(buffers); }
    } give_back{*this, scratch};
    std::size_t written = 0;  // out[0, written) holds the blocks added so far
    for (std::size_t first = 0; first < blocks; first += round) {
      const std::size_t count = std::min(round, blocks - first);
      parallel_for(count, [&](const Chunk& chunk) {
        for (std::size_t i = chunk.begin; i < chunk.end; ++i) {
          Real* time = scratch[i].time.get();
          auto* spectrum = scratch[i].spectrum.get();
          const std::size_t begin = (first + i) * block_;
          const std::size_t n = std::min(block_, signal.size() - begin);
          std::copy_n(signal.data() + begin, n, time);
          std::fill(time + n, time + n_, Real{0});
          Fftw<Real>::r2c(plans_.forward, time, spectrum);
          const auto* h = filter_spectrum_.get();
          for (std::size_t k = 0; k < bins; ++k) {  // written out: std::complex's * checks for NaN
            const Real re = spectrum[k][0] * h[k][0] - spectrum[k][1] * h[k][1];
            const Real im = spectrum[k][0] * h[k][1] + spectrum[k][1] * h[k][0];
            spectrum[k][0] = re;
            spectrum[k][1] = im;
          }
          Fftw<Real>::c2r(plans_.inverse, spectrum, time);
        }
      }, parallel);
      for (std::size_t i = 0; i < count; ++i) {
        const std::size_t begin = (first + i) * block_;
        const std::size_t end = begin + std::min(n_, out.size() - begin);
        const Real* time = scratch[i].time.get();  // time[k] adds to out[begin + k]
        // Blocks tile the output without gaps (a block reaches the next one's start):
        // added where earlier blocks wrote, copied beyond, so the output is never zeroed.
        const std::size_t overlap = std::min(end, written) - begin;
        double* o = out.data() + begin;
        for (std::size_t k = 0; k < overlap; ++k) o[k] += time[k];
        std::copy(time + overlap, time + (end - begin), o + overlap);
        written = std::max(written, end);
      }
    }
  }

 private:
  // A block's transform buffers. Kept between calls (taken and given back under a lock,
  // so concurrent calls are safe): fresh megabyte buffers would cost their page faults on
  // every call, a quarter of a 65,536-point call's time.
  struct Scratch {
    RealBufferOf<Real> time;
    ComplexBufferOf<Real> spectrum;
  };
  std::vector<Scratch> take(std::size_t count) {
    std::vector<Scratch> taken;
    {
      const std::lock_guard lock(scratch_mutex_);
      while (taken.size() < count && !scratch_.empty()) {
        taken.push_back(std::move(scratch_.back()));
        scratch_.pop_back();
      }
    }
    while (taken.size() < count) taken.push_back({real_buffer_of<Real>(n_), complex_buffer_of<Real>(n_ / 2 + 1)});
    return taken;
  }
  void give_back(std::vector<Scratch>& buffers) {
    const std::lock_guard lock(scratch_mutex_);
    for (Scratch& b : buffers) scratch_.push_back(std::move(b));
  }

  std::size_t n_, block_;  // transform size; input samples per block
  SizePlansOf<Real> plans_;
  ComplexBufferOf<Real> filter_spectrum_;
  std::mutex scratch_mutex_;
  std::vector<Scratch> scratch_;
};

}  // namespace

struct Convolver::Plans {
  std::unique_ptr<BlockEngine> engine;
};

Convolver::Convolver(std::span<const double> filter, FftPlanning planning, std::size_t signal_size,
                     SamplePrecision precision)
    : filter_size_(filter.size()), plans_(std::make_unique<Plans>()) {
  if (filter.empty()) throw InvalidArgument("convolution: the filter is empty");
  fft_size_ = best_transform_size(filter.size(), signal_size);
  if (precision == SamplePrecision::float32)
    plans_->engine = std::make_unique<Engine<float>>(filter, fft_size_, planning);
  else
    plans_->engine = std::make_unique<Engine<double>>(filter, fft_size_, planning);
}

Convolver::~Convolver() = default;

std::size_t Convolver::transform_size(std::size_t taps, std::size_t signal_size) {
  return best_transform_size(taps, signal_size);
}

std::vector<double> Convolver::apply(std::span<const double> signal, unsigned threads) const {
  if (signal.empty()) return {};
  std::vector<double> out(signal.size() + filter_size_ - 1);
  apply_into(signal, out, threads);
  return out;
}

void Convolver::apply_into(std::span<const double> signal, std::span<double> out, unsigned threads) const {
  if (out.size() != (signal.empty() ? 0 : signal.size() + filter_size_ - 1))
    throw InvalidArgument("convolution: the output holds " + std::to_string(out.size()) + " samples, not the " +
                          std::to_string(signal.empty() ? 0 : signal.size() + filter_size_ - 1) + " of the result");
  if (signal.empty()) return;
  plans_->engine->apply_into(signal, out, threads);
}

struct PartitionedConvolver::State {
  std::size_t filter_size = 0, block = 0, fft = 0;
  SizePlans plans;
  std::vector<ComplexBuffer> partitions;  // spectra of the filter's partitions
};

PartitionedConvolver::PartitionedConvolver(std::span<const double> filter, std::size_t partition, FftPlanning planning)
    : state_(std::make_unique<State>()) {
  if (filter.empty()) throw InvalidArgument("convolution: the filter is empty");
  if (partition < 64 || (partition & (partition - 1)) != 0 || partition > (std::size_t{1} << 24))
    throw InvalidArgument("convolution: the partition must be a power of two from 64 to 2^24");
  State& st = *state_;
  st.filter_size = filter.size();
  st.block = partition;
  st.fft = 2 * partition;
  st.plans = plans_for(st.fft, planning);
  RealBuffer time = real_buffer(st.fft);
  for (std::size_t begin = 0; begin < filter.size(); begin += st.block) {
    const std::size_t n = std::min(st.block, filter.size() - begin);
    std::fill(time.get(), time.get() + st.fft, 0.0);
    std::copy_n(filter.data() + begin, n, time.get());
    st.partitions.push_back(complex_buffer(st.fft / 2 + 1));
    fftw_execute_dft_r2c(st.plans.forward, time.get(), st.partitions.back().get());
  }
}

PartitionedConvolver::~PartitionedConvolver() = default;

std::size_t PartitionedConvolver::partitions() const noexcept { return state_->partitions.size(); }

std::vector<double> PartitionedConvolver::apply(std::span<const double> signal, unsigned threads) const {
  if (signal.empty()) return {};
  const State& st = *state_;
  const std::size_t B = st.block, bins = st.fft / 2 + 1;
  std::vector<double> out(signal.size() + st.filter_size - 1, 0.0);
  // Windows holding signal samples: block i's window starts at (i - 1) B, so the last
  // partial block is also in the first half of one more window.
  const std::size_t inputs = (signal.size() + B - 1) / B + 1;
  const std::size_t outputs = (out.size() + B - 1) / B;     // output blocks
  const double scale = 1.0 / static_cast<double>(st.fft);
  // X_i: the spectrum of the signal's samples [(i - 1) B, (i + 1) B) (zero outside it).
  std::vector<ComplexBuffer> input(inputs);
  ParallelOptions parallel;
  parallel.threads = resolve_thread_count(threads);
  parallel.name = "audio.convolve_partitioned";
  std::vector<RealBuffer> times;
  std::vector<ComplexBuffer> sums;
  for (unsigned t = 0; t < parallel.threads; ++t) {
    times.push_back(real_buffer(st.fft));
    sums.push_back(complex_buffer(bins));
  }
  parallel_for(inputs, [&](const Chunk& chunk) {
    double* time = times[chunk.worker].get();
    for (std::size_t i = chunk.begin; i < chunk.end; ++i) {
      for (std::size_t k = 0; k < st.fft; ++k) {
        const std::size_t at = i * B + k;  // sample at - B of the signal
        time[k] = at >= B && at - B < signal.size() ? signal[at - B] : 0.0;
      }
      input[i] = complex_buffer(bins);
      fftw_execute_dft_r2c(st.plans.forward, time, input[i].get());
    }
  }, parallel);
  // Output block j: the last B samples of IFFT(sum over p of X_(j - p) H_p), overlap-save.
  // Each block is one thread's, its sum in the order of p: the same on any thread count.
  parallel_for(outputs, [&](const Chunk& chunk) {
    double* time = times[chunk.worker].get();
    fftw_complex* sum = sums[chunk.worker].get();
    for (std::size_t j = chunk.begin; j < chunk.end; ++j) {
      std::fill(&sum[0][0], &sum[0][0] + 2 * bins, 0.0);
      const std::size_t first = j >= inputs ? j - inputs + 1 : 0;  // partitions whose input block exists
      for (std::size_t p = first; p <= j && p < st.partitions.size(); ++p) {
        const fftw_complex* x = input[j - p].get();
        const fftw_complex* h = st.partitions[p].get();
        for (std::size_t k = 0; k < bins; ++k) {
          sum[k][0] += x[k][0] * h[k][0] - x[k][1] * h[k][1];
          sum[k][1] += x[k][0] * h[k][1] + x[k][1] * h[k][0];
        }
      }
      fftw_execute_dft_c2r(st.plans.inverse, sum, time);
      const std::size_t begin = j * B, n = std::min(B, out.size() - begin);
      for (std::size_t k = 0; k < n; ++k) out[begin + k] = time[B + k] * scale;
    }
  }, parallel);
  return out;
}

std::vector<double> minimum_phase_fir(std::span<const double> magnitude, std::size_t taps) {
  const std::size_t n = 2 * (magnitude.size() >= 1 ? magnitude.size() - 1 : 0);
  if (n < 4 || (n & (n - 1)) != 0 || n > (std::size_t{1} << 24))
    throw InvalidArgument("minimum_phase_fir: the magnitude needs 2^k + 1 bins (k >= 1)");
  if (taps == 0 || taps > n) throw InvalidArgument("minimum_phase_fir: taps must be in [1, n]");
  ComplexBuffer a = complex_buffer(n), b = complex_buffer(n);
  fftw_plan forward = nullptr, inverse = nullptr;
  {
    std::lock_guard lock(planner_mutex());
    forward = fftw_plan_dft_1d(static_cast<int>(n), a.get(), b.get(), FFTW_FORWARD, FFTW_ESTIMATE);
    inverse = fftw_plan_dft_1d(static_cast<int>(n), b.get(), a.get(), FFTW_BACKWARD, FFTW_ESTIMATE);
  }
  struct Destroy {
    fftw_plan f, i;
    ~Destroy() {
      std::lock_guard lock(planner_mutex());
      if (f) fftw_destroy_plan(f);
      if (i) fftw_destroy_plan(i);
    }
  } destroy{forward, inverse};
  if (!forward || !inverse) throw Error("minimum_phase_fir: FFTW could not plan a transform");
  const std::size_t half = n / 2;
  // log |H| over the whole circle (even), then its real cepstrum.
  for (std::size_t k = 0; k < n; ++k) {
    const double m = magnitude[k <= half ? k : n - k];
    b[k][0] = std::log(std::max(m, 1e-5));
    b[k][1] = 0.0;
  }
  fftw_execute(inverse);  // a = n * cepstrum
  // Fold the cepstrum onto positive quefrencies: the minimum-phase log spectrum.
  for (std::size_t q = 0; q < n; ++q) {
    const double c = a[q][0] / static_cast<double>(n);
    const double w = q == 0 || q == half ? 1.0 : q < half ? 2.0 : 0.0;
    a[q][0] = c * w;
    a[q][1] = 0.0;
  }
  fftw_execute(forward);  // b = log H_min
  for (std::size_t k = 0; k < n; ++k) {
    const std::complex<double> h = std::exp(std::complex<double>(b[k][0], b[k][1]));
    b[k][0] = h.real();
    b[k][1] = h.imag();
  }
  fftw_execute(inverse);  // a = n * h_min
  std::vector<double> h(taps);
  // The last eighth fades out with a half Hann window, so truncation does not ring.
  const std::size_t fade = taps / 8;
  for (std::size_t i = 0; i < taps; ++i) {
    double w = 1.0;
    if (fade > 0 && i >= taps - fade)
      w = 0.5 + 0.5 * std::cos(std::numbers::pi * static_cast<double>(i - (taps - fade) + 1) / static_cast<double>(fade + 1));
    h[i] = a[i][0] / static_cast<double>(n) * w;
  }
  return h;
}

std::vector<double> convolve(std::span<const double> signal, std::span<const double> filter) {
  return Convolver(filter).apply(signal, 1);
}

}  // namespace vola::audio
