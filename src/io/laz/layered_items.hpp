// The layered item coders (compressor 3, LAS 1.4 formats 6-10): POINT14, RGB14,
// RGBNIR14, WAVEPACKET14 and BYTE14, versions 3 and 4. Each field group is coded into its own stream
// (a "layer"), so a reader may skip layers and a layer whose values never change in a
// chunk is left out (size 0: every point keeps the chunk's first value).
//
// Points are modelled per scanner channel (up to 4 "contexts", each with its own last
// point and models, created when a channel first appears in a chunk). The other items
// follow the context POINT14 publishes. Version 3 publishes it only on points where the
// channel changes (0 on the others) and its RGB/BYTE coders keep predicting from the
// previous context's last values when switching to a context seen before; version 4
// follows the channel on every point. Both are decoded as written.
//
// Internal to the LAZ codec (src/io/laz).
#pragma once

#include <array>
#include <cstdint>
#include <memory>
#include <span>
#include <vector>

#include "item_common.hpp"

namespace vola::io::laz {

// LAS formats 6-10's first 30 bytes, unpacked.
struct Point14 {
  std::int32_t x = 0, y = 0, z = 0;
  std::uint16_t intensity = 0;
  std::uint8_t return_number = 0, return_count = 0;
  std::uint8_t class_flags = 0, channel = 0, scan_direction = 0, edge = 0;
  std::uint8_t classification = 0, user_data = 0;
  std::int16_t scan_angle = 0;
  std::uint16_t source = 0;
  std::uint64_t gps = 0;
  bool gps_changed = false;  // coder state: did the last point's time change
};
Point14 unpack_point14(const std::uint8_t* p);
void pack_point14(const Point14& point, std::uint8_t* p);

// The layers of POINT14, in the order of their sizes and bytes in a chunk.
enum Layer14 : int { kXy, kZ, kClass, kFlags, kIntensity, kScanAngle, kUserData, kSource, kGps, kLayers14 };

struct Point14Context;  // one scanner channel's last point and models

// Decodes or encodes POINT14. decode/encode return the context the other items use.
class Point14Coder {
 public:
  Point14Coder(bool decoding, bool version4);
  ~Point14Coder();

  std::uint32_t start(const std::uint8_t* first);
  // Decoding: the layers' bytes (empty = absent). With xyz_only, every layer but XY and
  // Z is treated as absent (its fields keep the chunk's first values): XY and Z depend on
  // no other layer, so the coordinates come out the same (LASzip's selective decoding).
  void set_layers(const std::array<std::span<const std::uint8_t>, kLayers14>& layers, bool xyz_only = false);
  std::uint32_t decode(std::uint8_t* out);
  std::uint64_t overrun() const;

  std::uint32_t encode(const std::uint8_t* in);
  // Encoding: the finished layers (empty where nothing changed, except XY and Z, which
  // are always written).
  std::array<std::vector<std::uint8_t>, kLayers14> finish();

 private:
  Point14Context& context_for(std::uint32_t channel, const Point14& seed);
  void decode_returns(Point14Context& c, std::uint32_t changed, std::uint32_t& n, std::uint32_t& r);
  void decode_fields(Point14Context& c, Point14& last, std::uint32_t changed, std::uint32_t n, std::uint32_t r);
  void encode_returns(Point14Context& c, const Point14& last, const Point14& p, std::uint32_t changed);
  void encode_fields(Point14Context& c, const Point14& last, const Point14& p, std::uint32_t changed);

  bool decoding_, version4_;
  std::array<std::unique_ptr<Point14Context>, 4> contexts_;
  std::uint32_t current_ = 0;
  std::array<ArithmeticDecoder, kLayers14> decoders_;
  std::array<bool, kLayers14> present_{};
  std::array<ArithmeticEncoder, kLayers14> encoders_;
  std::array<bool, kLayers14> changed_{};
};

// RGB14 (nir = false) or RGBNIR14 (layers: RGB, then NIR).
class Rgb14Coder {
 public:
  Rgb14Coder(bool decoding, bool nir, bool version4);
  ~Rgb14Coder();
  void start(const std::uint8_t* first, std::uint32_t context);
  void set_layers(std::span<const std::uint8_t> rgb, std::span<const std::uint8_t> nir);
  void decode(std::uint32_t context, std::uint8_t* out);
  void encode(std::uint32_t context, const std::uint8_t* in);
  std::uint64_t overrun() const;
  std::array<std::vector<std::uint8_t>, 2> finish();

  struct Context;

 private:
  Context& follow(std::uint32_t context);

  bool decoding_, nir_, version4_;
  std::array<std::unique_ptr<Context>, 4> contexts_;
  std::uint32_t current_ = 0;
  ArithmeticDecoder decoders_[2];
  bool present_[2] = {};
  ArithmeticEncoder encoders_[2];
  bool changed_[2] = {};
};

// WAVEPACKET14: one layer. Where it is absent, every point repeats the packet of the
// point before it (as LASzip leaves its record buffer untouched).
class WavePacket14Coder {
 public:
  WavePacket14Coder(bool decoding, bool version4);
  ~WavePacket14Coder();
  void start(const std::uint8_t* first, std::uint32_t context);
  void set_layer(std::span<const std::uint8_t> layer);
  void decode(std::uint32_t context, std::uint8_t* out);
  void encode(std::uint32_t context, const std::uint8_t* in);
  std::uint64_t overrun() const;
  std::vector<std::uint8_t> finish();

  struct Context;

 private:
  Context& follow(std::uint32_t context);

  bool decoding_, version4_;
  std::array<std::unique_ptr<Context>, 4> contexts_;
  std::uint32_t current_ = 0;
  std::uint8_t previous_[29] = {};  // the last point's packet
  ArithmeticDecoder decoder_;
  bool present_ = false;
  ArithmeticEncoder encoder_;
  bool changed_ = false;
};

// BYTE14: one layer per extra byte.
class Byte14Coder {
 public:
  Byte14Coder(std::size_t count, bool decoding, bool version4);
  ~Byte14Coder();
  void start(const std::uint8_t* first, std::uint32_t context);
  void set_layers(std::span<const std::span<const std::uint8_t>> layers);
  void decode(std::uint32_t context, std::uint8_t* out);
  void encode(std::uint32_t context, const std::uint8_t* in);
  std::uint64_t overrun() const;
  std::vector<std::vector<std::uint8_t>> finish();

  struct Context;

 private:
  Context& follow(std::uint32_t context);

  std::size_t count_;
  bool decoding_, version4_;
  std::array<std::unique_ptr<Context>, 4> contexts_;
  std::uint32_t current_ = 0;
  std::vector<ArithmeticDecoder> decoders_;
  std::vector<char> present_;
  std::vector<ArithmeticEncoder> encoders_;
  std::vector<char> changed_;
};

}  // namespace vola::io::laz
