#include "ir_plot.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>

#include "png_writer.hpp"

namespace vola::cli {

namespace {

constexpr double kRangeDb = 60.0;
constexpr std::uint32_t kLeft = 44, kRight = 34, kTop = 10, kBottom = 24;
constexpr int kScale = 2;  // font pixels per glyph pixel

struct Rgb {
  std::uint8_t r, g, b;
};
constexpr Rgb kWhite{255, 255, 255}, kGrid{225, 225, 225}, kAxis{40, 40, 40}, kBlue{30, 90, 200}, kRed{220, 30, 30};

// 3x5 glyphs, one row per 3 bits (top row first, leftmost pixel = bit 2).
std::array<std::uint8_t, 5> glyph(char c) {
  switch (c) {
    case '0': return {7, 5, 5, 5, 7};
    case '1': return {2, 6, 2, 2, 7};
    case '2': return {7, 1, 7, 4, 7};
    case '3': return {7, 1, 7, 1, 7};
    case '4': return {5, 5, 7, 1, 1};
    case '5': return {7, 4, 7, 1, 7};
    case '6': return {7, 4, 7, 5, 7};
    case '7': return {7, 1, 1, 1, 1};
    case '8': return {7, 5, 7, 5, 7};
    case '9': return {7, 5, 7, 1, 7};
    case '-': return {0, 0, 7, 0, 0};
    case '.': return {0, 0, 0, 0, 2};
    case 'm': return {0, 0, 7, 7, 5};
    case 's': return {0, 3, 6, 1, 6};
    case 'd': return {1, 1, 7, 5, 7};
    case 'B': return {6, 5, 6, 5, 6};
    default: return {0, 0, 0, 0, 0};
  }
}

class Canvas {
 public:
  Canvas(std::uint32_t w, std::uint32_t h) : w_(w), h_(h), rgb_(std::size_t{w} * h * 3, 255) {}
  void set(std::int64_t x, std::int64_t y, Rgb c) {
    if (x < 0 || y < 0 || x >= w_ || y >= h_) return;
    const std::size_t i = (static_cast<std::size_t>(y) * w_ + static_cast<std::size_t>(x)) * 3;
    rgb_[i] = c.r;
    rgb_[i + 1] = c.g;
    rgb_[i + 2] = c.b;
  }
  void vline(std::int64_t x, std::int64_t y0, std::int64_t y1, Rgb c) {
    for (std::int64_t y = std::min(y0, y1); y <= std::max(y0, y1); ++y) set(x, y, c);
  }
  void hline(std::int64_t x0, std::int64_t x1, std::int64_t y, Rgb c) {
    for (std::int64_t x = std::min(x0, x1); x <= std::max(x0, x1); ++x) set(x, y, c);
  }
  // Text with its top-left corner at (x, y).
  void text(std::int64_t x, std::int64_t y, const std::string& s, Rgb c) {
    for (const char ch : s) {
      const auto g = glyph(ch);
      for (int row = 0; row < 5; ++row)
        for (int col = 0; col < 3; ++col)
          if (g[row] & (4 >> col))
            for (int dy = 0; dy < kScale; ++dy)
              for (int dx = 0; dx < kScale; ++dx) set(x + col * kScale + dx, y + row * kScale + dy, c);
      x += 4 * kScale;
    }
  }
  static std::int64_t text_width(const std::string& s) { return static_cast<std::int64_t>(s.size()) * 4 * kScale - kScale; }
  std::vector<std::uint8_t> take() { return std::move(rgb_); }

