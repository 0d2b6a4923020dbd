#include "gl_check.h"

#include <fmt/format.h>

#include <string>

namespace rvr {

namespace {

const char* gl_error_name(GLenum e) {
  switch (e) {
    case GL_INVALID_ENUM:
      return "GL_INVALID_ENUM";
    case GL_INVALID_VALUE:
      return "GL_INVALID_VALUE";
    case GL_INVALID_OPERATION:
      return "GL_INVALID_OPERATION";
    case GL_INVALID_FRAMEBUFFER_OPERATION:
      return "GL_INVALID_FRAMEBUFFER_OPERATION";
    case GL_OUT_OF_MEMORY:
      return "GL_OUT_OF_MEMORY";
    default:
      return "unknown GL error";
  }
}

}  // namespace

Status gl_check(const char* what, const char* file, int line) {
  std::string codes;
  // glGetError reports one flag per call; a bounded loop also survives a lost context, which
  // keeps returning an error forever.
  for (int i = 0; i < 16; ++i) {
    GLenum e = gl().GetError();
    if (e == GL_NO_ERROR) break;
    if (!codes.empty()) codes += ", ";
    codes += fmt::format("{} (0x{:04x})", gl_error_name(e), unsigned(e));
  }
  if (codes.empty()) return ok_status();
  return internal_error(fmt::format("GL error during {}: {} at {}:{}", what, codes, file, line));
}

}  // namespace rvr
