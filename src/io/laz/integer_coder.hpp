// LAZ's integer coder: codes an integer as a correction to a prediction. The correction
// c is split into its magnitude class k (the number of bits of |c|-ish, coded with a
// per-context symbol model) and the position of c inside that class (coded with one
// model per k; for k above `bits_high` only the top bits are modelled and the rest go
// raw). k of the last call is kept because the point coders use it as context for the
// next coordinate (a big jump in x predicts a big jump in y).
//
// Also the running median of 5 that predicts coordinate differences.
//
// Internal to the LAZ codec (src/io/laz).
#pragma once

#include <cstdint>
#include <vector>

#include "arithmetic_coder.hpp"

namespace vola::io::laz {

class IntegerCoder {
 public:
  IntegerCoder() = default;
  // bits: width of the values (32 = any int32); contexts: independent models for k.
  IntegerCoder(std::uint32_t bits, std::uint32_t contexts, bool decoder_tables, std::uint32_t bits_high = 8) {
    create(bits, contexts, decoder_tables, bits_high);
  }

  void create(std::uint32_t bits, std::uint32_t contexts, bool decoder_tables, std::uint32_t bits_high = 8) {
    bits_high_ = bits_high;
    if (bits && bits < 32) {
      corr_bits_ = bits;
      corr_range_ = 1u << bits;
      corr_min_ = -static_cast<std::int32_t>(corr_range_ / 2);
      corr_max_ = static_cast<std::int32_t>(static_cast<std::uint32_t>(corr_min_) + corr_range_ - 1);
    } else {
      corr_bits_ = 32;
      corr_range_ = 0;
      corr_min_ = INT32_MIN;
      corr_max_ = INT32_MAX;
    }
    decoder_tables_ = decoder_tables;
    k_models_.clear();
    k_models_.resize(contexts);
    position_models_.clear();
    position_models_.resize(corr_bits_ + 1);
    k_fresh_.assign(contexts, 0);
    position_fresh_.assign(corr_bits_ + 1, 0);
    reset();
  }

  // Back to the initial probabilities (every chunk starts from them). Models are
  // created and reset when first used after this: a small chunk touches few of them.
  void reset() {
    ++generation_;
    small_model_.reset();
    k_ = 0;
  }

  std::uint32_t k() const { return k_; }

  // Inlined like the decoder's calls (see ArithmeticDecoder).
  [[gnu::always_inline]] std::int32_t decode(ArithmeticDecoder& d, std::int32_t prediction, std::uint32_t context = 0) {
    std::uint32_t real = static_cast<std::uint32_t>(prediction) + static_cast<std::uint32_t>(read_correction(d, context));
    // Values wrap inside the coder's range (16-bit values stay in 0..65535).
    if (corr_range_) {
      if (static_cast<std::int32_t>(real) < 0) real += corr_range_;
      else if (real >= corr_range_) real -= corr_range_;
    }
    return static_cast<std::int32_t>(real);
  }

  void encode(ArithmeticEncoder& e, std::int32_t prediction, std::int32_t real, std::uint32_t context = 0) {
    std::int32_t c = static_cast<std::int32_t>(static_cast<std::uint32_t>(real) - static_cast<std::uint32_t>(prediction));
    if (c < corr_min_) c = static_cast<std::int32_t>(static_cast<std::uint32_t>(c) + corr_range_);
    else if (c > corr_max_) c = static_cast<std::int32_t>(static_cast<std::uint32_t>(c) - corr_range_);
    write_correction(e, c, context);
  }

 private:
  [[gnu::always_inline]] SymbolModel& k_model(std::uint32_t context) {
    if (k_fresh_[context] != generation_) [[unlikely]] refresh_k_model(context);
    return k_models_[context];
  }
  [[gnu::always_inline]] SymbolModel& position_model(std::uint32_t k) {
    if (position_fresh_[k] != generation_) [[unlikely]] refresh_position_model(k);
    return position_models_[k];
  }
  // Out of line: once per model and chunk, and the inlined decoders stay small.
  [[gnu::noinline]] void refresh_k_model(std::uint32_t context) {
    if (k_models_[context].symbols()) k_models_[context].reset();
    else k_models_[context].create(corr_bits_ + 1, decoder_tables_);
    k_fresh_[context] = generation_;
  }
  [[gnu::noinline]] void refresh_position_model(std::uint32_t k) {
    if (position_models_[k].symbols()) position_models_[k].reset();
    else position_models_[k].create(1u << (k <= bits_high_ ? k : bits_high_), decoder_tables_);
    position_fresh_[k] = generation_;
  }

