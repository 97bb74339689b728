#include "e57_pages.hpp"

#include <array>
#include <cstring>
#include <filesystem>

#include "vola/error.hpp"
#include "vola/little_endian.hpp"

namespace vola::io {

namespace {

constexpr std::uint64_t kE57PageSize = 1024;
constexpr std::uint64_t kE57PagePayload = kE57PageSize - 4;

std::array<std::uint32_t, 256> crc32c_table() {
  std::array<std::uint32_t, 256> table{};
  for (std::uint32_t i = 0; i < 256; ++i) {
    std::uint32_t c = i;
    for (int k = 0; k < 8; ++k) c = (c & 1) ? (c >> 1) ^ 0x82F63B78u : c >> 1;  // 0x1EDC6F41 reflected
    table[i] = c;
  }
  return table;
}

}  // namespace

std::uint32_t crc32c(const std::uint8_t* data, std::size_t size) {
  static const std::array<std::uint32_t, 256> table = crc32c_table();
  std::uint32_t c = 0xFFFFFFFFu;
  for (std::size_t i = 0; i < size; ++i) c = table[(c ^ data[i]) & 0xFF] ^ (c >> 8);
  return c ^ 0xFFFFFFFFu;
}

E57Pages::E57Pages(std::string path) : path_(std::move(path)), file_(path_, std::ios::binary) {
  if (!file_) throw IoError(path_ + ": cannot open");
  std::error_code error;
  const std::uint64_t size = std::filesystem::file_size(path_, error);
  if (error) throw IoError(path_ + ": cannot read its size: " + error.message());
  std::uint8_t h[48] = {};
  file_.read(reinterpret_cast<char*>(h), sizeof h);
  if (file_.gcount() != static_cast<std::streamsize>(sizeof h) || std::memcmp(h, "ASTM-E57", 8) != 0)
    throw FormatError(path_, 0, "not an E57 file (no \"ASTM-E57\" signature)");
  header_.major = load_le<std::uint32_t>(h + 8);
  header_.minor = load_le<std::uint32_t>(h + 12);
  header_.physical_length = load_le<std::uint64_t>(h + 16);
  header_.xml_physical_offset = load_le<std::uint64_t>(h + 24);
  header_.xml_logical_length = load_le<std::uint64_t>(h + 32);
  header_.page_size = load_le<std::uint64_t>(h + 40);
  if (header_.major != 1)
    throw FormatError(path_, 8,
                      "E57 version " + std::to_string(header_.major) + "." + std::to_string(header_.minor) +
                          " (vola reads version 1)");
  if (header_.page_size != kE57PageSize)
    throw FormatError(path_, 40, "a page size of " + std::to_string(header_.page_size) + " (E57 pages are 1024 bytes)");
  if (header_.physical_length != size || size % kE57PageSize != 0)
    throw FormatError(path_, 16,
                      "the header states " + std::to_string(header_.physical_length) + " bytes; the file holds " +
                          std::to_string(size) + (size % kE57PageSize ? " (not whole pages: cut short?)" : ""));
  logical_length_ = size / kE57PageSize * kE57PagePayload;
  verified_.assign(static_cast<std::size_t>(size / kE57PageSize), false);
  page_.resize(kE57PageSize);
  const std::uint64_t xml = logical_of(header_.xml_physical_offset, "the XML section");
  if (header_.xml_logical_length == 0 || header_.xml_logical_length > logical_length_ - xml)
    throw FormatError(path_, 32,
                      "the XML section (" + std::to_string(header_.xml_logical_length) + " bytes at " +
                          std::to_string(header_.xml_physical_offset) + ") does not lie inside the file");
}

std::uint64_t E57Pages::logical_of(std::uint64_t physical, const char* what) const {
  if (physical >= header_.physical_length || physical % kE57PageSize >= kE57PagePayload)
    throw FormatError(path_, physical,
                      std::string(what) + " starts at byte " + std::to_string(physical) +
                          ", outside the file's data (past its end or in a page checksum)");
  return physical / kE57PageSize * kE57PagePayload + physical % kE57PageSize;
}

void E57Pages::load_page(std::uint64_t page) {
  if (page == loaded_page_) return;
  const std::uint64_t at = page * kE57PageSize;
  file_.clear();
  file_.seekg(static_cast<std::streamoff>(at));
  file_.read(reinterpret_cast<char*>(page_.data()), static_cast<std::streamsize>(kE57PageSize));
  if (file_.gcount() != static_cast<std::streamsize>(kE57PageSize))
    throw IoError(path_ + ": byte " + std::to_string(at) + ": cannot read the page (was the file cut while read?)");
  bytes_read_ += kE57PageSize;
  const auto p = static_cast<std::size_t>(page);
  if (!verified_[p]) {
    const std::uint32_t stored = static_cast<std::uint32_t>(page_[kE57PagePayload]) << 24 |
                                 static_cast<std::uint32_t>(page_[kE57PagePayload + 1]) << 16 |
                                 static_cast<std::uint32_t>(page_[kE57PagePayload + 2]) << 8 |
                                 page_[kE57PagePayload + 3];
    if (stored != crc32c(page_.data(), kE57PagePayload))
      throw FormatError(path_, at + kE57PagePayload,
                        "the checksum of page " + std::to_string(page) + " does not match its bytes (a damaged file)");
    verified_[p] = true;
  }
  loaded_page_ = page;
}

void E57Pages::check_range(std::uint64_t logical, std::uint64_t size) const {
  if (logical > logical_length_ || size > logical_length_ - logical)
    throw FormatError(path_, logical / kE57PagePayload * kE57PageSize + logical % kE57PagePayload,
                      std::to_string(size) + " bytes asked past the end of the file");
}

void E57Pages::read(std::uint64_t logical, std::uint8_t* out, std::size_t size) {
  check_range(logical, size);
  while (size > 0) {
    const std::uint64_t page = logical / kE57PagePayload, offset = logical % kE57PagePayload;
    load_page(page);
    const std::size_t take = static_cast<std::size_t>(std::min<std::uint64_t>(size, kE57PagePayload - offset));
    std::memcpy(out, page_.data() + offset, take);
    out += take;
    size -= take;
    logical += take;
  }
}

std::vector<std::uint8_t> E57Pages::read(std::uint64_t logical, std::size_t size) {
  check_range(logical, size);  // before anything is allocated for a size a file states
  std::vector<std::uint8_t> bytes(size);
  read(logical, bytes.data(), size);
  return bytes;
}

}  // namespace vola::io
