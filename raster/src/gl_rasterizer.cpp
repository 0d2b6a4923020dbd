#include "rvr/raster/gl_rasterizer.h"

#include <fmt/format.h>

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <cstddef>
#include <cstring>
#include <glm/glm.hpp>
#include <glm/gtc/type_ptr.hpp>
#include <limits>
#include <new>
#include <string>
#include <type_traits>
#include <vector>

#include "gl_check.h"
#include "gl_context.h"
#include "gl_program.h"
#include "gl_shaders.h"
#include "rvr/shared/camera.h"
#include "rvr/shared/tessellate.h"

namespace rvr {

namespace {

using Clock = std::chrono::steady_clock;

double seconds_since(Clock::time_point start) {
  return std::chrono::duration<double>(Clock::now() - start).count();
}

// One corner of a triangle. Triangles are expanded (not indexed) so every corner can carry its
// triangle's geometric normal, and gl_PrimitiveID counts triangles from 0 in each object's draw.
struct Vertex {
  glm::vec3 position;
  glm::vec3 normal;
  glm::vec3 geometric_normal;
};
static_assert(sizeof(Vertex) == 9 * sizeof(float), "Vertex must be tightly packed for GL");

// One object's glDrawArrays and the uniforms that go with it.
struct DrawItem {
  GLint first = 0;
  GLsizei count = 0;
  uint32_t object = 0;
  const Material* material = nullptr;
  bool smooth = false;
  bool use_primitive_id = false;
};

struct SceneUniforms {
  GLint view = -1, projection = -1, eye = -1, ambient = -1, background = -1, shade = -1,
        smooth = -1, use_primitive_id = -1, object_id = -1, diffuse = -1, specular = -1,
        emission = -1, shininess = -1, lights = -1, light_count = -1;
};

// Colour attachments of the scene FBO, in fragment-output order (gl_shaders.h).
enum Target : int { kColour, kObjectId, kPrimitiveId, kViewDepth, kNormal, kCost, kTargetCount };

constexpr std::array<GLenum, kTargetCount> kTargetFormats = {GL_RGBA32F, GL_R32UI,   GL_R32UI,
                                                             GL_R32F,    GL_RGBA32F, GL_R32F};

Status append_mesh(const TriangleMesh& mesh, const std::string& name, std::vector<Vertex>& out) {
  const size_t n = mesh.positions.size();
  if (mesh.smooth() && mesh.normals.size() != n)
    return bad_input(
        fmt::format("object '{}': {} normals for {} positions", name, mesh.normals.size(), n));
  for (const glm::uvec3& t : mesh.triangles) {
    if (t.x >= n || t.y >= n || t.z >= n)
      return bad_input(
          fmt::format("object '{}': triangle index out of range ({} positions)", name, n));
    const glm::vec3 &p0 = mesh.positions[t.x], &p1 = mesh.positions[t.y], &p2 = mesh.positions[t.z];
    // Same expression as the tracer's face normal, so both flip the same way (face_viewer).
    glm::vec3 g = glm::cross(p1 - p0, p2 - p0);
    if (mesh.smooth()) {
      out.push_back({p0, mesh.normals[t.x], g});
      out.push_back({p1, mesh.normals[t.y], g});
      out.push_back({p2, mesh.normals[t.z], g});
    } else {
      out.push_back({p0, g, g});
      out.push_back({p1, g, g});
      out.push_back({p2, g, g});
    }
  }
  return ok_status();
}

std::string object_label(const Object& o, size_t index) {
  return o.name.empty() ? fmt::format("csg#{}", index) : o.name;
}

}  // namespace

Expected<GlInfo> query_gl_info() {
  auto context = create_gl_context(1, 1);
  if (!context) return context.error();
  auto strings = current_gl_strings();
  GlInfo info;
  info.backend = (*context)->backend();
  (*context)->destroy();
  if (!strings) return strings.error();
  info.version = strings->version;
  info.renderer = strings->renderer;
  info.vendor = strings->vendor;
  info.glsl_version = strings->glsl_version;
  return info;
}

struct GlRasterizer::Impl {
  std::unique_ptr<GlContext> context;
  GLuint scene_program = 0, cost_program = 0;
  SceneUniforms su;
  GLint cost_view = -1, cost_projection = -1;
  GLuint vao = 0, vertex_buffer = 0, light_buffer = 0, light_texture = 0, query = 0;
  GLint max_size = 0;  // largest framebuffer side the driver accepts
  PFNGLGETQUERYOBJECTUI64VPROC get_query_u64 = nullptr;  // GL 3.3, not exported by libOSMesa

