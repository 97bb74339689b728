// One grayscale PNG (8 or 16 bits per pixel) written row by row through libpng, to a
// temporary file renamed into place when finished.
#pragma once

#include <cstdint>
#include <memory>
#include <string>

namespace vola::io {

class PngImage {
 public:
  // Throws vola::IoError when the file cannot be created.
  PngImage(const std::string& path, std::uint32_t width, std::uint32_t height, int bits);
  ~PngImage();
  PngImage(const PngImage&) = delete;
  PngImage& operator=(const PngImage&) = delete;

  // `width` samples (16 bits: native-endian std::uint16_t), top row first.
  void write_row(const void* samples);
  // After the last row; throws vola::IoError if anything failed.
  void finish();

 private:
  struct State;
  std::unique_ptr<State> state_;
};

}  // namespace vola::io
