#include "codec.hpp"

#include <cstring>

#include "vola/error.hpp"

#ifdef VOLA_WITH_ZSTD
#include <zstd.h>
#endif

namespace vola {
VOLA_INLINE_NAMESPACE_BEGIN
namespace detail {

#ifdef VOLA_WITH_ZSTD
bool zstd_available() noexcept { return true; }

std::vector<std::uint8_t> zstd_compress(std::span<const std::uint8_t> raw, int level) {
  std::vector<std::uint8_t> out(ZSTD_compressBound(raw.size()));
  const std::size_t n = ZSTD_compress(out.data(), out.size(), raw.data(), raw.size(), level);
  if (ZSTD_isError(n)) throw Error(std::string("zstd compression failed: ") + ZSTD_getErrorName(n));
  out.resize(n);
  return out;
}

std::vector<std::uint8_t> zstd_decompress(std::span<const std::uint8_t> packed, std::uint64_t raw_size,
                                          const std::string& name, std::uint64_t offset) {
  const unsigned long long declared = ZSTD_getFrameContentSize(packed.data(), packed.size());
  if (declared == ZSTD_CONTENTSIZE_ERROR)
    throw FormatError(name, offset, "compressed data is not a zstd frame");
  if (declared != ZSTD_CONTENTSIZE_UNKNOWN && declared != raw_size)
    throw FormatError(name, offset,
                      "zstd frame holds " + std::to_string(declared) + " bytes, the record promises " +
                          std::to_string(raw_size));
  std::vector<std::uint8_t> out(raw_size);
  const std::size_t n = ZSTD_decompress(out.data(), out.size(), packed.data(), packed.size());
  if (ZSTD_isError(n)) throw FormatError(name, offset, std::string("zstd: ") + ZSTD_getErrorName(n));
  if (n != raw_size)
    throw FormatError(name, offset,
                      "zstd data decompresses to " + std::to_string(n) + " bytes, expected " +
                          std::to_string(raw_size));
  return out;
}
#else
bool zstd_available() noexcept { return false; }

std::vector<std::uint8_t> zstd_compress(std::span<const std::uint8_t>, int) {
  throw Error("this vola was built without zstd (VOLA_WITH_ZSTD=OFF): cannot compress");
}

std::vector<std::uint8_t> zstd_decompress(std::span<const std::uint8_t>, std::uint64_t, const std::string& name,
                                          std::uint64_t offset) {
  throw FormatError(name, offset, "zstd-compressed data, but this vola was built without zstd");
}
#endif

std::vector<std::uint8_t> shuffle_words(std::span<const std::uint64_t> words) {
  const std::size_t n = words.size();
  std::vector<std::uint8_t> out(8 * n);
  for (std::size_t i = 0; i < n; ++i)
    for (std::size_t b = 0; b < 8; ++b) out[b * n + i] = static_cast<std::uint8_t>(words[i] >> (8 * b));
  return out;
}

std::vector<std::uint64_t> unshuffle_words(std::span<const std::uint8_t> bytes) {
  const std::size_t n = bytes.size() / 8;
  std::vector<std::uint64_t> out(n, 0);
  for (std::size_t b = 0; b < 8; ++b)
    for (std::size_t i = 0; i < n; ++i) out[i] |= std::uint64_t{bytes[b * n + i]} << (8 * b);
  return out;
}

}  // namespace detail
VOLA_INLINE_NAMESPACE_END
}  // namespace vola