  // Render targets, re-made when the image size changes.
  int width = 0, height = 0;
  GLuint scene_fbo = 0, cost_fbo = 0, depth_buffer = 0;
  std::array<GLuint, kTargetCount> targets{};

  // Kept to reuse their capacity across renders.
  std::vector<Vertex> vertices;
  std::vector<uint32_t> scratch;  // one-channel readback
  std::vector<glm::vec4> scratch_rgba;

  ~Impl() { release(); }

  // Context, programs and buffers: done once per GlRasterizer.
  Status init();
  Status create_resources();
  Status resize(int w, int h);
  void release_targets();
  void release();
  Expected<RenderOutput> render(const Scene& scene, const RenderOptions& options);
};

Status GlRasterizer::Impl::init() {
  if (context) return context->make_current();
  Status s = create_resources();
  if (!s) release();  // half-made state must not be reused by the next render
  return s;
}

Status GlRasterizer::Impl::create_resources() {
  auto created = create_gl_context(1, 1);  // 1x1: every pixel we keep goes to an FBO
  if (!created) return created.error();
  context = std::move(created.value());
  auto strings = current_gl_strings();
  if (!strings) return strings.error();
  RVR_TRY(check_gl_driver(*strings));

  auto scene = build_program("scene", shaders::kSceneVertex, shaders::kSceneFragment);
  if (!scene) return scene.error();
  scene_program = *scene;
  auto cost = build_program("cost", shaders::kCostVertex, shaders::kCostFragment);
  if (!cost) return cost.error();
  cost_program = *cost;

  auto loc = [&](const char* name) { return glGetUniformLocation(scene_program, name); };
  su.view = loc("u_view");
  su.projection = loc("u_projection");
  su.eye = loc("u_eye");
  su.ambient = loc("u_ambient");
  su.background = loc("u_background");
  su.shade = loc("u_shade");
  su.smooth = loc("u_smooth");
  su.use_primitive_id = loc("u_use_primitive_id");
  su.object_id = loc("u_object_id");
  su.diffuse = loc("u_diffuse");
  su.specular = loc("u_specular");
  su.emission = loc("u_emission");
  su.shininess = loc("u_shininess");
  su.lights = loc("u_lights");
  su.light_count = loc("u_light_count");
  cost_view = glGetUniformLocation(cost_program, "u_view");
  cost_projection = glGetUniformLocation(cost_program, "u_projection");

  glGenVertexArrays(1, &vao);
  glGenBuffers(1, &vertex_buffer);
  glBindVertexArray(vao);
  glBindBuffer(GL_ARRAY_BUFFER, vertex_buffer);
  auto attrib = [](GLuint index, size_t offset) {
    glEnableVertexAttribArray(index);
    glVertexAttribPointer(index, 3, GL_FLOAT, GL_FALSE, sizeof(Vertex),
                          reinterpret_cast<const void*>(offset));
  };
  attrib(shaders::kAttribPosition, offsetof(Vertex, position));
  attrib(shaders::kAttribNormal, offsetof(Vertex, normal));
  attrib(shaders::kAttribGeometricNormal, offsetof(Vertex, geometric_normal));

  glGenBuffers(1, &light_buffer);
  glGenTextures(1, &light_texture);
  glGenQueries(1, &query);
  get_query_u64 = reinterpret_cast<PFNGLGETQUERYOBJECTUI64VPROC>(
      context->proc_address("glGetQueryObjectui64v"));
  if (!get_query_u64) return internal_error("the GL has no glGetQueryObjectui64v");

  GLint max_renderbuffer = 0;
  GLint max_viewport[2] = {0, 0};
  glGetIntegerv(GL_MAX_RENDERBUFFER_SIZE, &max_renderbuffer);
  glGetIntegerv(GL_MAX_VIEWPORT_DIMS, max_viewport);
  max_size = std::min({max_renderbuffer, max_viewport[0], max_viewport[1]});
  RVR_GL_CHECK("GL setup");
  return ok_status();
}

Status GlRasterizer::Impl::resize(int w, int h) {
  if (w == width && h == height && scene_fbo != 0) return ok_status();
  if (w > max_size || h > max_size)
    return internal_error(fmt::format(
        "image {}x{} exceeds the GL driver's largest framebuffer ({} per side)", w, h, max_size));
  release_targets();
  glGenRenderbuffers(kTargetCount, targets.data());
  for (int i = 0; i < kTargetCount; ++i) {
    glBindRenderbuffer(GL_RENDERBUFFER, targets[size_t(i)]);
    glRenderbufferStorage(GL_RENDERBUFFER, kTargetFormats[size_t(i)], w, h);
  }
  glGenRenderbuffers(1, &depth_buffer);
  glBindRenderbuffer(GL_RENDERBUFFER, depth_buffer);
  glRenderbufferStorage(GL_RENDERBUFFER, GL_DEPTH_COMPONENT32F, w, h);
  RVR_GL_CHECK("allocating render targets");

  glGenFramebuffers(1, &scene_fbo);
  glBindFramebuffer(GL_FRAMEBUFFER, scene_fbo);
  std::array<GLenum, kCost> draw_buffers{};
  for (int i = 0; i < kCost; ++i) {
    glFramebufferRenderbuffer(GL_FRAMEBUFFER, GLenum(GL_COLOR_ATTACHMENT0 + i), GL_RENDERBUFFER,
                              targets[size_t(i)]);
    draw_buffers[size_t(i)] = GLenum(GL_COLOR_ATTACHMENT0 + i);
  }
  glFramebufferRenderbuffer(GL_FRAMEBUFFER, GL_DEPTH_ATTACHMENT, GL_RENDERBUFFER, depth_buffer);
  glDrawBuffers(GLsizei(draw_buffers.size()), draw_buffers.data());
  GLenum status = glCheckFramebufferStatus(GL_FRAMEBUFFER);
  if (status != GL_FRAMEBUFFER_COMPLETE)
    return internal_error(fmt::format("scene framebuffer incomplete (0x{:04x})", status));

  // The overdraw pass has its own FBO: it blends and ignores depth.
  glGenFramebuffers(1, &cost_fbo);
  glBindFramebuffer(GL_FRAMEBUFFER, cost_fbo);
  glFramebufferRenderbuffer(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, GL_RENDERBUFFER, targets[kCost]);
  GLenum cost_buffer = GL_COLOR_ATTACHMENT0;
  glDrawBuffers(1, &cost_buffer);
  status = glCheckFramebufferStatus(GL_FRAMEBUFFER);
  if (status != GL_FRAMEBUFFER_COMPLETE)
    return internal_error(fmt::format("cost framebuffer incomplete (0x{:04x})", status));
  RVR_GL_CHECK("creating framebuffers");
  width = w;
  height = h;
  return ok_status();
}

void GlRasterizer::Impl::release_targets() {
  if (scene_fbo) glDeleteFramebuffers(1, &scene_fbo);
  if (cost_fbo) glDeleteFramebuffers(1, &cost_fbo);
  if (depth_buffer) glDeleteRenderbuffers(1, &depth_buffer);
  if (targets[0]) glDeleteRenderbuffers(kTargetCount, targets.data());
  scene_fbo = cost_fbo = depth_buffer = 0;
  targets.fill(0);
  width = height = 0;
}

void GlRasterizer::Impl::release() {
  if (!context) return;
  // Deleting needs the context current; if that fails, destroying the context frees it all.
  if (context->make_current()) {
    release_targets();
    if (scene_program) glDeleteProgram(scene_program);
    if (cost_program) glDeleteProgram(cost_program);
    if (vao) glDeleteVertexArrays(1, &vao);
    if (vertex_buffer) glDeleteBuffers(1, &vertex_buffer);
    if (light_buffer) glDeleteBuffers(1, &light_buffer);
    if (light_texture) glDeleteTextures(1, &light_texture);
    if (query) glDeleteQueries(1, &query);
  }
  context->destroy();
  context.reset();
  // Names belong to the destroyed context: forget them so a later init() starts clean.
  scene_program = cost_program = 0;
  vao = vertex_buffer = light_buffer = light_texture = query = 0;
  scene_fbo = cost_fbo = depth_buffer = 0;
  targets.fill(0);
  width = height = 0;
  get_query_u64 = nullptr;
}

Expected<RenderOutput> GlRasterizer::Impl::render(const Scene& scene,
                                                  const RenderOptions& options) {
  const int w = scene.image.width, h = scene.image.height;
  if (w < 1 || h < 1) return bad_input(fmt::format("image size {}x{} is empty", w, h));
  RenderOutput out;

  // --- setup: context, programs (first call only), render targets (on size change)
  auto t = Clock::now();
  RVR_TRY(init());
  RVR_TRY(resize(w, h));
  out.stats["time.setup"] = seconds_since(t);

  // --- upload: expand every object to triangles, then one vertex buffer and one light buffer
  t = Clock::now();
  vertices.clear();
  vertices.reserve(3 * scene.triangle_count());  // meshes; tessellated shapes add a little
  std::vector<DrawItem> draws;
  std::vector<std::string> skipped_csg;
  const Material fallback = default_material();
  for (size_t i = 0; i < scene.objects.size(); ++i) {
    const Object& o = scene.objects[i];
    DrawItem d;
    d.object = uint32_t(i);
    d.first = GLint(vertices.size());
    d.material = o.material < scene.materials.size() ? &scene.materials[o.material] : nullptr;
    if (!d.material) {
      if (!scene.materials.empty())
        return bad_input(
            fmt::format("object '{}': material index {} out of range", o.name, o.material));
      d.material = &fallback;  // a hand-made scene with no material list: the built-in grey
    }
    switch (o.type) {
      case ObjectType::Triangles:
        RVR_TRY(append_mesh(o.mesh, o.name, vertices));
        d.smooth = o.mesh.smooth();
        d.use_primitive_id = true;
        break;
      case ObjectType::Sphere:
        RVR_TRY(
            append_mesh(tessellate_sphere(o.sphere, options.sphere_segments), o.name, vertices));
        d.smooth = true;
        break;
      case ObjectType::Plane:
        RVR_TRY(append_mesh(tessellate_plane(o.plane), o.name, vertices));
        break;
      case ObjectType::Csg:
        skipped_csg.push_back(object_label(o, i));
        continue;
    }
    d.count = GLsizei(GLint(vertices.size()) - d.first);
    if (d.count > 0) draws.push_back(d);
  }
  glBindVertexArray(vao);
  glBindBuffer(GL_ARRAY_BUFFER, vertex_buffer);
  glBufferData(GL_ARRAY_BUFFER, GLsizeiptr(vertices.size() * sizeof(Vertex)), vertices.data(),
               GL_STATIC_DRAW);

  const std::vector<LightSample> samples = options.mode == RenderMode::Visibility
                                               ? std::vector<LightSample>{}
                                               : light_samples(scene.lights);
  std::vector<glm::vec4> light_texels;
  light_texels.reserve(2 * samples.size() + 2);
  for (const LightSample& s : samples) {
    light_texels.emplace_back(s.position, 1.0f);
    light_texels.emplace_back(s.intensity, 0.0f);
  }
  if (light_texels.empty()) light_texels.resize(2, glm::vec4(0.0f));  // never an empty buffer
  glBindBuffer(GL_TEXTURE_BUFFER, light_buffer);
  glBufferData(GL_TEXTURE_BUFFER, GLsizeiptr(light_texels.size() * sizeof(glm::vec4)),
               light_texels.data(), GL_STATIC_DRAW);
  glActiveTexture(GL_TEXTURE0);
  glBindTexture(GL_TEXTURE_BUFFER, light_texture);
  glTexBuffer(GL_TEXTURE_BUFFER, GL_RGBA32F, light_buffer);
  RVR_GL_CHECK("uploading geometry and lights");
  out.stats["time.upload"] = seconds_since(t);

  // --- scene pass: z-buffer visibility, ids, depth, normal, local shading
  t = Clock::now();
  const glm::mat4 view = view_matrix(scene.camera);
  const glm::mat4 projection = projection_matrix(scene.camera, w, h);
  glBindFramebuffer(GL_FRAMEBUFFER, scene_fbo);
  glViewport(0, 0, w, h);
  glDisable(GL_CULL_FACE);  // two-sided, like the tracer
  glDisable(GL_BLEND);
  glEnable(GL_DEPTH_TEST);
  glDepthFunc(GL_LESS);
  glDepthMask(GL_TRUE);
  const float inf = std::numeric_limits<float>::infinity();
  const glm::vec4 background(scene.image.background, 1.0f);
  const glm::vec4 zero(0.0f);
  const GLuint no_id[4] = {kNoId, kNoId, kNoId, kNoId};
  const GLfloat far_view[4] = {inf, 0.0f, 0.0f, 0.0f};
  const GLfloat depth_one = 1.0f;
  glClearBufferfv(GL_COLOR, kColour, glm::value_ptr(background));
  glClearBufferuiv(GL_COLOR, kObjectId, no_id);
  glClearBufferuiv(GL_COLOR, kPrimitiveId, no_id);
  glClearBufferfv(GL_COLOR, kViewDepth, far_view);
  glClearBufferfv(GL_COLOR, kNormal, glm::value_ptr(zero));
  glClearBufferfv(GL_DEPTH, 0, &depth_one);

  glUseProgram(scene_program);
  glUniformMatrix4fv(su.view, 1, GL_FALSE, glm::value_ptr(view));
  glUniformMatrix4fv(su.projection, 1, GL_FALSE, glm::value_ptr(projection));
  glUniform3fv(su.eye, 1, glm::value_ptr(scene.camera.eye));
  glUniform3fv(su.ambient, 1, glm::value_ptr(scene.ambient));
  glUniform3fv(su.background, 1, glm::value_ptr(scene.image.background));
  glUniform1i(su.shade, options.mode == RenderMode::Visibility ? 0 : 1);
  glUniform1i(su.lights, 0);
  glUniform1i(su.light_count, GLint(samples.size()));
  glBeginQuery(GL_SAMPLES_PASSED, query);
  for (const DrawItem& d : draws) {
    glUniform1ui(su.object_id, d.object);
    glUniform1i(su.smooth, d.smooth ? 1 : 0);
    glUniform1i(su.use_primitive_id, d.use_primitive_id ? 1 : 0);
    glUniform3fv(su.diffuse, 1, glm::value_ptr(d.material->diffuse));
    glUniform3fv(su.specular, 1, glm::value_ptr(d.material->specular));
    glUniform3fv(su.emission, 1, glm::value_ptr(d.material->emission));
    glUniform1f(su.shininess, d.material->shininess);
    glDrawArrays(GL_TRIANGLES, d.first, d.count);
  }
  glEndQuery(GL_SAMPLES_PASSED);
  glFinish();
  RVR_GL_CHECK("scene pass");
  out.stats["time.render"] = seconds_since(t);

  // --- cost pass: every fragment generated, whatever the depth test would say
  t = Clock::now();
  glBindFramebuffer(GL_FRAMEBUFFER, cost_fbo);
  glClearBufferfv(GL_COLOR, 0, glm::value_ptr(zero));
  glDisable(GL_DEPTH_TEST);
  glEnable(GL_BLEND);
  glBlendFunc(GL_ONE, GL_ONE);
  glUseProgram(cost_program);
  glUniformMatrix4fv(cost_view, 1, GL_FALSE, glm::value_ptr(view));
  glUniformMatrix4fv(cost_projection, 1, GL_FALSE, glm::value_ptr(projection));
  if (!vertices.empty()) glDrawArrays(GL_TRIANGLES, 0, GLsizei(vertices.size()));
  glDisable(GL_BLEND);
  glFinish();
  RVR_GL_CHECK("cost pass");
  out.stats["time.cost"] = seconds_since(t);

  // --- readback
  t = Clock::now();
  FrameBuffers& fb = out.buffers;
  fb.width = w;
  fb.height = h;
  const size_t n = fb.pixel_count();
  fb.color.resize(n);
  fb.depth.resize(n);
  fb.object_id.resize(n);
  fb.primitive_id.resize(n);
  fb.normal.resize(n);
  fb.cost.resize(n);
  glPixelStorei(GL_PACK_ALIGNMENT, 1);
  // Each attachment is read in its stored layout into reused scratch memory, then copied once
  // into the FrameBuffers with rows flipped (GL rows are bottom-up, ours top-down).
  auto read_scalar = [&](GLuint fbo, int attachment, GLenum format, GLenum type, auto& dst) {
    using T = typename std::decay_t<decltype(dst)>::value_type;
    static_assert(sizeof(T) == 4);
    scratch.resize(n);
    glBindFramebuffer(GL_READ_FRAMEBUFFER, fbo);
    glReadBuffer(GLenum(GL_COLOR_ATTACHMENT0 + attachment));
    glReadPixels(0, 0, w, h, format, type, scratch.data());
    for (int y = 0; y < h; ++y)
      std::memcpy(dst.data() + size_t(y) * size_t(w),
                  scratch.data() + size_t(h - 1 - y) * size_t(w), size_t(w) * sizeof(T));
  };
  auto read_rgb = [&](int attachment, std::vector<glm::vec3>& dst) {
    scratch_rgba.resize(n);
    glBindFramebuffer(GL_READ_FRAMEBUFFER, scene_fbo);
    glReadBuffer(GLenum(GL_COLOR_ATTACHMENT0 + attachment));
    glReadPixels(0, 0, w, h, GL_RGBA, GL_FLOAT, scratch_rgba.data());
    for (int y = 0; y < h; ++y) {
      const glm::vec4* src = scratch_rgba.data() + size_t(h - 1 - y) * size_t(w);
      glm::vec3* row = dst.data() + size_t(y) * size_t(w);
      for (int x = 0; x < w; ++x) row[x] = glm::vec3(src[x]);
    }
  };
  read_rgb(kColour, fb.color);
  read_rgb(kNormal, fb.normal);
  read_scalar(scene_fbo, kObjectId, GL_RED_INTEGER, GL_UNSIGNED_INT, fb.object_id);
  read_scalar(scene_fbo, kPrimitiveId, GL_RED_INTEGER, GL_UNSIGNED_INT, fb.primitive_id);
  read_scalar(scene_fbo, kViewDepth, GL_RED, GL_FLOAT, fb.depth);
  read_scalar(cost_fbo, 0, GL_RED, GL_FLOAT, fb.cost);
  GLuint64 passed = 0;
  get_query_u64(query, GL_QUERY_RESULT, &passed);
  RVR_GL_CHECK("readback");
  out.stats["time.readback"] = seconds_since(t);

  double generated = 0.0;
  size_t covered = 0;
  for (size_t i = 0; i < n; ++i) {
    generated += double(fb.cost[i]);
    covered += fb.object_id[i] != kNoId ? 1 : 0;
  }
  out.stats["triangles.submitted"] = double(vertices.size() / 3);
  out.stats["fragments.generated"] = generated;
  out.stats["fragments.passed"] = double(passed);
  out.stats["pixels.covered"] = double(covered);
  out.stats["overdraw"] = covered > 0 ? generated / double(covered) : 0.0;

  if (!skipped_csg.empty()) {
    std::string names;
    for (const std::string& s : skipped_csg) names += (names.empty() ? "" : ", ") + s;
    out.warnings.push_back(fmt::format("csg objects have no z-buffer form: skipped {} ({})",
                                       skipped_csg.size(), names));
  }
  if (options.mode == RenderMode::Full)
    out.warnings.push_back(
        "raster: shadows, reflection, refraction and depth of field are not implemented; full "
        "mode rendered local shading");
  if (scene.image.samples_per_pixel > 1)
    out.warnings.push_back(fmt::format(
        "raster: {} samples per pixel requested; multisampling is not implemented, rendered 1",
        scene.image.samples_per_pixel));
  return out;
}

GlRasterizer::GlRasterizer() : impl_(std::make_unique<Impl>()) {}

GlRasterizer::~GlRasterizer() = default;

Expected<RenderOutput> GlRasterizer::render(const Scene& scene, const RenderOptions& options) {
  try {
    return impl_->render(scene, options);
  } catch (const std::bad_alloc&) {
    return internal_error(fmt::format("out of memory rendering {}x{} with {} objects",
                                      scene.image.width, scene.image.height, scene.objects.size()));
  }
}

}  // namespace rvr
