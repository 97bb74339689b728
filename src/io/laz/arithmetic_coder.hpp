// The adaptive binary arithmetic (range) coder of LAZ, as the LASzip specification
// defines it: a 32-bit interval (base, length) renormalised a byte at a time, adaptive
// bit models with 13-bit probabilities, and adaptive symbol models with 15-bit
// cumulative frequencies (with a look-up table that speeds up decoding). Every rule
// below (initial counts, update cadence, halving, the bytes done() emits) is part of the
// format: change any of them and the bytes no longer mean the same points.
//
// Internal to the LAZ codec (src/io/laz). Header-only so that the per-point item coders
// inline the hot calls.
#pragma once

#include <bit>
#include <cstddef>
#include <cstring>
#include <cstdint>
#include <memory>
#include <span>
#include <vector>



namespace vola::io::laz {

inline constexpr std::uint32_t kMinLength = 0x01000000u;  // renormalise below 2^24
inline constexpr std::uint32_t kMaxLength = 0xFFFFFFFFu;
inline constexpr unsigned kBitShift = 13;                  // bit model probability precision
inline constexpr std::uint32_t kBitMaxCount = 1u << kBitShift;
inline constexpr unsigned kSymbolShift = 15;               // symbol model frequency precision
inline constexpr std::uint32_t kSymbolMaxCount = 1u << kSymbolShift;

// A two-symbol adaptive model. The probability of 0 is re-estimated every
// `update_cycle` bits, with a cycle that grows (x5/4) up to 64 so that early bits adapt
// quickly and later ones cost little.
struct BitModel {
  std::uint32_t bit0_count = 1, bit_count = 2;
  std::uint32_t bit0_prob = 1u << (kBitShift - 1);
  std::uint32_t update_cycle = 4, until_update = 4;

  void reset() { *this = BitModel{}; }
  // Out of line: rare, and the decoders' hot paths stay small.
  [[gnu::noinline]] void update() {
    if ((bit_count += update_cycle) > kBitMaxCount) {
      bit_count = (bit_count + 1) >> 1;
      bit0_count = (bit0_count + 1) >> 1;
      if (bit0_count == bit_count) ++bit_count;
    }
    const std::uint32_t scale = 0x80000000u / bit_count;
    bit0_prob = (bit0_count * scale) >> (31 - kBitShift);
    update_cycle = (5 * update_cycle) >> 2;
    if (update_cycle > 64) update_cycle = 64;
    until_update = update_cycle;
  }
};

// An adaptive model over `symbols` symbols (2..2048). `distribution[k]` is the
// cumulative frequency below symbol k scaled to 2^15; decoders keep a table from the top
// bits of a scaled value to the first candidate symbol.
class SymbolModel {
 public:
  SymbolModel() = default;
  SymbolModel(std::uint32_t symbols, bool decoder_table) { create(symbols, decoder_table); }

  void create(std::uint32_t symbols, bool decoder_table) {
    symbols_ = symbols;
    last_symbol_ = symbols - 1;
    table_size_ = table_shift_ = 0;
    if (decoder_table) {
      // Four entries per symbol, for every model: the table is the decoder's own
      // speed-up (the format fixes only the distribution). LASzip has one entry per 4
      // symbols and none below 17 symbols, and bisects the rest with a branch per step;
      // a finer table mostly lands on the symbol at once (measured on point format 3:
      // one entry per symbol +13%, then four per symbol and tables for small models +6%).
      std::uint32_t table_bits = 2;
      while (symbols > (1u << (table_bits - 2))) ++table_bits;
      table_size_ = 1u << table_bits;
      table_shift_ = kSymbolShift - table_bits;
    }
    storage_ = std::make_unique<std::uint32_t[]>(2 * std::size_t{symbols});
    distribution = storage_.get();
    counts = distribution + symbols;
    // 16-bit entries (symbols <= 2048): a decoder's hot tables take half the cache
    // (measured +2.5% on point format 3, whose RGB and GPS models have 256-516 symbols).
    table_storage_.reset(table_size_ ? new std::uint16_t[table_size_ + 2 + kTableSlack] : nullptr);
    table = table_storage_.get();
    reset();
  }

