// Internal: an adaptive binary range coder (carry-propagating, 32-bit range, bytes out),
// used for the context-modelled occupancy levels of compressed files
// (docs/FILE_FORMAT.md, levels record flags 3). Written from the textbook idea of
// arithmetic coding with a range of 2^24..2^32 renormalised a byte at a time; the byte
// stream a given sequence of (bit, probability) pairs makes is fixed by this file, so it
// is part of the file format.
#pragma once

#include <cstdint>
#include <span>
#include <vector>

#include "vola/version.hpp"

namespace vola {
VOLA_INLINE_NAMESPACE_BEGIN
namespace detail {

// The probability that the next bit is 0, in 1/65536, and how often it was updated: the
// first updates move it fast (1/2, 1/4, ... of the way to the bit seen), later ones by
// 1/32 (or 1/2^kMaxShift, for models that must follow faster). Kept within [32, 65504], so that no bit costs more than 11 bits or less than
// 1/1400 bit: a stream cannot claim more than ~1400 raw bits per stored bit, which keeps
// the "8192 raw bytes per stored byte" rule of compressed records sound.
struct BitModel {
  std::uint16_t p = 32768;
  std::uint8_t seen = 0;

  template <unsigned kMaxShift = 5>
  void update(bool bit) noexcept {
    static constexpr std::uint8_t kShift[16] = {1, 2, 2, 3, 3, 3, 3, 4, 4, 4, 4, 4, 4, 4, 4, 5};
    const unsigned shift = kShift[seen] < kMaxShift ? kShift[seen] : kMaxShift;
    if (seen < 15) ++seen;
    // Both moves, then a select: the bit is as unpredictable as the data.
    const int q = p;
    const int down = q - (q >> shift), up = q + ((65536 - q) >> shift);
    const int moved = bit ? down : up;
    p = static_cast<std::uint16_t>(moved < 32 ? 32 : (moved > 65504 ? 65504 : moved));
  }
};

class RangeEncoder {
 public:
  explicit RangeEncoder(std::vector<std::uint8_t>& out) : out_(out) {}
  // Encodes `bit` and returns it (so that one templated coding routine serves both ways).
  bool code(BitModel& m, bool bit) {
    code_with(m.p, bit);
    m.update(bit);
    return bit;
  }
  // Encodes `bit` with probability `p0` (of a 0, in 1/65536, within [32, 65504]).
  bool code_with(std::uint32_t p0, bool bit) {
    const std::uint32_t bound = (range_ >> 16) * p0;
    if (!bit) {
      range_ = bound;
    } else {
      low_ += bound;
      range_ -= bound;
    }
    while (range_ < (1u << 24)) {
      range_ <<= 8;
      shift_low();
    }
    return bit;
  }
  void finish() {
    for (int i = 0; i < 5; ++i) shift_low();
  }

 private:
  void shift_low() {
    if (static_cast<std::uint32_t>(low_) < 0xFF000000u || (low_ >> 32) != 0) {
      const auto carry = static_cast<std::uint8_t>(low_ >> 32);
      std::uint8_t byte = cache_;
      do {
        out_.push_back(static_cast<std::uint8_t>(byte + carry));
        byte = 0xFF;
      } while (--pending_ != 0);
      cache_ = static_cast<std::uint8_t>(low_ >> 24);
    }
    ++pending_;
    low_ = (low_ & 0x00FFFFFFu) << 8;
  }

  std::vector<std::uint8_t>& out_;
  std::uint64_t low_ = 0;
  std::uint32_t range_ = 0xFFFFFFFFu;
  std::uint8_t cache_ = 0;
  std::uint64_t pending_ = 1;
};

class RangeDecoder {
 public:
  explicit RangeDecoder(std::span<const std::uint8_t> in) : in_(in) {
    for (int i = 0; i < 5; ++i) code_ = (code_ << 8) | next();
  }
  // Decodes a bit; the argument is ignored (see RangeEncoder::code).
  bool code(BitModel& m, bool = false) {
    const bool bit = code_with(m.p);
    m.update(bit);
    return bit;
  }
  // Decodes a bit of probability `p0` (see RangeEncoder::code_with).
  bool code_with(std::uint32_t p0, bool = false) {
    const std::uint32_t bound = (range_ >> 16) * p0;
    const bool bit = code_ >= bound;
    // Selects rather than branches, as in update().
    code_ = bit ? code_ - bound : code_;
    range_ = bit ? range_ - bound : bound;
    while (range_ < (1u << 24)) {
      range_ <<= 8;
      code_ = (code_ << 8) | next();
    }
    return bit;
  }
  // The encoder's finish() writes exactly the bytes this decoder reads: anything else
  // (a stream read past its end, or bytes left over) is corrupt data.
  bool consumed_exactly() const noexcept { return at_ == in_.size(); }

 private:
  std::uint32_t next() noexcept { return at_ < in_.size() ? in_[at_++] : (++at_, 0u); }

  std::span<const std::uint8_t> in_;
  std::size_t at_ = 0;
  std::uint32_t code_ = 0;
  std::uint32_t range_ = 0xFFFFFFFFu;
};

}  // namespace detail
VOLA_INLINE_NAMESPACE_END
}  // namespace vola
