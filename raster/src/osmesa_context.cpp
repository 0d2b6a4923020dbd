// OSMesa: Mesa's off-screen interface. libOSMesa is opened at run time (not linked), so that
// rvr starts and falls back to EGL on systems whose Mesa no longer ships it. Its entry points
// then come only through OSMesaGetProcAddress, never from the library's exported gl* symbols.
// glad's gl.h first, in a block of its own: osmesa.h would otherwise pull in the system
// GL/gl.h, which glad refuses to follow.
#include <glad/gl.h>
// (keeps clang-format from sorting across the line above)
#include <GL/osmesa.h>
#include <dlfcn.h>
#include <fmt/format.h>

#include <cstdlib>
#include <memory>
#include <string>
#include <type_traits>
#include <utility>
#include <vector>

#include "gl_context.h"
#include "rvr/core/expected.h"

namespace rvr {

namespace {

#ifdef RVR_LINK_OSMESA
// A reference the linker must resolve, so libOSMesa is loaded at start-up (see CMakeLists.txt).
[[gnu::used]] void* const kLinkedOSMesa = reinterpret_cast<void*>(&OSMesaGetProcAddress);
#endif

// The four functions we use, looked up once per process.
struct OsMesaLibrary {
  decltype(&OSMesaCreateContextAttribs) create_context = nullptr;
  decltype(&OSMesaMakeCurrent) make_current = nullptr;
  decltype(&OSMesaDestroyContext) destroy_context = nullptr;
  decltype(&OSMesaGetProcAddress) get_proc_address = nullptr;
  std::string error;  // why the library cannot be used, or empty
};

const OsMesaLibrary& osmesa_library() {
  static const OsMesaLibrary library = [] {
    OsMesaLibrary lib;
    // RVR_OSMESA_LIBRARY points at another OSMesa build (or, in tests, at nothing).
    const char* env = std::getenv("RVR_OSMESA_LIBRARY");
    const char* name = env && *env ? env : "libOSMesa.so.8";
    // Never closed: Mesa does not support being unloaded while its threads run.
    void* handle = dlopen(name, RTLD_NOW | RTLD_LOCAL);
    if (!handle) {
      const char* why = dlerror();
      lib.error = fmt::format("cannot load {}: {}", name, why ? why : "unknown reason");
      return lib;
    }
    auto find = [&](auto& fn, const char* symbol) {
      fn = reinterpret_cast<std::remove_reference_t<decltype(fn)>>(dlsym(handle, symbol));
      if (!fn && lib.error.empty()) lib.error = fmt::format("{} has no {}", name, symbol);
    };
    find(lib.create_context, "OSMesaCreateContextAttribs");
    find(lib.make_current, "OSMesaMakeCurrent");
    find(lib.destroy_context, "OSMesaDestroyContext");
    find(lib.get_proc_address, "OSMesaGetProcAddress");
    return lib;
  }();
  return library;
}

class OsMesaContext final : public GlContext {
 public:
  explicit OsMesaContext(const OsMesaLibrary& lib) : lib_(lib) {}
  ~OsMesaContext() override { destroy(); }
  const char* backend() const override { return "osmesa"; }

  Status create() {
    const int attribs[] = {OSMESA_FORMAT,
                           OSMESA_RGBA,
                           OSMESA_DEPTH_BITS,
                           0,  // every render goes to an FBO with its own depth buffer
                           OSMESA_PROFILE,
                           OSMESA_CORE_PROFILE,
                           OSMESA_CONTEXT_MAJOR_VERSION,
                           3,
                           OSMESA_CONTEXT_MINOR_VERSION,
                           3,
                           0};
    context_ = lib_.create_context(attribs, nullptr);
    if (!context_) return internal_error("could not create an OSMesa OpenGL 3.3 core context");
    buffer_.assign(4, 0);  // 1x1 RGBA: OSMesa insists on a default framebuffer
    return finish_creation();
  }

 protected:
  Status bind() override {
    if (!context_) return internal_error("OSMesa context used after destroy()");
    if (!lib_.make_current(context_, buffer_.data(), GL_UNSIGNED_BYTE, 1, 1))
      return internal_error("OSMesaMakeCurrent failed");
    return ok_status();
  }
  void release_native() override {
    if (!context_) return;
    lib_.destroy_context(context_);
    context_ = nullptr;
    buffer_.clear();
  }
  void* proc_address(const char* name) const override {
    return reinterpret_cast<void*>(lib_.get_proc_address(name));
  }

 private:
  const OsMesaLibrary& lib_;
  OSMesaContext context_ = nullptr;
  std::vector<unsigned char> buffer_;
};

}  // namespace

Expected<std::unique_ptr<GlContext>> create_osmesa_context() {
  const OsMesaLibrary& lib = osmesa_library();
  if (!lib.error.empty()) return internal_error(lib.error);
  auto context = std::make_unique<OsMesaContext>(lib);
  RVR_TRY(context->create());
  return std::unique_ptr<GlContext>(std::move(context));
}

}  // namespace rvr