  [[gnu::always_inline]] std::int32_t read_correction(ArithmeticDecoder& d, std::uint32_t context) {
    k_ = d.decode_symbol(k_model(context));
    if (k_ == 0) return static_cast<std::int32_t>(d.decode_bit(small_model_));  // c is 0 or 1
    if (k_ >= 32) return corr_min_;
    std::uint32_t c;
    if (k_ <= bits_high_) {
      c = d.decode_symbol(position_model(k_));
    } else {
      const std::uint32_t low_bits = k_ - bits_high_;
      c = d.decode_symbol(position_model(k_)) << low_bits;
      c |= d.read_bits(low_bits);
    }
    // Class k holds [-(2^k - 1), -2^(k-1)] then [2^(k-1) + 1, 2^k].
    const std::int64_t half = std::int64_t{1} << (k_ - 1);
    const std::int64_t value = c >= half ? std::int64_t{c} + 1 : std::int64_t{c} - ((std::int64_t{1} << k_) - 1);
    return static_cast<std::int32_t>(static_cast<std::uint32_t>(value));
  }

  void write_correction(ArithmeticEncoder& e, std::int32_t c, std::uint32_t context) {
    std::uint32_t magnitude = c <= 0 ? 0u - static_cast<std::uint32_t>(c) : static_cast<std::uint32_t>(c) - 1;
    k_ = 0;
    while (magnitude) {
      magnitude >>= 1;
      ++k_;
    }
    e.encode_symbol(k_model(context), k_);
    if (k_ == 0) {
      e.encode_bit(small_model_, static_cast<std::uint32_t>(c));
      return;
    }
    if (k_ >= 32) return;
    const std::int64_t shifted = c < 0 ? std::int64_t{c} + ((std::int64_t{1} << k_) - 1) : std::int64_t{c} - 1;
    const auto position = static_cast<std::uint32_t>(shifted);
    if (k_ <= bits_high_) {
      e.encode_symbol(position_model(k_), position);
    } else {
      const std::uint32_t low_bits = k_ - bits_high_;
      e.encode_symbol(position_model(k_), position >> low_bits);
      e.write_bits(low_bits, position & ((1u << low_bits) - 1));
    }
  }

  std::uint32_t corr_bits_ = 0, bits_high_ = 8, corr_range_ = 0, k_ = 0;
  std::int32_t corr_min_ = 0, corr_max_ = 0;
  bool decoder_tables_ = true;
  std::uint32_t generation_ = 0;  // a model is current when its "fresh" entry equals this
  std::vector<SymbolModel> k_models_;
  BitModel small_model_;
  std::vector<SymbolModel> position_models_;  // index k; [0] unused
  std::vector<std::uint32_t> k_fresh_, position_fresh_;
};

// The median of the last 5 values, kept sorted with a flag that alternates which end
// a new value displaces (so that it tracks a drifting series without a ring buffer).
struct Median5 {
  std::int32_t v[5] = {0, 0, 0, 0, 0};
  bool high = true;

  std::int32_t get() const { return v[2]; }
  void add(std::int32_t x) {
    if (high) {
      if (x < v[2]) {
        v[4] = v[3];
        v[3] = v[2];
        if (x < v[0]) {
          v[2] = v[1];
          v[1] = v[0];
          v[0] = x;
        } else if (x < v[1]) {
          v[2] = v[1];
          v[1] = x;
        } else {
          v[2] = x;
        }
      } else {
        if (x < v[3]) {
          v[4] = v[3];
          v[3] = x;
        } else {
          v[4] = x;
        }
        high = false;
      }
    } else {
      if (v[2] < x) {
        v[0] = v[1];
        v[1] = v[2];
        if (v[4] < x) {
          v[2] = v[3];
          v[3] = v[4];
          v[4] = x;
        } else if (v[3] < x) {
          v[2] = v[3];
          v[3] = x;
        } else {
          v[2] = x;
        }
      } else {
        if (v[1] < x) {
          v[0] = v[1];
          v[1] = x;
        } else {
          v[0] = x;
        }
        high = true;
      }
    }
  }
};

// Models created on first use under a small key (e.g. "the last classification"), all
// forgotten at each chunk start. The storage is kept, so a chunk allocates only the
// models it uses beyond those of earlier chunks.
template <std::uint32_t Keys>
class LazyModels {
 public:
  LazyModels() = default;
  LazyModels(std::uint32_t symbols, bool decoder_table) : symbols_(symbols), table_(decoder_table) { forget(); }
  void configure(std::uint32_t symbols, bool decoder_table) {
    symbols_ = symbols;
    table_ = decoder_table;
    forget();
  }
  void forget() {
    for (auto& s : slot_) s = -1;
    used_ = 0;
  }
  SymbolModel& at(std::uint32_t key) {
    if (slot_[key] < 0) {
      if (used_ == pool_.size()) pool_.emplace_back(symbols_, table_);
      else pool_[used_].reset();
      slot_[key] = static_cast<std::int32_t>(used_++);
    }
    return pool_[static_cast<std::size_t>(slot_[key])];
  }

 private:
  std::int32_t slot_[Keys];
  std::vector<SymbolModel> pool_;
  std::size_t used_ = 0;
  std::uint32_t symbols_ = 2;
  bool table_ = true;
};

}  // namespace vola::io::laz
