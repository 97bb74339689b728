#include "plugin.hpp"

#include <dlfcn.h>

#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <map>
#include <mutex>
#include <vector>

namespace vola::plugin {

namespace {

namespace fs = std::filesystem;

struct Loaded {
  void* handle = nullptr;
  std::string error;  // why it could not be loaded, when handle is null
};

// Folders to look in, most specific first; duplicates are harmless.
std::vector<fs::path> search_folders() {
  std::vector<fs::path> folders;
  if (const char* dir = std::getenv("VOLA_PLUGIN_DIR"); dir && *dir) folders.emplace_back(dir);
  // The executable, Python extension or shared library this code was linked into.
  Dl_info self{};
  if (dladdr(reinterpret_cast<void*>(&plugin_symbol), &self) && self.dli_fname) {
    std::error_code error;
    const fs::path object = fs::canonical(self.dli_fname, error);
    if (!error) {
      const fs::path here = object.parent_path();
      folders.push_back(here);
      folders.push_back(here / "vola");
      folders.push_back(here.parent_path() / VOLA_PLUGIN_LIBDIR_NAME / "vola");
    }
  }
  folders.emplace_back(VOLA_PLUGIN_BUILD_DIR);
  folders.emplace_back(VOLA_PLUGIN_INSTALL_DIR);
  return folders;
}

Loaded load(const std::string& name) {
  const std::string file_name = "libvola_" + name + ".so";
  std::string searched;
  for (const fs::path& folder : search_folders()) {
    const fs::path candidate = folder / file_name;
    std::error_code error;
    if (!fs::is_regular_file(candidate, error)) {
      searched += (searched.empty() ? "" : ", ") + folder.string();
      continue;
    }
    void* handle = ::dlopen(candidate.c_str(), RTLD_NOW | RTLD_LOCAL);
    if (!handle) return {nullptr, candidate.string() + " does not load: " + ::dlerror()};
    const auto version = reinterpret_cast<VersionEntry>(::dlsym(handle, kVersionSymbol));
    if (!version || std::strcmp(version(), kPluginVersion) != 0) {
      const std::string found = version ? version() : "none";
      ::dlclose(handle);
      return {nullptr, candidate.string() + " is from another build of vola (version " + found + ", this is " +
                           kPluginVersion + ")"};
    }
    return {handle, {}};
  }
  return {nullptr, file_name + " was not found in " + searched};
}

}  // namespace

void* plugin_symbol(const char* name, const char* symbol, const std::string& purpose) {
  static std::mutex mutex;
  static std::map<std::string, Loaded> plugins;
  std::lock_guard lock(mutex);
  auto it = plugins.find(name);
  if (it == plugins.end()) it = plugins.emplace(name, load(name)).first;
  const Loaded& plugin = it->second;
  const std::string needs = purpose + " needs vola's " + name + " plugin; ";
  if (!plugin.handle) throw IoError(needs + plugin.error + " (reinstall vola, or set VOLA_PLUGIN_DIR to its folder)");
  void* address = ::dlsym(plugin.handle, symbol);
  if (!address) throw IoError(needs + "libvola_" + name + ".so has no " + symbol);
  return address;
}

}  // namespace vola::plugin
