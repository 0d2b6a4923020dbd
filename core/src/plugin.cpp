#include "rvr/core/plugin.h"

#include <dlfcn.h>
#include <stdlib.h>

#include <climits>
#include <initializer_list>

namespace rvr {
namespace {

// The folder of `file`, as an absolute path without symbolic links (so that two spellings of
// one folder compare equal); empty when it cannot be told.
std::string folder_of(const std::string& file) {
  char resolved[PATH_MAX];
  if (!::realpath(file.c_str(), resolved)) return {};
  const std::string path(resolved);
  const auto slash = path.rfind('/');
  return slash == std::string::npos ? std::string() : path.substr(0, slash);
}

// The folder of the running executable, where the build puts the plugins beside it.
std::string executable_folder() {
  return folder_of("/proc/self/exe");
}

}  // namespace

std::string rvr_code_folder() {
  Dl_info info{};
  if (!::dladdr(reinterpret_cast<const void*>(&executable_folder), &info) || !info.dli_fname)
    return executable_folder();
  return folder_of(info.dli_fname);
}

Expected<void*> open_plugin(const char* module, const char* symbol, const std::string& what) {
  std::string tried;
  void* handle = nullptr;
  const std::string executable = executable_folder(), code = rvr_code_folder();
  for (const std::string& folder : {executable, code == executable ? std::string() : code}) {
    if (handle || folder.empty()) continue;
    const std::string beside = folder + "/" + module;
    handle = ::dlopen(beside.c_str(), RTLD_NOW | RTLD_LOCAL);
    if (!handle) tried += (tried.empty() ? "" : "; ") + std::string(::dlerror());
  }
  if (!handle) {
    handle = ::dlopen(module, RTLD_NOW | RTLD_LOCAL);
    if (!handle) tried += (tried.empty() ? "" : "; ") + std::string(::dlerror());
  }
  if (!handle) return internal_error("cannot load " + what + " " + module + ": " + tried);
  void* function = ::dlsym(handle, symbol);
  if (!function)
    return internal_error(std::string(module) + " is not this build's " + what + " (no " + symbol +
                          ")");
  return function;
}

}  // namespace rvr
