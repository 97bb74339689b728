// Internal: little-endian byte appending and bounds-checked reading. Every read past
// the end throws FormatError with the file name and the offset.
#pragma once

#include <bit>
#include <cstdint>
#include <cstring>
#include <span>
#include <string>
#include <vector>

#include "vola/error.hpp"

namespace vola {
VOLA_INLINE_NAMESPACE_BEGIN
namespace detail {

static_assert(std::endian::native == std::endian::little,
              "vola reads and writes .vol files in the host's byte order, which must be little-endian");

class ByteWriter {
 public:
  explicit ByteWriter(std::vector<std::uint8_t>& out) : out_(out) {}
  template <class T>
  void put(T value) {
    const auto at = out_.size();
    out_.resize(at + sizeof(T));
    std::memcpy(out_.data() + at, &value, sizeof(T));
  }
  void put_bytes(std::span<const std::uint8_t> bytes) { out_.insert(out_.end(), bytes.begin(), bytes.end()); }
  void pad_to(std::size_t alignment) {
    while (out_.size() % alignment) out_.push_back(0);
  }
  std::size_t size() const noexcept { return out_.size(); }
  std::vector<std::uint8_t>& bytes() noexcept { return out_; }

 private:
  std::vector<std::uint8_t>& out_;
};

class ByteReader {
 public:
  // `base` is the offset of bytes[0] in the file, for error messages.
  ByteReader(std::span<const std::uint8_t> bytes, const std::string& name, std::uint64_t base)
      : bytes_(bytes), name_(name), base_(base) {}
  template <class T>
  T get(const char* what) {
    need(sizeof(T), what);
    T value;
    std::memcpy(&value, bytes_.data() + at_, sizeof(T));
    at_ += sizeof(T);
    return value;
  }
  std::span<const std::uint8_t> take(std::uint64_t n, const char* what) {
    need(n, what);
    auto s = bytes_.subspan(at_, n);
    at_ += n;
    return s;
  }
  void need(std::uint64_t n, const char* what) const {
    if (n > bytes_.size() - at_)
      VOLA_THROW(FormatError(name_, offset(),
                        std::string(what) + " needs " + std::to_string(n) + " bytes but only " +
                            std::to_string(bytes_.size() - at_) + " remain"));
  }
  std::uint64_t offset() const noexcept { return base_ + at_; }
  std::size_t remaining() const noexcept { return bytes_.size() - at_; }
  void skip_padding(std::size_t alignment) {
    const std::size_t pad = (alignment - (base_ + at_) % alignment) % alignment;
    at_ += std::min(pad, remaining());
  }
  [[noreturn]] void fail(const std::string& cause) const { VOLA_THROW(FormatError(name_, offset(), cause)); }
  [[noreturn]] void fail_at(std::uint64_t offset, const std::string& cause) const {
    VOLA_THROW(FormatError(name_, offset, cause));
  }

 private:
  std::span<const std::uint8_t> bytes_;
  const std::string& name_;
  std::uint64_t base_;
  std::size_t at_ = 0;
};

}  // namespace detail
VOLA_INLINE_NAMESPACE_END
}  // namespace vola
