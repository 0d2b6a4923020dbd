// A headless OpenGL 3.3 core context. Rendering goes into FBOs, so the context only has to
// exist and be current; GlContext is all the renderer sees, so an EGL surfaceless context can
// later replace OSMesa without touching the renderer.
#pragma once

#include <memory>
#include <string>
#include <vector>

#include "rvr/raster/gl_rasterizer.h"
#include "rvr/shared/expected.h"

struct osmesa_context;  // OSMesa's handle; its header stays in gl_context.cpp

namespace rvr {

class GlContext {
 public:
  virtual ~GlContext() = default;
  // Binds the context to the calling thread; GL calls go to it until another is made current.
  virtual Status make_current() = 0;
  virtual void destroy() = 0;
  virtual const char* backend() const = 0;  // "osmesa"
  // Entry points libOSMesa does not export (e.g. glGetQueryObjectui64v). Never null-checks
  // reliably: OSMesa returns non-null for unknown names, so ask only for what the version has.
  virtual void* proc_address(const char* name) const = 0;
};

// GL_VERSION etc. of the current context; an Internal error when the strings are missing
// (e.g. libGL linked before libOSMesa).
struct GlStrings {
  std::string version, renderer, vendor, glsl_version;
};
Expected<GlStrings> current_gl_strings();

// Internal error for drivers that cannot render correctly (softpipe draws black).
Status check_gl_driver(const GlStrings& strings);

class OsMesaContext final : public GlContext {
 public:
  // A core 3.3 context (Mesa gives 4.5) with a width x height RGBA default buffer, made current.
  // Refuses GALLIUM_DRIVER values known to crash inside context creation.
  static Expected<std::unique_ptr<OsMesaContext>> create(int width, int height);

  ~OsMesaContext() override { destroy(); }
  OsMesaContext(const OsMesaContext&) = delete;
  OsMesaContext& operator=(const OsMesaContext&) = delete;

  Status make_current() override;
  void destroy() override;
  const char* backend() const override { return "osmesa"; }
  void* proc_address(const char* name) const override;

 private:
  OsMesaContext() = default;
  osmesa_context* context_ = nullptr;
  int width_ = 0, height_ = 0;
  std::vector<unsigned char> buffer_;  // the default framebuffer OSMesa insists on
};

// A context of the chosen back end, made current. Default: OSMesa, or EGL when OSMesa cannot
// be loaded; the fallback is appended to `warnings`.
Expected<std::unique_ptr<GlContext>> create_gl_context(GlBackend backend, int width, int height,
                                                       std::vector<std::string>& warnings);

}  // namespace rvr
