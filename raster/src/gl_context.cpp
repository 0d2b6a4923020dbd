#include "gl_context.h"

#include <GL/osmesa.h>
#include <fmt/format.h>

#include <cstdlib>
#include <string_view>

#include "gl_check.h"

namespace rvr {

Expected<GlStrings> current_gl_strings() {
  auto get = [](GLenum name) -> std::string {
    const GLubyte* s = glGetString(name);
    return s ? std::string(reinterpret_cast<const char*>(s)) : std::string();
  };
  GlStrings strings{get(GL_VERSION), get(GL_RENDERER), get(GL_VENDOR),
                    get(GL_SHADING_LANGUAGE_VERSION)};
  if (strings.version.empty() || strings.renderer.empty())
    return internal_error(
        "glGetString returned nothing: the GL entry points are not OSMesa's (is libGL linked "
        "before libOSMesa?)");
  RVR_GL_CHECK("glGetString");
  return strings;
}

Status check_gl_driver(const GlStrings& strings) {
  // softpipe renders an all-black image without any GL error (PLATFORM-NOTES.md).
  if (strings.renderer.find("softpipe") != std::string::npos)
    return internal_error(
        fmt::format("GL driver '{}' cannot render correctly; unset GALLIUM_DRIVER to use llvmpipe",
                    strings.renderer));
  return ok_status();
}

Expected<std::unique_ptr<OsMesaContext>> OsMesaContext::create(int width, int height) {
  // zink and swr crash inside OSMesa context creation rather than failing, so they are refused
  // before we get there.
  if (const char* driver = std::getenv("GALLIUM_DRIVER")) {
    std::string_view d(driver);
    if (d == "zink" || d == "swr")
      return internal_error(fmt::format(
          "GALLIUM_DRIVER={} crashes OSMesa context creation; unset GALLIUM_DRIVER to use "
          "llvmpipe",
          d));
  }
  if (width < 1 || height < 1)
    return internal_error(fmt::format("GL context size {}x{} is invalid", width, height));

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
  std::unique_ptr<OsMesaContext> ctx(new OsMesaContext());
  ctx->context_ = OSMesaCreateContextAttribs(attribs, nullptr);
  if (!ctx->context_) return internal_error("could not create an OSMesa OpenGL 3.3 core context");
  ctx->width_ = width;
  ctx->height_ = height;
  ctx->buffer_.assign(size_t(width) * size_t(height) * 4, 0);
  RVR_TRY(ctx->make_current());
  return ctx;
}

Status OsMesaContext::make_current() {
  if (!context_) return internal_error("OSMesa context used after destroy()");
  if (!OSMesaMakeCurrent(context_, buffer_.data(), GL_UNSIGNED_BYTE, width_, height_))
    return internal_error("OSMesaMakeCurrent failed");
  return ok_status();
}

void OsMesaContext::destroy() {
  if (!context_) return;
  OSMesaDestroyContext(context_);
  context_ = nullptr;
  buffer_.clear();
}

void* OsMesaContext::proc_address(const char* name) const {
  return reinterpret_cast<void*>(OSMesaGetProcAddress(name));
}

Expected<std::unique_ptr<GlContext>> create_gl_context(GlBackend backend, int width, int height,
                                                       std::vector<std::string>& warnings) {
  (void)warnings;
  if (backend == GlBackend::Egl) return internal_error("the EGL back end is not built yet");
  auto ctx = OsMesaContext::create(width, height);
  if (!ctx) return ctx.error();
  return std::unique_ptr<GlContext>(std::move(ctx.value()));
}

}  // namespace rvr
