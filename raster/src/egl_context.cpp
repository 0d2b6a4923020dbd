// EGL surfaceless (EGL_PLATFORM_SURFACELESS_MESA): a GL context with no window system and no
// surface at all; everything is drawn into FBOs. libEGL (GLVND) is opened at run time like
// libOSMesa, so neither is a link dependency; GL entry points come from eglGetProcAddress
// (core functions included: EGL_KHR_get_all_proc_addresses, which Mesa has).
//
// glad's EGL loader is not used: before a display exists it detects EGL 1.0 and leaves
// eglGetPlatformDisplay unloaded, and it probes eglGetDisplay(EGL_DEFAULT_DISPLAY), which
// makes an X11 display object. We need ten functions, looked up with dlsym.
#include <EGL/egl.h>
#include <EGL/eglext.h>
#include <EGL/eglplatform.h>
#include <dlfcn.h>
#include <fmt/format.h>

#include <memory>
#include <string>
#include <type_traits>
#include <utility>

#include "gl_context.h"
#include "rvr/core/expected.h"

namespace rvr {

namespace {

struct EglLibrary {
  PFNEGLGETERRORPROC GetError = nullptr;
  PFNEGLQUERYSTRINGPROC QueryString = nullptr;
  PFNEGLGETPLATFORMDISPLAYPROC GetPlatformDisplay = nullptr;
  PFNEGLINITIALIZEPROC Initialize = nullptr;
  PFNEGLBINDAPIPROC BindAPI = nullptr;
  PFNEGLCHOOSECONFIGPROC ChooseConfig = nullptr;
  PFNEGLCREATECONTEXTPROC CreateContext = nullptr;
  PFNEGLMAKECURRENTPROC MakeCurrent = nullptr;
  PFNEGLGETCURRENTCONTEXTPROC GetCurrentContext = nullptr;
  PFNEGLDESTROYCONTEXTPROC DestroyContext = nullptr;
  PFNEGLGETPROCADDRESSPROC GetProcAddress = nullptr;
};

// The display is per process and stays initialised: eglTerminate would pull it from under
// every other context of the process.
struct EglDisplay {
  EglLibrary egl;
  EGLDisplay display = EGL_NO_DISPLAY;
  std::string error;  // why EGL cannot be used, or empty
};

std::string egl_error_name(EGLint code) {
  switch (code) {
    case EGL_NOT_INITIALIZED:
      return "EGL_NOT_INITIALIZED";
    case EGL_BAD_ALLOC:
      return "EGL_BAD_ALLOC";
    case EGL_BAD_ATTRIBUTE:
      return "EGL_BAD_ATTRIBUTE";
    case EGL_BAD_CONFIG:
      return "EGL_BAD_CONFIG";
    case EGL_BAD_CONTEXT:
      return "EGL_BAD_CONTEXT";
    case EGL_BAD_DISPLAY:
      return "EGL_BAD_DISPLAY";
    case EGL_BAD_MATCH:
      return "EGL_BAD_MATCH";
    case EGL_BAD_PARAMETER:
      return "EGL_BAD_PARAMETER";
    default:
      return fmt::format("EGL error 0x{:04x}", unsigned(code));
  }
}

const EglDisplay& egl_display() {
  static const EglDisplay result = [] {
    EglDisplay d;
    EglLibrary& egl = d.egl;
    // Never closed: Mesa does not support being unloaded while its threads run.
    void* handle = dlopen("libEGL.so.1", RTLD_NOW | RTLD_LOCAL);
    if (!handle) {
      const char* why = dlerror();
      d.error = fmt::format("cannot load libEGL.so.1: {}", why ? why : "unknown reason");
      return d;
    }
    auto find = [&](auto& fn, const char* symbol) {
      fn = reinterpret_cast<std::remove_reference_t<decltype(fn)>>(dlsym(handle, symbol));
      if (!fn && d.error.empty()) d.error = fmt::format("libEGL.so.1 has no {}", symbol);
    };
    find(egl.GetError, "eglGetError");
    find(egl.QueryString, "eglQueryString");
    find(egl.GetPlatformDisplay, "eglGetPlatformDisplay");
    find(egl.Initialize, "eglInitialize");
    find(egl.BindAPI, "eglBindAPI");
    find(egl.ChooseConfig, "eglChooseConfig");
    find(egl.CreateContext, "eglCreateContext");
    find(egl.MakeCurrent, "eglMakeCurrent");
    find(egl.GetCurrentContext, "eglGetCurrentContext");
    find(egl.DestroyContext, "eglDestroyContext");
    find(egl.GetProcAddress, "eglGetProcAddress");
    if (!d.error.empty()) return d;
    auto last_error = [&] { return egl_error_name(egl.GetError()); };

    const char* client_extensions = egl.QueryString(EGL_NO_DISPLAY, EGL_EXTENSIONS);
    if (!client_extensions ||
        std::string(client_extensions).find("EGL_MESA_platform_surfaceless") == std::string::npos) {
      d.error = "EGL has no EGL_MESA_platform_surfaceless";
      return d;
    }
    EGLDisplay display = egl.GetPlatformDisplay(
        EGL_PLATFORM_SURFACELESS_MESA, reinterpret_cast<void*>(EGL_DEFAULT_DISPLAY), nullptr);
    EGLint major = 0, minor = 0;
    if (display == EGL_NO_DISPLAY || !egl.Initialize(display, &major, &minor)) {
      d.error = fmt::format("no EGL surfaceless display ({})", last_error());
      return d;
    }
    const char* extensions = egl.QueryString(display, EGL_EXTENSIONS);
    if (!extensions ||
        std::string(extensions).find("EGL_KHR_surfaceless_context") == std::string::npos) {
      d.error = "the EGL display has no EGL_KHR_surfaceless_context";
      return d;
    }
    d.display = display;
    return d;
  }();
  return result;
}

class EglContext final : public GlContext {
 public:
  EglContext(const EglLibrary& egl, EGLDisplay display) : egl_(egl), display_(display) {}
  ~EglContext() override { destroy(); }
  const char* backend() const override { return "egl"; }

