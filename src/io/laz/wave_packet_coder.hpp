// Wave packets (LAS formats 4, 5, 9 and 10): the 29 bytes that point a return to its
// digitised waveform. WAVEPACKET13 (point-wise, version 1) and WAVEPACKET14 (layered,
// versions 3 and 4) code them alike, each field against the last packet:
//   descriptor index  a symbol (256), no prediction
//   byte offset       a symbol (4, its model chosen by the last one): 0 the same offset,
//                     1 the last offset plus the last packet's size, 2 the last offset
//                     plus a 32-bit difference (coded against the last such difference),
//                     3 the offset in full (64 raw bits, low half first)
//   packet size       an integer against the last size
//   return point      the float's bits as an integer against the last one's
//   X(t), Y(t), Z(t)  likewise, one integer coder with a context per axis
// Packet layout: index (u8), offset (u64), size (u32), return point and X/Y/Z(t) (f32),
// little-endian.
//
// Internal to the LAZ codec (src/io/laz).
#pragma once

#include <cstdint>
#include <cstring>

#include "integer_coder.hpp"
#include "vola/little_endian.hpp"

namespace vola::io::laz {

inline constexpr std::size_t kWavePacketBytes = 29;

class WavePacketCoder {
 public:
  explicit WavePacketCoder(bool decoding) {
    index_.create(256, decoding);
    for (auto& m : offset_kind_) m.create(4, decoding);
    offset_diff_.create(32, 1, decoding);
    size_.create(32, 1, decoding);
    return_point_.create(32, 1, decoding);
    xyz_.create(32, 3, decoding);
  }

  void reset() {
    index_.reset();
    for (auto& m : offset_kind_) m.reset();
    for (auto* ic : {&offset_diff_, &size_, &return_point_, &xyz_}) ic->reset();
    last_kind_ = 0;
    last_diff_ = 0;
  }

  // `last` and `out` are whole packets (29 bytes); they may be the same bytes.
  void decode(ArithmeticDecoder& d, const std::uint8_t* last, std::uint8_t* out) {
    const auto last_offset = load_le<std::uint64_t>(last + 1);
    const auto last_size = load_le<std::uint32_t>(last + 9);
    const auto index = static_cast<std::uint8_t>(d.decode_symbol(index_));
    last_kind_ = d.decode_symbol(offset_kind_[last_kind_]);
    std::uint64_t offset = last_offset;
    if (last_kind_ == 1) {
      offset = last_offset + last_size;
    } else if (last_kind_ == 2) {
      last_diff_ = offset_diff_.decode(d, last_diff_);
      offset = last_offset + static_cast<std::uint64_t>(static_cast<std::int64_t>(last_diff_));
    } else if (last_kind_ == 3) {
      const std::uint64_t low = d.read_int();
      offset = low | (std::uint64_t{d.read_int()} << 32);
    }
    const std::int32_t size = size_.decode(d, static_cast<std::int32_t>(last_size));
    const std::int32_t return_point = return_point_.decode(d, load_le<std::int32_t>(last + 13));
    std::int32_t xyz[3];
    for (int a = 0; a < 3; ++a) xyz[a] = xyz_.decode(d, load_le<std::int32_t>(last + 17 + 4 * a), static_cast<std::uint32_t>(a));
    out[0] = index;
    std::memcpy(out + 1, &offset, 8);
    std::memcpy(out + 9, &size, 4);
    std::memcpy(out + 13, &return_point, 4);
    std::memcpy(out + 17, xyz, 12);
  }

  void encode(ArithmeticEncoder& e, const std::uint8_t* last, const std::uint8_t* in) {
    e.encode_symbol(index_, in[0]);
    const auto last_offset = load_le<std::uint64_t>(last + 1);
    const auto offset = load_le<std::uint64_t>(in + 1);
    const auto last_size = load_le<std::uint32_t>(last + 9);
    const auto diff64 = static_cast<std::int64_t>(offset - last_offset);
    const auto diff32 = static_cast<std::int32_t>(diff64);
    std::uint32_t kind = 3;
    if (diff64 == diff32) kind = diff32 == 0 ? 0 : diff32 == static_cast<std::int32_t>(last_size) ? 1 : 2;
    e.encode_symbol(offset_kind_[last_kind_], kind);
    last_kind_ = kind;
    if (kind == 2) {
      offset_diff_.encode(e, last_diff_, diff32);
      last_diff_ = diff32;
    } else if (kind == 3) {
      e.write_int(static_cast<std::uint32_t>(offset));
      e.write_int(static_cast<std::uint32_t>(offset >> 32));
    }
    size_.encode(e, static_cast<std::int32_t>(last_size), load_le<std::int32_t>(in + 9));
    return_point_.encode(e, load_le<std::int32_t>(last + 13), load_le<std::int32_t>(in + 13));
    for (int a = 0; a < 3; ++a)
      xyz_.encode(e, load_le<std::int32_t>(last + 17 + 4 * a), load_le<std::int32_t>(in + 17 + 4 * a),
                  static_cast<std::uint32_t>(a));
  }

 private:
  SymbolModel index_, offset_kind_[4];
  IntegerCoder offset_diff_, size_, return_point_, xyz_;
  std::uint32_t last_kind_ = 0;
  std::int32_t last_diff_ = 0;
};

}  // namespace vola::io::laz
