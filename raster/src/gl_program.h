// Shader compilation and linking; failures carry the driver's info log.
#pragma once

#include <glad/gl.h>

#include "rvr/core/expected.h"

namespace rvr {

// A linked program object (owned by the caller), or an Internal error with the info log.
Expected<GLuint> build_program(const char* name, const char* vertex_source,
                               const char* fragment_source);

}  // namespace rvr
