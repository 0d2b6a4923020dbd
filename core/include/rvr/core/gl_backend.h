// Where the OpenGL z-buffer's context comes from, and what that context reports: plain types,
// here so that the renderer table and the command line name them without including raster/.
#pragma once

#include <string>
#include <vector>

namespace rvr {

// Both run Mesa's llvmpipe; they differ only in how the context is made. Default: OSMesa, or
// EGL surfaceless when OSMesa cannot be loaded (the rasterizer then says so in its warnings).
enum class GlBackend { Default, OsMesa, Egl };

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
