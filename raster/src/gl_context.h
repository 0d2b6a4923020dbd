// A headless OpenGL 3.3 core context. Rendering goes into FBOs, so the context only has to
// exist and be current. GlContext is all the renderer sees; two back ends make one:
//  - OSMesa (libOSMesa, loaded at run time so rvr still starts where it is missing),
//  - EGL surfaceless (EGL_PLATFORM_SURFACELESS_MESA), the way forward now that newer Mesa
//    releases have dropped OSMesa.
#pragma once

#include <glad/gl.h>

#include <memory>
#include <string>
#include <vector>

#include "rvr/core/expected.h"
#include "rvr/core/gl_backend.h"

namespace rvr {

class GlContext {
 public:
  virtual ~GlContext();
  GlContext(const GlContext&) = delete;
  GlContext& operator=(const GlContext&) = delete;

  // Binds the context to the calling thread; gl() then returns its entry points.
  Status make_current();
  // Releases the context (idempotent); gl() on this thread is unusable afterwards.
  void destroy();
  virtual const char* backend() const = 0;  // "osmesa" or "egl"

 protected:
  GlContext() = default;
  // Makes the native context current on the calling thread.
  virtual Status bind() = 0;
  virtual void release_native() = 0;
  // The back end's GetProcAddress: what glad loads the entry points with.
  virtual void* proc_address(const char* name) const = 0;
  // Binds, loads the entry points and checks the version; the back ends' create() ends here.
  Status finish_creation();

 private:
  GladGLContext entry_points_{};
  bool loaded_ = false;
};

// GL_VERSION etc. of the current context; an Internal error when the strings are missing.
struct GlStrings {
  std::string version, renderer, vendor, glsl_version;
};
Expected<GlStrings> current_gl_strings();

// Internal error for drivers that cannot render correctly (softpipe draws black).
Status check_gl_driver(const GlStrings& strings);

// Internal error for GALLIUM_DRIVER values known to crash inside context creation.
Status check_gallium_driver_variable();

// The back ends. Each returns a context that is already current, or an Internal error saying
// why none could be made (library missing, no 3.3 core context, ...).
Expected<std::unique_ptr<GlContext>> create_osmesa_context();
Expected<std::unique_ptr<GlContext>> create_egl_context();

// A context of the chosen back end, made current. Default: OSMesa, or EGL when OSMesa cannot
// be used; the fallback and its reason are appended to `warnings`.
Expected<std::unique_ptr<GlContext>> create_gl_context(GlBackend backend,
                                                       std::vector<std::string>& warnings);

}  // namespace rvr
