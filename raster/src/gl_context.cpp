#include "gl_context.h"

#include <fmt/format.h>

#include <cassert>
#include <cstdlib>
#include <string_view>
#include <variant>

#include "gl_check.h"

namespace rvr {

namespace {

// GL keeps one current context per thread; so do we, for its entry points.
thread_local const GladGLContext* t_current_entry_points = nullptr;

}  // namespace

const GladGLContext& gl() {
  assert(t_current_entry_points && "GL call with no current GlContext on this thread");
  return *t_current_entry_points;
}

GlContext::~GlContext() = default;

Status GlContext::make_current() {
  if (!loaded_) return internal_error(fmt::format("{} GL context used after destroy()", backend()));
  RVR_TRY(bind());
  t_current_entry_points = &entry_points_;
  return ok_status();
}

void GlContext::destroy() {
  if (!loaded_) return;
  release_native();
  if (t_current_entry_points == &entry_points_) t_current_entry_points = nullptr;
  loaded_ = false;
}

Status GlContext::finish_creation() {
  RVR_TRY(bind());
  auto load = [](void* self, const char* name) -> GLADapiproc {
    return reinterpret_cast<GLADapiproc>(static_cast<GlContext*>(self)->proc_address(name));
  };
  const int version = gladLoadGLContextUserPtr(&entry_points_, load, this);
  if (version == 0 || !entry_points_.VERSION_3_3)
    return internal_error(
        fmt::format("{}: the context does not offer OpenGL 3.3 core (loader saw version {}.{})",
                    backend(), GLAD_VERSION_MAJOR(version), GLAD_VERSION_MINOR(version)));
  loaded_ = true;
  t_current_entry_points = &entry_points_;
  return ok_status();
}

Expected<GlStrings> current_gl_strings() {
  auto get = [](GLenum name) -> std::string {
    const GLubyte* s = gl().GetString(name);
    return s ? std::string(reinterpret_cast<const char*>(s)) : std::string();
  };
  GlStrings strings{get(GL_VERSION), get(GL_RENDERER), get(GL_VENDOR),
                    get(GL_SHADING_LANGUAGE_VERSION)};
  if (strings.version.empty() || strings.renderer.empty())
    return internal_error("glGetString returned nothing for GL_VERSION or GL_RENDERER");
  RVR_GL_CHECK("glGetString");
  return strings;
}

Status check_gl_driver(const GlStrings& strings) {
  // softpipe renders an all-black image without any GL error (docs/platform-notes.md).
  if (strings.renderer.find("softpipe") != std::string::npos)
    return internal_error(
        fmt::format("GL driver '{}' cannot render correctly; unset GALLIUM_DRIVER to use llvmpipe",
                    strings.renderer));
  return ok_status();
}

Status check_gallium_driver_variable() {
  // zink and swr crash inside context creation rather than failing, so they are refused
  // before we get there.
  if (const char* driver = std::getenv("GALLIUM_DRIVER")) {
    std::string_view d(driver);
    if (d == "zink" || d == "swr")
      return internal_error(fmt::format(
          "GALLIUM_DRIVER={} crashes GL context creation; unset GALLIUM_DRIVER to use llvmpipe",
          d));
  }
  return ok_status();
}

Expected<std::unique_ptr<GlContext>> create_gl_context(GlBackend backend,
                                                       std::vector<std::string>& warnings) {
  RVR_TRY(check_gallium_driver_variable());
  if (backend == GlBackend::OsMesa) return create_osmesa_context();
  if (backend == GlBackend::Egl) return create_egl_context();
  auto osmesa = create_osmesa_context();
  if (osmesa) return osmesa;
  auto egl = create_egl_context();
  if (!egl)
    return internal_error(
        fmt::format("no GL context: {}; and {}", osmesa.error().message, egl.error().message));
  warnings.push_back(fmt::format("OSMesa unavailable ({}); using EGL surfaceless instead",
                                 osmesa.error().message));
  return egl;
}

}  // namespace rvr
