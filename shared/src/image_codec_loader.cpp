#include "image_codec_loader.h"

#include <dlfcn.h>
#include <unistd.h>

#include <climits>
#include <initializer_list>
#include <mutex>
#include <string>

namespace rvr {
namespace {

// The folder of the running executable, where the build puts the module beside it.
std::string executable_folder() {
  char path[PATH_MAX];
  const ssize_t n = ::readlink("/proc/self/exe", path, sizeof(path) - 1);
  if (n <= 0) return {};
  std::string exe(path, size_t(n));
  const auto slash = exe.rfind('/');
  return slash == std::string::npos ? std::string() : exe.substr(0, slash);
}

// The folder of the shared object holding this code when it is not the executable (the Python
// module), where its build puts the modules beside it too; empty otherwise.
std::string library_folder() {
  Dl_info info{};
  if (!::dladdr(reinterpret_cast<const void*>(&executable_folder), &info) || !info.dli_fname)
    return {};
  const std::string object(info.dli_fname);
  const auto slash = object.rfind('/');
  return slash == std::string::npos ? std::string() : object.substr(0, slash);
}

template <class Table>
struct Loaded {
  const Table* table = nullptr;
  std::string error;
};

// dlopens `module` (beside the executable first, then beside the shared object holding this
// code) and takes its table from `symbol`, which must carry `abi_version`.
template <class Table>
Loaded<Table> load(const char* module, const char* symbol, int abi_version) {
  Loaded<Table> result;
  std::string tried;
  void* handle = nullptr;
  const std::string executable = executable_folder(), library = library_folder();
  for (const std::string& folder : {executable, library == executable ? std::string() : library}) {
    if (handle || folder.empty()) continue;
    const std::string beside = folder + "/" + module;
    handle = ::dlopen(beside.c_str(), RTLD_NOW | RTLD_LOCAL);
    if (!handle) tried += (tried.empty() ? "" : "; ") + std::string(::dlerror());
  }
  if (!handle) {
    handle = ::dlopen(module, RTLD_NOW | RTLD_LOCAL);
    if (!handle) tried += (tried.empty() ? "" : "; ") + std::string(::dlerror());
  }
  if (!handle) {
    result.error = "cannot load the image library " + std::string(module) + ": " + tried;
    return result;
  }
  using Get = const Table* (*)();
  auto get = reinterpret_cast<Get>(::dlsym(handle, symbol));
  const Table* table = get ? get() : nullptr;
  if (!table || table->abi_version != abi_version) {
    result.error = std::string(module) + " is not this build's image library (interface " +
                   (table ? std::to_string(table->abi_version) : std::string("missing")) +
                   ", expected " + std::to_string(abi_version) + ")";
    return result;
  }
  result.table = table;  // kept loaded for the life of the process
  return result;
}

}  // namespace

Expected<const rvr_image_codec*> image_codec() {
  static std::once_flag once;
  static Loaded<rvr_image_codec> loaded;
  std::call_once(once, [] {
    loaded = load<rvr_image_codec>("librvr_image_codec.so", "rvr_image_codec_get",
                                   RVR_IMAGE_CODEC_ABI_VERSION);
  });
  if (!loaded.table) return internal_error(loaded.error);
  return loaded.table;
}

Expected<const rvr_image_writer*> image_writer() {
  static std::once_flag once;
  static Loaded<rvr_image_writer> loaded;
  std::call_once(once, [] {
    loaded = load<rvr_image_writer>("librvr_image_writer.so", "rvr_image_writer_get",
                                    RVR_IMAGE_WRITER_ABI_VERSION);
  });
  if (!loaded.table) return internal_error(loaded.error);
  return loaded.table;
}

}  // namespace rvr
