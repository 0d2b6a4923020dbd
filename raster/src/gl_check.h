// The GL entry points (exported by libOSMesa, GL_GLEXT_PROTOTYPES) and the one place where GL
// errors become rvr::Error values.
#pragma once

#include <GL/gl.h>
#include <GL/glext.h>

#include "rvr/shared/expected.h"

namespace rvr {

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

// Propagates the error of an Expected/Status expression.
#define RVR_TRY(expr)                                                                    \
  do {                                                                                   \
    if (auto rvr_try_result_ = (expr); !rvr_try_result_) return rvr_try_result_.error(); \
  } while (0)
