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
  if (ZSTD_isError(n)) VOLA_THROW(Error(std::string("zstd compression failed: ") + ZSTD_getErrorName(n)));
  out.resize(n);
  return out;
}

std::vector<std::uint8_t> zstd_decompress(std::span<const std::uint8_t> packed, std::uint64_t raw_size,
                                          const std::string& name, std::uint64_t offset) {
  const unsigned long long declared = ZSTD_getFrameContentSize(packed.data(), packed.size());
  if (declared == ZSTD_CONTENTSIZE_ERROR)
    VOLA_THROW(FormatError(name, offset, "compressed data is not a zstd frame"));
  if (declared != ZSTD_CONTENTSIZE_UNKNOWN && declared != raw_size)
    VOLA_THROW(FormatError(name, offset,
                      "zstd frame holds " + std::to_string(declared) + " bytes, the record promises " +
                          std::to_string(raw_size)));
  std::vector<std::uint8_t> out(raw_size);
  const std::size_t n = ZSTD_decompress(out.data(), out.size(), packed.data(), packed.size());
  if (ZSTD_isError(n)) VOLA_THROW(FormatError(name, offset, std::string("zstd: ") + ZSTD_getErrorName(n)));
  if (n != raw_size)
    VOLA_THROW(FormatError(name, offset,
                      "zstd data decompresses to " + std::to_string(n) + " bytes, expected " +
                          std::to_string(raw_size)));
  return out;
}
#else
bool zstd_available() noexcept { return false; }

std::vector<std::uint8_t> zstd_compress(std::span<const std::uint8_t>, int) {
  VOLA_THROW(Error("this vola was built without zstd (VOLA_WITH_ZSTD=OFF): cannot compress"));
}

std::vector<std::uint8_t> zstd_decompress(std::span<const std::uint8_t>, std::uint64_t, const std::string& name,
                                          std::uint64_t offset) {
  VOLA_THROW(FormatError(name, offset, "zstd-compressed data, but this vola was built without zstd"));
}
#endif

std::vector<std::uint8_t> lanes16_from_words(std::span<const std::uint64_t> words) {
  const std::size_t n = words.size();
  std::vector<std::uint8_t> out(8 * n);
  for (std::size_t i = 0; i < n; ++i)
    for (std::size_t lane = 0; lane < 4; ++lane) {
      const std::size_t at = 2 * (lane * n + i);
      out[at] = static_cast<std::uint8_t>(words[i] >> (16 * lane));
      out[at + 1] = static_cast<std::uint8_t>(words[i] >> (16 * lane + 8));
    }
  return out;
}

void words_from_lanes16(std::span<const std::uint8_t> bytes, std::span<std::uint64_t> words) {
  const std::size_t n = words.size();
  for (std::size_t i = 0; i < n; ++i) {
    std::uint64_t w = 0;
    for (std::size_t lane = 0; lane < 4; ++lane) {
      const std::size_t at = 2 * (lane * n + i);
      w |= (std::uint64_t{bytes[at]} | std::uint64_t{bytes[at + 1]} << 8) << (16 * lane);
    }
    words[i] = w;
  }
}

}  // namespace detail
VOLA_INLINE_NAMESPACE_END
}  // namespace vola
