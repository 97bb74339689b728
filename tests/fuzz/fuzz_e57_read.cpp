// Fuzz entry point of the terrestrial scan readers. The E57 reader (src/io/e57*.cpp: pages and their checksums, the XML
// through expat, compressed-vector sections, data packets, bit-packed bytestreams, poses):
// the input is the file, written to a scratch file of this process, summarised and read
// with its columns and the reference's payload. A mutation almost always breaks a page
// checksum, which the reader refuses first, so the checksums are written again before
// the read (but when the input's last byte is 0xFF: those reach the check itself). Only
// vola::Error may escape; a read cloud has one value per point in every column and no
// more points than its scans' records. The same bytes are also read as a Leica PTX file
// (src/io/ptx.cpp), whose seeds are PTX text: one value per point in every column too.
#include <cstddef>
#include <cstdint>
#include <span>
#include <string>
#include <vector>

#include "../io/e57_test_file.hpp"
#include "fuzz_seeds.hpp"
#include "scratch_file.hpp"
#include "vola/error.hpp"
#include "vola/io/e57.hpp"
#include "vola/io/ptx.hpp"

namespace {

using vola_fuzz::check;

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  std::vector<std::uint8_t> bytes(data, data + size);
  if (size > 0 && data[size - 1] != 0xFF)
    for (std::size_t page = 0; page + 1024 <= bytes.size(); page += 1024) {
      const std::uint32_t crc = vola_io_test::e57_test_crc32c(bytes.data() + page, 1020);
      for (std::size_t k = 0; k < 4; ++k) bytes[page + 1020 + k] = static_cast<std::uint8_t>(crc >> (24 - 8 * k));
    }
  try {
    const std::string ptx = vola_fuzz::scratch_file("ptx", "ptx", std::span(data, size));
    vola::io::InputOptions options;
    options.payload = true;
    const vola::io::Input in = vola::io::read_ptx(ptx, options);
    check(in.cloud.xyz.size() % 3 == 0);
    for (const auto& a : in.cloud.attributes) check(a.values.size() == in.cloud.size());
    check(in.cloud.payload.empty() || in.cloud.payload.size() == in.cloud.size());
  } catch (const vola::Error&) {
  }
  const std::string path = vola_fuzz::scratch_file("e57", "e57", bytes);
  try {
    const vola::io::E57Summary summary = vola::io::e57_summary(path);
    std::uint64_t records = 0;
    for (const auto& scan : summary.scans) records += scan.records;
    vola::io::InputOptions options;
    options.payload = true;
    const vola::io::Input in = vola::io::read_e57(path, options);
    check(in.cloud.xyz.size() % 3 == 0);
    check(in.cloud.size() + in.not_finite <= records);
    for (const auto& a : in.cloud.attributes) check(a.values.size() == in.cloud.size());
    check(in.cloud.payload.empty() || in.cloud.payload.size() == in.cloud.size());
    ++vola_fuzz::stats().parsed;
  } catch (const vola::Error&) {
    ++vola_fuzz::stats().refused;
  }
  return 0;
}
