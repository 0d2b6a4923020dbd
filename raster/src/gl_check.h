// The GL entry points and the one place where GL errors become rvr::Error values.
//
// Entry points come from a glad loader (generated at build time by Debian's python3-glad) with
// one table per context, so OSMesa and EGL contexts can live in one process: `gl()` is the
// table of the context current on this thread, as GL itself keeps a current context per
// thread. Call GL as `gl().DrawArrays(...)`.
#pragma once

#include <glad/gl.h>

#include "rvr/core/expected.h"

namespace rvr {

// The entry points of the context made current on this thread by GlContext::make_current().
// Calling it with no current context is a programming error (checked in debug builds).
const GladGLContext& gl();

// Drains glGetError; returns an Internal error naming every pending error code, what was being
// done and where, or ok when the GL is clean.
Status gl_check(const char* what, const char* file, int line);

}  // namespace rvr

// Returns the GL error (as rvr::Error) from the enclosing function, which must return an
// Expected<...> or Status.
#define RVR_GL_CHECK(what)                                                                         \
  do {                                                                                             \
    if (::rvr::Status rvr_gl_status_ = ::rvr::gl_check(what, __FILE__, __LINE__); !rvr_gl_status_) \
      return rvr_gl_status_.error();                                                               \
  } while (0)
