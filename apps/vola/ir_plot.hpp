// A picture of impulse responses for `vola sonify --plot`: one panel per response, level
// in dB relative to the response's peak (0 to -60 dB) against time in ms, with the direct
// arrival in red, grid lines, and tick labels in a built-in 3x5 pixel font.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

namespace vola::cli {

struct PlotPanel {
  std::vector<double> response;  // the impulse response, sample 0 = time 0
  std::int64_t direct_sample = -1;  // drawn in red; -1 = none (blocked)
};

// The RGB pixels (row 0 at the top) of the panels stacked vertically, `width` wide.
std::vector<std::uint8_t> plot_responses(const std::vector<PlotPanel>& panels, double sample_rate, std::uint32_t width,
                                         std::uint32_t panel_height, std::uint32_t& height);
// plot_responses written as a PNG. Throws IoError when the file cannot be written.
void write_response_plot(const std::string& path, const std::vector<PlotPanel>& panels, double sample_rate);

}  // namespace vola::cli