  // Every symbol starts with count 1; the first update comes after (symbols + 6) / 2.
  void reset() {
    total_count_ = 0;
    update_cycle_ = symbols_;
    for (std::uint32_t k = 0; k < symbols_; ++k) counts[k] = 1;
    update();
    until_update = update_cycle_ = (symbols_ + 6) >> 1;
  }

  [[gnu::noinline]] void update() {
    if ((total_count_ += update_cycle_) > kSymbolMaxCount) {
      total_count_ = 0;
      for (std::uint32_t k = 0; k < symbols_; ++k) total_count_ += (counts[k] = (counts[k] + 1) >> 1);
    }
    const std::uint32_t scale = 0x80000000u / total_count_;
    // Locals: the stores below would otherwise make the compiler reload the members.
    std::uint32_t* const dist = distribution;
    const std::uint32_t* const count = counts;
    const std::uint32_t symbols = symbols_;
    std::uint32_t sum = 0;
    for (std::uint32_t k = 0; k < symbols; ++k) {
      dist[k] = (scale * sum) >> (31 - kSymbolShift);
      sum += count[k];
    }
    if (table) fill_table();
    update_cycle_ = (5 * update_cycle_) >> 2;
    const std::uint32_t max_cycle = (symbols_ + 6) << 3;
    if (update_cycle_ > max_cycle) update_cycle_ = max_cycle;
    until_update = update_cycle_;
  }

  // table[j] = the last symbol whose distribution, in table units, is below j. Writes
  // kTableSlack entries at a time (one store for most symbols, which span a few
  // entries, instead of a loop whose exit a predictor misses at every symbol); writes
  // past a symbol's entries are overwritten by the next symbols, and the slack after
  // the table takes the last ones.
  static constexpr std::uint32_t kTableSlack = 8;
  void fill_table() {
    std::uint16_t* const entries = table;
    const std::uint32_t* const dist = distribution;
    const std::uint32_t symbols = symbols_, shift = table_shift_;
    std::uint32_t s = 0;  // entries 1..s are final
    for (std::uint32_t k = 1; k < symbols; ++k) {
      const std::uint32_t w = dist[k] >> shift;
      std::uint16_t block[kTableSlack];
      for (auto& e : block) e = static_cast<std::uint16_t>(k - 1);
      std::uint32_t j = s + 1;
      do {
        std::memcpy(entries + j, block, sizeof block);
        j += kTableSlack;
      } while (j <= w);
      s = w;
    }
    entries[0] = 0;
    for (std::uint32_t j = s + 1; j <= table_size_ + 1; ++j) entries[j] = static_cast<std::uint16_t>(symbols - 1);
  }

  std::uint32_t symbols() const { return symbols_; }
  std::uint32_t last_symbol() const { return last_symbol_; }
  std::uint32_t table_size() const { return table_size_; }
  std::uint32_t table_shift() const { return table_shift_; }

  std::uint32_t* distribution = nullptr;
  std::uint32_t* counts = nullptr;
  std::uint16_t* table = nullptr;
  std::uint32_t until_update = 0;

 private:
  std::unique_ptr<std::uint32_t[]> storage_;
  std::unique_ptr<std::uint16_t[]> table_storage_;
  std::uint32_t symbols_ = 0, last_symbol_ = 0, table_size_ = 0, table_shift_ = 0;
  std::uint32_t total_count_ = 0, update_cycle_ = 0;
};

// Decodes one arithmetic-coded stream held in a span. Reading past the span yields zero
// bytes (as a valid stream never does: the encoder pads its end so that the decoder's
// reads stay in step) and counts them, so that a truncated or corrupt stream decodes to
// garbage without touching memory outside the span; callers check overrun().
class ArithmeticDecoder {
 public:
  ArithmeticDecoder() = default;
  explicit ArithmeticDecoder(std::span<const std::uint8_t> bytes) { start(bytes); }

  void start(std::span<const std::uint8_t> bytes) {
    pos_ = bytes.data();
    end_ = bytes.data() + bytes.size();
    whole_words_end_ = bytes.size() >= 4 ? end_ - 3 : bytes.data();
    overrun_ = 0;
    length_ = kMaxLength;
    value_ = next_byte() << 24;
    value_ |= next_byte() << 16;
    value_ |= next_byte() << 8;
    value_ |= next_byte();
  }

