// The fuzz build does not bundle the viewer's page (npm and esbuild): the routes serve
// these stand-ins instead of src/viewer's generated web_assets.cpp.
#include "web_assets.hpp"

namespace vola::viewer {

std::string_view index_html() noexcept { return "<!doctype html><title>vola view</title><script src=\"viewer.js\"></script>"; }
std::string_view viewer_js() noexcept { return "console.log('vola view');"; }

}  // namespace vola::viewer
