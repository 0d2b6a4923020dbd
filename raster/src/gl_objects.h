// GL objects owned by handles (RAII): a handle deletes its object when it is reset, assigned
// another or destroyed. GL deletes only in a current context, so the owner
// (GlRasterizer::Impl::release) resets its handles while its context is current, and forgets
// them when it cannot make it current (destroying a context frees its objects).
#pragma once

#include <glad/gl.h>

#include <utility>

#include "gl_check.h"

namespace rvr {

// Kind: how an object of the kind is made (one name) and deleted.
template <class Kind>
class GlObject {
 public:
  GlObject() = default;
  // Adopts a name made elsewhere (a linked program).
  explicit GlObject(GLuint name) : name_(name) {}
  GlObject(GlObject&& other) noexcept : name_(std::exchange(other.name_, 0)) {}
  GlObject& operator=(GlObject&& other) noexcept {
    if (this != &other) {
      reset();
      name_ = std::exchange(other.name_, 0);
    }
    return *this;
  }
  GlObject(const GlObject&) = delete;
  GlObject& operator=(const GlObject&) = delete;
  ~GlObject() { reset(); }

  // A new object of the kind.
  static GlObject generate() {
    GlObject object;
    Kind::generate(&object.name_);
    return object;
  }

  // The handle stands for its name in GL calls; 0 when it holds nothing.
  operator GLuint() const { return name_; }

  void reset() {
    if (name_ != 0) Kind::destroy(name_);
    name_ = 0;
  }
  // Lets go of the name without deleting it: its context is gone, and the object with it.
  void forget() { name_ = 0; }

 private:
  GLuint name_ = 0;
};

struct GlBufferKind {
  static void generate(GLuint* name) { gl().GenBuffers(1, name); }
  static void destroy(GLuint name) { gl().DeleteBuffers(1, &name); }
};
struct GlTextureKind {
  static void generate(GLuint* name) { gl().GenTextures(1, name); }
  static void destroy(GLuint name) { gl().DeleteTextures(1, &name); }
};
struct GlFramebufferKind {
  static void generate(GLuint* name) { gl().GenFramebuffers(1, name); }
  static void destroy(GLuint name) { gl().DeleteFramebuffers(1, &name); }
};
struct GlRenderbufferKind {
  static void generate(GLuint* name) { gl().GenRenderbuffers(1, name); }
  static void destroy(GLuint name) { gl().DeleteRenderbuffers(1, &name); }
};
struct GlVertexArrayKind {
  static void generate(GLuint* name) { gl().GenVertexArrays(1, name); }
  static void destroy(GLuint name) { gl().DeleteVertexArrays(1, &name); }
};
struct GlQueryKind {
  static void generate(GLuint* name) { gl().GenQueries(1, name); }
  static void destroy(GLuint name) { gl().DeleteQueries(1, &name); }
};
// Programs are made by build_program (gl_program.h) and adopted.
struct GlProgramKind {
  static void destroy(GLuint name) { gl().DeleteProgram(name); }
};

using GlBuffer = GlObject<GlBufferKind>;
using GlTexture = GlObject<GlTextureKind>;
using GlFramebuffer = GlObject<GlFramebufferKind>;
using GlRenderbuffer = GlObject<GlRenderbufferKind>;
using GlVertexArray = GlObject<GlVertexArrayKind>;
using GlQuery = GlObject<GlQueryKind>;
using GlProgram = GlObject<GlProgramKind>;

}  // namespace rvr