  // The decoding calls are always inlined: the item decoders then hold the decoder's
  // state (value, length, position) in registers across a whole point, rather than
  // storing and reloading it around every call (one symbol's result is the next one's
  // input, so each round trip through memory adds to every symbol's latency).
  [[gnu::always_inline]] std::uint32_t decode_bit(BitModel& m) {
    const std::uint32_t x = m.bit0_prob * (length_ >> kBitShift);
    const std::uint32_t bit = value_ >= x;
    // Select rather than branch: the bit is as unpredictable as the data.
    value_ = bit ? value_ - x : value_;
    length_ = bit ? length_ - x : x;
    m.bit0_count += bit ^ 1;
    renormalise();
    if (--m.until_update == 0) [[unlikely]] m.update();
    return bit;
  }

  [[gnu::always_inline]] std::uint32_t decode_symbol(SymbolModel& m) {
    const std::uint32_t unit = length_ >> kSymbolShift;
    const std::uint32_t dv = value_ / unit;
    // The table narrows the candidates to [sym, n); a model without one (an encoder's)
    // bisects them all. distribution[k] > dv is distribution[k] * unit > value.
    std::uint32_t sym = 0, n = m.symbols();
    if (m.table) [[likely]] {
      std::uint32_t t = dv >> m.table_shift();
      // Only a corrupt stream (value >= length) reaches past the table.
      if (t > m.table_size()) t = m.table_size();
      sym = m.table[t];
      n = m.table[t + 1] + 1;
    }
    while (n > sym + 1) [[unlikely]] {
      const std::uint32_t k = (sym + n) >> 1;
      if (m.distribution[k] > dv) n = k; else sym = k;
    }
    const std::uint32_t x = m.distribution[sym] * unit;
    // distribution[symbols] is counts[0]: readable, and not used for the last symbol.
    const std::uint32_t next = m.distribution[sym + 1] * unit;
    const std::uint32_t y = sym == m.last_symbol() ? length_ : next;
    value_ -= x;
    length_ = y - x;
    renormalise();
    ++m.counts[sym];
    if (--m.until_update == 0) [[unlikely]] m.update();
    return sym;
  }

  // `bits` (1..32) raw bits; above 19 the low 16 come first, as the encoder wrote them.
  [[gnu::always_inline]] std::uint32_t read_bits(unsigned bits) {
    if (bits > 19) {
      const std::uint32_t low = read_short();
      return (read_few_bits(bits - 16) << 16) | low;
    }
    return read_few_bits(bits);
  }
  [[gnu::always_inline]] std::uint32_t read_short() { return read_few_bits(16); }
  [[gnu::always_inline]] std::uint32_t read_int() {
    const std::uint32_t low = read_short();
    return (read_short() << 16) | low;
  }

  // Bytes wanted beyond the span so far (0 for a sound stream).
  std::uint64_t overrun() const { return overrun_; }

 private:
  // 1..19 bits.
  [[gnu::always_inline]] std::uint32_t read_few_bits(unsigned bits) {
    const std::uint32_t sym = value_ / (length_ >>= bits);
    value_ -= length_ * sym;
    renormalise();
    return sym & ((1u << bits) - 1);
  }
  std::uint32_t next_byte() {
    if (pos_ < end_) return *pos_++;
    ++overrun_;
    return 0;
  }
  // Brings length back to 2^24 or more: shifts in 0 to 3 bytes at once, as many as
  // length has leading zero bytes. No branch on whether (or how far) to renormalise:
  // about one symbol in three does, a coin toss that a branch predictor loses. Within
  // 4 bytes of the end it goes byte by byte so as never to read past the span.
  [[gnu::always_inline]] void renormalise() {
    if (pos_ < whole_words_end_) [[likely]] {
      // 0, 8, 16 or 24 (length is never 0; "| 1" spares the compiler's test for it)
      const unsigned shift = static_cast<unsigned>(std::countl_zero(length_ | 1u)) & 24u;
      std::uint32_t word;
      std::memcpy(&word, pos_, 4);
      if constexpr (std::endian::native == std::endian::little) word = __builtin_bswap32(word);
      value_ = (value_ << shift) | static_cast<std::uint32_t>(std::uint64_t{word} >> (32 - shift));
      length_ <<= shift;
      pos_ += shift >> 3;
    } else if (length_ < kMinLength) {
      const Refill r = refill_near_end(pos_, end_, value_, length_);
      pos_ = r.pos;
      value_ = r.value;
      length_ = r.length;
      overrun_ += r.missing;
    }
  }
  // Out of line, and on values rather than on the decoder: a call given the decoder's
  // address would make the inlined callers keep its state in memory.
  struct Refill {
    const std::uint8_t* pos;
    std::uint32_t value, length, missing;
  };
  [[gnu::noinline]] static Refill refill_near_end(const std::uint8_t* pos, const std::uint8_t* end, std::uint32_t value,
                                                  std::uint32_t length) {
    std::uint32_t missing = 0;
    do {
      std::uint32_t byte = 0;
      if (pos < end) byte = *pos++;
      else ++missing;
      value = (value << 8) | byte;
    } while ((length <<= 8) < kMinLength);
    return {pos, value, length, missing};
  }

