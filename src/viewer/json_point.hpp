// A point as the viewer's JSON replies write it: [x, y, z].
#pragma once

#include <nlohmann/json.hpp>

#include "vola/frame.hpp"

namespace vola::viewer {

inline nlohmann::json json_point(const Point& p) { return nlohmann::json::array({p[0], p[1], p[2]}); }

}  // namespace vola::viewer
