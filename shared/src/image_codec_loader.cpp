#include "image_codec_loader.h"

#include <dlfcn.h>
#include <unistd.h>

#include <climits>
#include <mutex>
#include <string>

namespace rvr {
namespace {

constexpr const char* kModule = "librvr_image_codec.so";

// The folder of the running executable, where the build puts the module beside it.
std::string executable_folder() {
  char path[PATH_MAX];
  const ssize_t n = ::readlink("/proc/self/exe", path, sizeof(path) - 1);
  if (n <= 0) return {};
  std::string exe(path, size_t(n));
  const auto slash = exe.rfind('/');
  return slash == std::string::npos ? std::string() : exe.substr(0, slash);
}

struct Loaded {
  const rvr_image_codec* codec = nullptr;
  std::string error;
};

Loaded load() {
  Loaded result;
  std::string tried;
  void* handle = nullptr;
  const std::string folder = executable_folder();
  if (!folder.empty()) {
    const std::string beside = folder + "/" + kModule;
    handle = ::dlopen(beside.c_str(), RTLD_NOW | RTLD_LOCAL);
    if (!handle) tried = ::dlerror();
  }
  if (!handle) {
    handle = ::dlopen(kModule, RTLD_NOW | RTLD_LOCAL);
    if (!handle) tried += (tried.empty() ? "" : "; ") + std::string(::dlerror());
  }
  if (!handle) {
    result.error = "cannot load the image library " + std::string(kModule) + ": " + tried;
    return result;
  }
  using Get = const rvr_image_codec* (*)();
  auto get = reinterpret_cast<Get>(::dlsym(handle, "rvr_image_codec_get"));
  const rvr_image_codec* codec = get ? get() : nullptr;
  if (!codec || codec->abi_version != RVR_IMAGE_CODEC_ABI_VERSION) {
    result.error = std::string(kModule) + " is not this build's image library (interface " +
                   (codec ? std::to_string(codec->abi_version) : std::string("missing")) +
                   ", expected " + std::to_string(RVR_IMAGE_CODEC_ABI_VERSION) + ")";
    return result;
  }
  result.codec = codec;  // kept loaded for the life of the process
  return result;
}

}  // namespace

Expected<const rvr_image_codec*> image_codec() {
  static std::once_flag once;
  static Loaded loaded;
  std::call_once(once, [] { loaded = load(); });
  if (!loaded.codec) return internal_error(loaded.error);
  return loaded.codec;
}

}  // namespace rvr
