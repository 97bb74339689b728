#include "vola/io/png_image.hpp"

#include <png.h>

#include <csetjmp>

#include "vola/output_file.hpp"
#include "vola/error.hpp"

namespace vola::io {

// libpng reports errors by longjmp to the last setjmp: every call into it below is
// guarded by one in the calling frame, which holds no object needing destruction
// between the setjmp and the call. The C++ exception is thrown after the jump, in our
// own frame, never through libpng's C frames.
struct PngImage::State {
  explicit State(const std::string& path) : file(path) {}
  OutputFile file;
  png_structp png = nullptr;
  png_infop info = nullptr;
  std::string message;  // libpng's error text
  ~State() { png_destroy_write_struct(&png, &info); }

  [[noreturn]] void fail() const { throw IoError(file.path() + ": PNG: " + (message.empty() ? "write failed" : message)); }
};

namespace {
void on_error(png_structp png, png_const_charp message) {
  auto* state = static_cast<std::string*>(png_get_error_ptr(png));
  *state = message ? message : "error";
  png_longjmp(png, 1);
}
void on_warning(png_structp, png_const_charp) {}
}  // namespace

PngImage::PngImage(const std::string& path, std::uint32_t width, std::uint32_t height, int bits, PngColour colour)
    : state_(std::make_unique<State>(path)) {
  State& s = *state_;
  s.png = png_create_write_struct(PNG_LIBPNG_VER_STRING, &s.message, on_error, on_warning);
  if (!s.png) throw IoError(path + ": PNG: cannot create a libpng writer");
  s.info = png_create_info_struct(s.png);
  if (!s.info) throw IoError(path + ": PNG: cannot create a libpng info structure");
  if (setjmp(png_jmpbuf(s.png))) s.fail();
  png_init_io(s.png, s.file.stream());
  png_set_IHDR(s.png, s.info, width, height, bits, colour == PngColour::rgb ? PNG_COLOR_TYPE_RGB : PNG_COLOR_TYPE_GRAY,
               PNG_INTERLACE_NONE, PNG_COMPRESSION_TYPE_DEFAULT, PNG_FILTER_TYPE_DEFAULT);
  // Two-level slices compress best unfiltered; height maps and pictures gain from the filters.
  if (bits == 8 && colour == PngColour::grey) png_set_filter(s.png, PNG_FILTER_TYPE_BASE, PNG_FILTER_NONE);
  png_write_info(s.png, s.info);
  // PNG stores 16-bit samples big-endian.
  if (bits == 16) png_set_swap(s.png);
}

PngImage::~PngImage() = default;

void PngImage::write_row(const void* samples) {
  State& s = *state_;
  if (setjmp(png_jmpbuf(s.png))) s.fail();
  png_write_row(s.png, static_cast<png_const_bytep>(samples));
}

void PngImage::finish() {
  State& s = *state_;
  if (setjmp(png_jmpbuf(s.png))) s.fail();
  png_write_end(s.png, nullptr);
  s.file.commit();
}

void write_png(const std::string& path, std::uint32_t width, std::uint32_t height, const std::uint8_t* samples,
               int bits, PngColour colour) {
  PngImage image(path, width, height, bits, colour);
  const std::size_t row_bytes = std::size_t{width} * (colour == PngColour::rgb ? 3 : 1) * (bits == 16 ? 2 : 1);
  for (std::uint32_t y = 0; y < height; ++y) image.write_row(samples + y * row_bytes);
  image.finish();
}

}  // namespace vola::io