  const std::uint8_t* pos_ = nullptr;
  const std::uint8_t* end_ = nullptr;
  const std::uint8_t* whole_words_end_ = nullptr;  // 4 bytes can be read before this
  std::uint64_t overrun_ = 0;
  std::uint32_t value_ = 0, length_ = kMaxLength;
};

// The encoder twin: appends to its own byte vector (so that a carry never runs into
// bytes that are not part of this stream).
class ArithmeticEncoder {
 public:
  void encode_bit(BitModel& m, std::uint32_t bit) {
    const std::uint32_t x = m.bit0_prob * (length_ >> kBitShift);
    if (bit == 0) {
      length_ = x;
      ++m.bit0_count;
    } else {
      add_to_base(x);
      length_ -= x;
    }
    if (length_ < kMinLength) renormalise();
    if (--m.until_update == 0) m.update();
  }

  void encode_symbol(SymbolModel& m, std::uint32_t sym) {
    const std::uint32_t unit = length_ >> kSymbolShift;
    const std::uint32_t x = m.distribution[sym] * unit;
    add_to_base(x);
    // The last symbol takes the whole rest of the interval (the decoder's y = length).
    if (sym == m.last_symbol()) length_ -= x;
    else length_ = m.distribution[sym + 1] * unit - x;
    if (length_ < kMinLength) renormalise();
    ++m.counts[sym];
    if (--m.until_update == 0) m.update();
  }

  void write_bits(unsigned bits, std::uint32_t value) {
    if (bits > 19) {
      write_short(value & 0xFFFFu);
      value >>= 16;
      bits -= 16;
    }
    add_to_base(value * (length_ >>= bits));
    if (length_ < kMinLength) renormalise();
  }
  void write_short(std::uint32_t value) {
    add_to_base(value * (length_ >>= 16));
    if (length_ < kMinLength) renormalise();
  }
  void write_int(std::uint32_t value) {
    write_short(value & 0xFFFFu);
    write_short(value >> 16);
  }

  // Flushes the interval and pads with zeros so that a decoder's reads end exactly at
  // the last byte (1 or 2 bytes of interval, then 3 or 2 zeros: 4 in all).
  void finish() {
    bool another_byte = true;
    if (length_ > 2 * kMinLength) {
      add_to_base(kMinLength);
      length_ = kMinLength >> 1;
    } else {
      add_to_base(kMinLength >> 1);
      length_ = kMinLength >> 9;
      another_byte = false;
    }
    renormalise();
    out_.push_back(0);
    out_.push_back(0);
    if (another_byte) out_.push_back(0);
  }

  std::vector<std::uint8_t>& bytes() { return out_; }
  void clear() {
    out_.clear();
    base_ = 0;
    length_ = kMaxLength;
  }

 private:
  void add_to_base(std::uint32_t x) {
    const std::uint32_t before = base_;
    base_ += x;
    if (base_ < before) propagate_carry();
  }
  void propagate_carry() {
    for (std::size_t i = out_.size(); i-- > 0;) {
      if (out_[i] != 0xFF) {
        ++out_[i];
        return;
      }
      out_[i] = 0;
    }
  }
  void renormalise() {
    do {
      out_.push_back(static_cast<std::uint8_t>(base_ >> 24));
      base_ <<= 8;
    } while ((length_ <<= 8) < kMinLength);
  }

  std::vector<std::uint8_t> out_;
  std::uint32_t base_ = 0, length_ = kMaxLength;
};

}  // namespace vola::io::laz
