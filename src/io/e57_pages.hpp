// The physical layer of an E57 file (ASTM E2807): pages of `page_size` bytes whose last
// four hold the CRC-32C of the rest, so that a file's logical bytes are every page's
// first page_size - 4. Written from the standard; no E57 library is packaged for Debian 12.
#pragma once

#include <cstdint>
#include <fstream>
#include <string>
#include <vector>

namespace vola::io {

// The 48-byte header at the start of the file (not paged logically: its bytes are the
// first page's first 48).
struct E57Header {
  std::uint32_t major = 0, minor = 0;
  std::uint64_t physical_length = 0;
  std::uint64_t xml_physical_offset = 0;
  std::uint64_t xml_logical_length = 0;
  std::uint64_t page_size = 0;
};

class E57Pages {
 public:
  // Opens the file and checks its header: the signature "ASTM-E57", major version 1, a
  // page size of 1024 (the only one the standard allows), the stated length equal to the
  // file's and the XML inside it. Throws IoError or FormatError naming the file.
  explicit E57Pages(std::string path);

  const std::string& path() const noexcept { return path_; }
  const E57Header& header() const noexcept { return header_; }
  std::uint64_t logical_length() const noexcept { return logical_length_; }
  // The logical offset of a physical one (an offset inside a page's checksum is an error
  // naming `what`).
  std::uint64_t logical_of(std::uint64_t physical, const char* what) const;

  // `size` logical bytes from `logical`, each page's checksum verified the first time the
  // page is read. Throws FormatError naming the page's byte offset when a checksum does not
  // match or the bytes run past the file.
  void read(std::uint64_t logical, std::uint8_t* out, std::size_t size);
  std::vector<std::uint8_t> read(std::uint64_t logical, std::size_t size);

  // Throws FormatError when `size` logical bytes from `logical` are not all in the file.
  void check_range(std::uint64_t logical, std::uint64_t size) const;

  // Bytes read from the file so far (pages, checksums included).
  std::uint64_t bytes_read() const noexcept { return bytes_read_; }

 private:
  void load_page(std::uint64_t page);

  std::string path_;
  std::ifstream file_;
  E57Header header_;
  std::uint64_t logical_length_ = 0;
  std::uint64_t loaded_page_ = ~std::uint64_t{0};
  std::vector<std::uint8_t> page_;
  std::vector<bool> verified_;  // one flag a page
  std::uint64_t bytes_read_ = 0;
};

// CRC-32C (Castagnoli, reflected, initial and final xor all ones), as E57 pages carry it.
std::uint32_t crc32c(const std::uint8_t* data, std::size_t size);

}  // namespace vola::io
