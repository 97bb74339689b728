#include "vola/audio/convolve.hpp"

#include <fftw3.h>

#include <algorithm>
#include <cmath>
#include <numbers>
#include <complex>
#include <mutex>
#include <thread>

#include "vola/error.hpp"

namespace vola::audio {

namespace {

// FFTW's planner is not thread-safe; executing plans on new arrays is.
std::mutex& planner_mutex() {
  static std::mutex m;
  return m;
}

struct FftwFree {
  void operator()(void* p) const noexcept { fftw_free(p); }
};
using RealBuffer = std::unique_ptr<double[], FftwFree>;
using ComplexBuffer = std::unique_ptr<fftw_complex[], FftwFree>;

RealBuffer real_buffer(std::size_t n) {
  auto* p = fftw_alloc_real(n);
  if (!p) throw std::bad_alloc();
  return RealBuffer(p);
}
ComplexBuffer complex_buffer(std::size_t n) {
  auto* p = fftw_alloc_complex(n);
  if (!p) throw std::bad_alloc();
  return ComplexBuffer(p);
}

}  // namespace

struct Convolver::Plans {
  fftw_plan forward = nullptr;
  fftw_plan inverse = nullptr;
  ComplexBuffer filter_spectrum;
  ~Plans() {
    std::lock_guard lock(planner_mutex());
    if (forward) fftw_destroy_plan(forward);
    if (inverse) fftw_destroy_plan(inverse);
  }
};

Convolver::Convolver(std::span<const double> filter) : filter_size_(filter.size()), plans_(std::make_unique<Plans>()) {
  if (filter.empty()) throw InvalidArgument("convolution: the filter is empty");
  // Blocks at least four times the filter keep the FFT work per output sample low; a
  // power of two (>= 2 * filter) also keeps a block's tail shorter than a block, so even
  // blocks never overlap each other (see apply).
  fft_size_ = 4096;
  while (fft_size_ < 4 * filter.size()) fft_size_ *= 2;
  block_ = fft_size_ - filter.size() + 1;
  const std::size_t bins = fft_size_ / 2 + 1;
  RealBuffer time = real_buffer(fft_size_);
  plans_->filter_spectrum = complex_buffer(bins);
  ComplexBuffer spectrum = complex_buffer(bins);
  {
    std::lock_guard lock(planner_mutex());
    const int n = static_cast<int>(fft_size_);
    plans_->forward = fftw_plan_dft_r2c_1d(n, time.get(), spectrum.get(), FFTW_ESTIMATE);
    plans_->inverse = fftw_plan_dft_c2r_1d(n, spectrum.get(), time.get(), FFTW_ESTIMATE);
  }
  if (!plans_->forward || !plans_->inverse) throw Error("convolution: FFTW could not plan a transform");
  std::fill(time.get(), time.get() + fft_size_, 0.0);
  std::copy(filter.begin(), filter.end(), time.get());
  fftw_execute_dft_r2c(plans_->forward, time.get(), plans_->filter_spectrum.get());
}

Convolver::~Convolver() = default;

std::vector<double> Convolver::apply(std::span<const double> signal, unsigned threads) const {
  if (signal.empty()) return {};
  std::vector<double> out(signal.size() + filter_size_ - 1, 0.0);
  const std::size_t blocks = (signal.size() + block_ - 1) / block_;
  const std::size_t bins = fft_size_ / 2 + 1;
  const double scale = 1.0 / static_cast<double>(fft_size_);
  if (threads == 0) threads = std::max(1u, std::thread::hardware_concurrency());
  threads = static_cast<unsigned>(std::min<std::size_t>(threads, (blocks + 1) / 2));
  // Block b writes out[b * block_, b * block_ + fft_size_): it overlaps only blocks b - 1
  // and b + 1. All even blocks are added first, then all odd ones, so every sample gets
  // its (at most two) contributions in the same order whatever the thread count.
  std::vector<RealBuffer> times;
  std::vector<ComplexBuffer> spectra;
  for (unsigned t = 0; t < threads; ++t) {  // allocated here: a thread must not throw
    times.push_back(real_buffer(fft_size_));
    spectra.push_back(complex_buffer(bins));
  }
  auto run = [&](std::size_t parity, std::size_t first, std::size_t stride) {
    double* time = times[first].get();
    fftw_complex* spectrum = spectra[first].get();
    for (std::size_t b = parity + 2 * first; b < blocks; b += 2 * stride) {
      const std::size_t begin = b * block_;
      const std::size_t n = std::min(block_, signal.size() - begin);
      std::copy_n(signal.data() + begin, n, time);
      std::fill(time + n, time + fft_size_, 0.0);
      fftw_execute_dft_r2c(plans_->forward, time, spectrum);
      for (std::size_t k = 0; k < bins; ++k) {
        const std::complex<double> a(spectrum[k][0], spectrum[k][1]);
        const std::complex<double> h(plans_->filter_spectrum[k][0], plans_->filter_spectrum[k][1]);
        const std::complex<double> y = a * h;
        spectrum[k][0] = y.real();
        spectrum[k][1] = y.imag();
      }
      fftw_execute_dft_c2r(plans_->inverse, spectrum, time);
      const std::size_t valid = std::min(fft_size_, out.size() - begin);
      for (std::size_t i = 0; i < valid; ++i) out[begin + i] += time[i] * scale;
    }
  };
  for (std::size_t parity = 0; parity < 2; ++parity) {
    std::vector<std::jthread> pool;
    for (unsigned t = 1; t < threads; ++t) pool.emplace_back(run, parity, t, threads);
    run(parity, 0, threads);
  }
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
