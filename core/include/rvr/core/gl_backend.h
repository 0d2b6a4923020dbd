// Where the OpenGL z-buffer's context comes from, and what that context reports: plain types,
// here so that the renderer table and the command line name them without including raster/.
#pragma once

#include <optional>
#include <string>
#include <string_view>
#include <vector>

namespace rvr {

// Both run Mesa's llvmpipe; they differ only in how the context is made. Default: OSMesa, or
// EGL surfaceless when OSMesa cannot be loaded (the rasterizer then says so in its warnings).
enum class GlBackend { Default, OsMesa, Egl };

// The names a user chooses a back end by (the command line's --gl, Python's gl=), stated once.
inline const std::vector<std::string>& gl_backend_names() {
  static const std::vector<std::string> names = {"osmesa", "egl"};
  return names;
}

// The back end gl_backend_names() calls `name`; nullopt for any other name (an empty one
// included: the caller's default).
inline std::optional<GlBackend> parse_gl_backend(std::string_view name) {
  if (name == "osmesa") return GlBackend::OsMesa;
  if (name == "egl") return GlBackend::Egl;
  return std::nullopt;
}

// What the GL context reports, for `rvr info` and bug reports.
struct GlInfo {
  std::string backend;   // "osmesa" or "egl": the one in use
  std::string version;   // GL_VERSION
  std::string renderer;  // GL_RENDERER, e.g. "llvmpipe (LLVM 15.0.6, 256 bits)"
  std::string vendor;    // GL_VENDOR
  std::string glsl_version;
  std::vector<std::string> warnings;  // e.g. that the default fell back to EGL, and why
};

}  // namespace rvr
