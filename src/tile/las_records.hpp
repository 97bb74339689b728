// Internal to vola_tile: LAS point records (from a map or a decoded LAZ chunk) into a
// point source's coordinates and attribute values.
#pragma once

#include <cstdint>
#include <span>
#include <vector>

#include "vola/io/las.hpp"

namespace vola::tile {

// x y z of every record into xyz (replaced).
void las_record_xyz(const io::LasHeader& header, std::span<const std::uint8_t> records, std::vector<double>& xyz);
// x y z, and the values of io::las_attributes(header) straight from the record bytes.
void las_record_points(const io::LasHeader& header, std::span<const std::uint8_t> records, std::vector<double>& xyz,
                       std::vector<std::vector<double>>& values);

}  // namespace vola::tile
