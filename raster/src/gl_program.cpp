#include "gl_program.h"

#include <fmt/format.h>
#include <stddef.h>

#include <string>

#include "gl_check.h"

namespace rvr {

namespace {

std::string shader_log(GLuint shader) {
  GLint length = 0;
  gl().GetShaderiv(shader, GL_INFO_LOG_LENGTH, &length);
  std::string log(size_t(length > 0 ? length : 0), '\0');
  if (length > 0) gl().GetShaderInfoLog(shader, length, nullptr, log.data());
  while (!log.empty() && (log.back() == '\0' || log.back() == '\n')) log.pop_back();
  return log;
}

std::string program_log(GLuint program) {
  GLint length = 0;
  gl().GetProgramiv(program, GL_INFO_LOG_LENGTH, &length);
  std::string log(size_t(length > 0 ? length : 0), '\0');
  if (length > 0) gl().GetProgramInfoLog(program, length, nullptr, log.data());
  while (!log.empty() && (log.back() == '\0' || log.back() == '\n')) log.pop_back();
  return log;
}

Expected<GLuint> compile(const char* name, GLenum stage, const char* source) {
  GLuint shader = gl().CreateShader(stage);
  if (shader == 0) return internal_error(fmt::format("{}: glCreateShader failed", name));
  gl().ShaderSource(shader, 1, &source, nullptr);
  gl().CompileShader(shader);
  GLint ok = GL_FALSE;
  gl().GetShaderiv(shader, GL_COMPILE_STATUS, &ok);
  if (ok != GL_TRUE) {
    std::string log = shader_log(shader);
    gl().DeleteShader(shader);
    return internal_error(fmt::format("{} {} shader does not compile: {}", name,
                                      stage == GL_VERTEX_SHADER ? "vertex" : "fragment", log));
  }
  return shader;
}

}  // namespace

Expected<GLuint> build_program(const char* name, const char* vertex_source,
                               const char* fragment_source) {
  RVR_TRY_ASSIGN(vs, compile(name, GL_VERTEX_SHADER, vertex_source));
  auto fs = compile(name, GL_FRAGMENT_SHADER, fragment_source);
  if (!fs) {
    gl().DeleteShader(*vs);
    return fs.error();
  }
  GLuint program = gl().CreateProgram();
  gl().AttachShader(program, *vs);
  gl().AttachShader(program, *fs);
  gl().LinkProgram(program);
  // The program keeps the compiled code; the shader objects are no longer needed.
  gl().DetachShader(program, *vs);
  gl().DetachShader(program, *fs);
  gl().DeleteShader(*vs);
  gl().DeleteShader(*fs);
  GLint ok = GL_FALSE;
  gl().GetProgramiv(program, GL_LINK_STATUS, &ok);
  if (ok != GL_TRUE) {
    std::string log = program_log(program);
    gl().DeleteProgram(program);
    return internal_error(fmt::format("{} program does not link: {}", name, log));
  }
  RVR_GL_CHECK("building a shader program");
  return program;
}

}  // namespace rvr
