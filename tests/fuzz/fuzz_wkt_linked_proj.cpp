// The fuzz build has no plugin libraries: vola::geo finds the PROJ entry points linked
// into the fuzz program (src/geo/plugins/proj_crs.cpp) instead of loading libvola_proj.so.
#include <cstring>
#include <string>

#include "../../src/geo/proj_plugin.hpp"
#include "vola/error.hpp"

extern "C" const vola::geo::plugin::ProjEntries* vola_plugin_proj_entries();

namespace vola::plugin {

void* plugin_symbol(const char* name, const char* symbol, const std::string& purpose) {
  if (std::strcmp(name, "proj") != 0 || std::strcmp(symbol, vola::geo::plugin::kProjEntriesSymbol) != 0)
    throw IoError(purpose + ": no plugin " + name + " in the fuzz build");
  return reinterpret_cast<void*>(&vola_plugin_proj_entries);
}

}  // namespace vola::plugin
