#include "tools/dataset/media_module.hpp"

#include <dlfcn.h>

#include <cstdlib>
#include <mutex>
#include <stdexcept>
#include <vector>

namespace parallax {
namespace {

using EntryPoint = const MediaModule* (*)();

std::vector<std::string> CandidatePaths() {
  std::vector<std::string> paths;
  if (const char* env = std::getenv("PARALLAX_MEDIA_MODULE"); env != nullptr && *env != '\0') {
    paths.emplace_back(env);
  }
  paths.emplace_back(PARALLAX_MEDIA_MODULE_BUILD_PATH);
  paths.emplace_back(PARALLAX_MEDIA_MODULE_INSTALL_PATH);
  return paths;
}

const MediaModule* Load() {
  std::string tried;
  for (const std::string& path : CandidatePaths()) {
    // Never unloaded: the module's objects live until the process ends.
    void* handle = dlopen(path.c_str(), RTLD_NOW | RTLD_LOCAL);
    if (handle == nullptr) {
      tried += "\n  " + path + ": " + dlerror();
      continue;
    }
    auto* entry = reinterpret_cast<EntryPoint>(dlsym(handle, "ParallaxMediaModule"));
    if (entry == nullptr) {
      tried += "\n  " + path + ": no ParallaxMediaModule";
      continue;
    }
    return entry();
  }
  throw std::runtime_error(
      "the media module (videos and images other than PNG/JPEG) could not be loaded; tried:" +
      tried);
}

}  // namespace

const MediaModule& LoadMediaModule() {
  static std::once_flag once;
  static const MediaModule* module = nullptr;
  static std::string error;
  std::call_once(once, [] {
    try {
      module = Load();
    } catch (const std::exception& e) {
      error = e.what();
    }
  });
  if (module == nullptr) throw std::runtime_error(error);
  return *module;
}

}  // namespace parallax
