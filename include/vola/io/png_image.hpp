// The one PNG writer of the library: an image written row by row through libpng (grey or
// RGB, 8 or 16 bits per sample), to a temporary file renamed into place when finished, so
// that a failed write never leaves a cut file under the final name. Exports, renders,
// SLAM frames and plots all write through it.
#pragma once

#include <cstdint>
#include <memory>
#include <string>

namespace vola::io {

enum class PngColour { grey, rgb };

class PngImage {
 public:
  // bits: 8 or 16 per sample. Throws vola::IoError when the file cannot be created.
  PngImage(const std::string& path, std::uint32_t width, std::uint32_t height, int bits,
           PngColour colour = PngColour::grey);
  ~PngImage();
  PngImage(const PngImage&) = delete;
  PngImage& operator=(const PngImage&) = delete;

  // One row of `width` pixels (1 or 3 samples each; 16 bits: native-endian
  // std::uint16_t), top row first.
  void write_row(const void* samples);
  // After the last row; throws vola::IoError if anything failed.
  void finish();

 private:
  struct State;
  std::unique_ptr<State> state_;
};

// A whole image at once: `samples` holds height rows of width pixels.
void write_png(const std::string& path, std::uint32_t width, std::uint32_t height, const std::uint8_t* samples,
               int bits, PngColour colour);

}  // namespace vola::io
