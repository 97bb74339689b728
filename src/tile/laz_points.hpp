// Internal to vola_tile: a LAZ file's chunks as a PointSource (open_las_points picks it).
#pragma once

#include <memory>

#include "vola/io/las.hpp"
#include "vola/tile/point_source.hpp"

namespace vola::tile {

std::unique_ptr<PointSource> open_laz_points(std::unique_ptr<io::LasReader> reader);

}  // namespace vola::tile