 private:
  std::int64_t w_, h_;
  std::vector<std::uint8_t> rgb_;
};

// A tick step of 1, 2 or 5 times a power of ten giving at most `max_ticks` ticks.
double tick_step(double span, int max_ticks) {
  const double raw = span / max_ticks;
  const double p = std::pow(10.0, std::floor(std::log10(raw)));
  for (const double m : {1.0, 2.0, 5.0, 10.0})
    if (m * p >= raw) return m * p;
  return 10.0 * p;
}

std::string number(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%g", v);
  return buf;
}

}  // namespace

std::vector<std::uint8_t> plot_responses(const std::vector<PlotPanel>& panels, double sample_rate, std::uint32_t width,
                                         std::uint32_t panel_height, std::uint32_t& height) {
  height = panel_height * static_cast<std::uint32_t>(std::max<std::size_t>(panels.size(), 1));
  Canvas canvas(width, height);
  std::size_t longest = 1;
  for (const auto& p : panels) longest = std::max(longest, p.response.size());
  const double duration_ms = static_cast<double>(longest) / sample_rate * 1000.0;
  const std::int64_t plot_w = static_cast<std::int64_t>(width) - kLeft - kRight;
  const std::int64_t plot_h = static_cast<std::int64_t>(panel_height) - kTop - kBottom;
  const double x_step = tick_step(duration_ms, 10);
  for (std::size_t i = 0; i < panels.size(); ++i) {
    const PlotPanel& panel = panels[i];
    const std::int64_t top = static_cast<std::int64_t>(i * panel_height) + kTop, bottom = top + plot_h;
    auto x_of_ms = [&](double ms) { return kLeft + static_cast<std::int64_t>(std::lround(ms / duration_ms * static_cast<double>(plot_w - 1))); };
    auto y_of_db = [&](double db) { return top + static_cast<std::int64_t>(std::lround(-db / kRangeDb * static_cast<double>(plot_h))); };
    // Grid and labels.
    for (double db = 0; db >= -kRangeDb; db -= 10) {
      canvas.hline(kLeft, kLeft + plot_w - 1, y_of_db(db), kGrid);
      const std::string label = number(db);
      canvas.text(kLeft - 6 - Canvas::text_width(label), y_of_db(db) - 5, label, kAxis);
    }
    canvas.text(4, top + plot_h / 2 + 8, "dB", kAxis);
    for (double ms = 0; ms <= duration_ms + 1e-9; ms += x_step) {
      canvas.vline(x_of_ms(ms), top, bottom, kGrid);
      const std::string label = number(ms);
      canvas.text(x_of_ms(ms) - Canvas::text_width(label) / 2, bottom + 5, label, kAxis);
    }
    canvas.text(kLeft + plot_w + 8, bottom + 5, "ms", kAxis);
    canvas.hline(kLeft, kLeft + plot_w - 1, bottom, kAxis);
    canvas.vline(kLeft, top, bottom, kAxis);
    // Bars: per pixel column the strongest sample it covers, as dB below the panel's peak.
    double peak = 0.0;
    for (const double v : panel.response) peak = std::max(peak, std::abs(v));
    if (peak == 0.0) continue;
    std::vector<double> column(static_cast<std::size_t>(plot_w), 0.0);
    std::vector<bool> direct(static_cast<std::size_t>(plot_w), false);
    for (std::size_t n = 0; n < panel.response.size(); ++n) {
      const double ms = static_cast<double>(n) / sample_rate * 1000.0;
      const auto x = static_cast<std::size_t>(x_of_ms(ms) - kLeft);
      column[x] = std::max(column[x], std::abs(panel.response[n]));
      if (static_cast<std::int64_t>(n) == panel.direct_sample && panel.response[n] != 0.0) direct[x] = true;
    }
    for (std::size_t x = 0; x < column.size(); ++x) {
      if (column[x] == 0.0) continue;
      const double db = std::max(20.0 * std::log10(column[x] / peak), -kRangeDb);
      if (db <= -kRangeDb) continue;
      canvas.vline(kLeft + static_cast<std::int64_t>(x), y_of_db(db), bottom - 1, direct[x] ? kRed : kBlue);
    }
  }
  return canvas.take();
}

void write_response_plot(const std::string& path, const std::vector<PlotPanel>& panels, double sample_rate) {
  std::uint32_t height = 0;
  const auto rgb = plot_responses(panels, sample_rate, 1200, 320, height);
  write_png_rgb8(path, 1200, height, rgb);
}

}  // namespace vola::cli