  Status create() {
    auto last_egl_error = [&] { return egl_error_name(egl_.GetError()); };
    if (!egl_.BindAPI(EGL_OPENGL_API))
      return internal_error(
          fmt::format("egl_.BindAPI(EGL_OPENGL_API) failed ({})", last_egl_error()));
    const EGLint config_attribs[] = {EGL_RENDERABLE_TYPE, EGL_OPENGL_BIT, EGL_SURFACE_TYPE, 0,
                                     EGL_NONE};
    EGLConfig config = nullptr;
    EGLint count = 0;
    if (!egl_.ChooseConfig(display_, config_attribs, &config, 1, &count) || count < 1)
      return internal_error(fmt::format("no EGL config for desktop OpenGL ({})", last_egl_error()));
    const EGLint context_attribs[] = {EGL_CONTEXT_MAJOR_VERSION,
                                      3,
                                      EGL_CONTEXT_MINOR_VERSION,
                                      3,
                                      EGL_CONTEXT_OPENGL_PROFILE_MASK,
                                      EGL_CONTEXT_OPENGL_CORE_PROFILE_BIT,
                                      EGL_NONE};
    context_ = egl_.CreateContext(display_, config, EGL_NO_CONTEXT, context_attribs);
    if (context_ == EGL_NO_CONTEXT)
      return internal_error(
          fmt::format("could not create an EGL OpenGL 3.3 core context ({})", last_egl_error()));
    return finish_creation();
  }

 protected:
  Status bind() override {
    auto last_egl_error = [&] { return egl_error_name(egl_.GetError()); };
    if (context_ == EGL_NO_CONTEXT) return internal_error("EGL context used after destroy()");
    if (!egl_.MakeCurrent(display_, EGL_NO_SURFACE, EGL_NO_SURFACE, context_))
      return internal_error(fmt::format("eglMakeCurrent failed ({})", last_egl_error()));
    return ok_status();
  }
  void release_native() override {
    if (context_ == EGL_NO_CONTEXT) return;
    if (egl_.GetCurrentContext() == context_)
      egl_.MakeCurrent(display_, EGL_NO_SURFACE, EGL_NO_SURFACE, EGL_NO_CONTEXT);
    egl_.DestroyContext(display_, context_);
    context_ = EGL_NO_CONTEXT;
  }
  void* proc_address(const char* name) const override {
    return reinterpret_cast<void*>(egl_.GetProcAddress(name));
  }

 private:
  const EglLibrary& egl_;
  EGLDisplay display_;
  EGLContext context_ = EGL_NO_CONTEXT;
};

}  // namespace

Expected<std::unique_ptr<GlContext>> create_egl_context() {
  const EglDisplay& d = egl_display();
  if (!d.error.empty()) return internal_error("EGL surfaceless: " + d.error);
  auto context = std::make_unique<EglContext>(d.egl, d.display);
  RVR_TRY(context->create());
  return std::unique_ptr<GlContext>(std::move(context));
}

}  // namespace rvr
