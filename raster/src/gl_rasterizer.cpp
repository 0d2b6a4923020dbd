#include "rvr/raster/gl_rasterizer.h"

#include <fmt/format.h>
#include <glad/gl.h>

#include <algorithm>
#include <array>
#include <chrono>
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <glm/glm.hpp>
#include <glm/gtc/matrix_transform.hpp>
#include <glm/gtc/type_ptr.hpp>
#include <initializer_list>
#include <limits>
#include <map>
#include <memory>
#include <new>
#include <optional>
#include <string>
#include <string_view>
#include <type_traits>
#include <utility>
#include <variant>
#include <vector>

#include "accumulation_buffer.h"
#include "csg_leaves.h"
#include "depth_of_field_blur.h"
#include "draw_list_prep.h"
#include "environment_maps.h"
#include "gl_check.h"
#include "gl_context.h"
#include "gl_objects.h"
#include "gl_program.h"
#include "gl_shaders.h"
#include "planar_mirrors.h"
#include "rvr/core/camera.h"
#include "rvr/core/framebuffers.h"
#include "rvr/core/image_sample.h"
#include "rvr/core/progress.h"
#include "rvr/core/shapes/csg.h"
#include "rvr/core/shapes/sphere.h"
#include "rvr/core/shapes/triangle_mesh.h"
#include "rvr/core/surface_colour.h"
#include "rvr/core/texture.h"
#include "rvr/core/timer.h"
#include "shadow_plan.h"

namespace rvr {

namespace {

using Clock = std::chrono::steady_clock;

// One corner of a triangle. Triangles are expanded (not indexed) so every corner can carry its
// triangle's geometric normal, and gl_PrimitiveID counts triangles from 0 in each object's draw.
struct Vertex {
  glm::vec3 position;
  glm::vec3 normal;
  glm::vec3 geometric_normal;
};
static_assert(sizeof(Vertex) == 9 * sizeof(float), "Vertex must be tightly packed for GL");

// The same corner's texture coordinates and vertex colour, in a buffer of their own that exists
// only when some object varies in colour (untextured scenes upload exactly what they did).
struct SurfaceVertex {
  glm::vec2 uv{0.0f};
  glm::vec3 colour{1.0f};
};
static_assert(sizeof(SurfaceVertex) == 5 * sizeof(float), "tightly packed for GL");

// One object's glDrawArrays and the uniforms that go with it.
struct DrawItem {
  GLint first = 0;
  GLsizei count = 0;
  uint32_t object = 0;
  const Material* material = nullptr;
  bool smooth = false;
  bool use_primitive_id = false;
  GLuint texture = 0;  // the material's texture, 0: not textured
  bool coloured = false;
  // A CSG solid: its leaves' tessellations one after the other, `leaf_triangles` each; its
  // winners texture is Impl::csg_winners[csg_slot].
  const CsgNode* csg = nullptr;
  uint32_t leaf_triangles = 0;
  size_t csg_slot = 0;
};

struct SceneUniforms {
  GLint view = -1, projection = -1, eye = -1, ambient = -1, background = -1, shade = -1,
        smooth = -1, use_primitive_id = -1, object_id = -1, diffuse = -1, specular = -1,
        emission = -1, shininess = -1, lights = -1, light_first = -1, light_end = -1, base = -1,
        shadows = -1, shadow_maps = -1, face_rotation = -1, shadow_bias = -1, shadow_texel = -1,
        shadow_pcf = -1, textured = -1, coloured = -1, texture = -1, keep = -1, csg_half = -1,
        csg_centre = -1, csg_masked = -1, csg_winners = -1;
};

// Texture units of the scene pass.
constexpr GLint kLightUnit = 0;
constexpr GLint kShadowUnit = 1;
constexpr GLint kTextureUnit = 2;
constexpr GLint kCsgUnit = 3;

// Shadow maps (full mode). Every light sample (a point light, or one stratum centre of an area
// light) gets a full cube: six 90 degree faces around the sample, stored as six layers of one
// R32F 2D texture array (GL 3.3 has no cube-map arrays), each texel the linear distance |P - L|
// of the nearest surface. A cube rather than one hemisphere map per area sample keeps one code
// path for both kinds of light and leaves nothing outside the map (surfaces behind an area
// light's plane still cast and receive correctly).
//
// Memory: the maps of all samples at once would be 6 * size^2 * 4 bytes each (24 MiB at 1024),
// so the samples go in batches (shadow_plan.h: plan_shadow_maps); each batch renders its maps and
// then adds its samples' light to the colour in an extra lighting pass (depth test GL_EQUAL against
// the first pass's depth: same program, same vertices, so the depths are bit-identical).
//
// Resolution and bias: options.shadow_map_size (default 1024) texels per 90 degree face, so a
// texel spans at most 2/1024 rad: ~1 cm at 5 scene units, a fraction of a pixel of a 640x480
// view of the Cornell box. The lookup (shader shadow_visibility) compares |P - L| - bias with
// the stored distance, bias = options.shadow_bias (constant, scene units, default 0.01) + a
// slope term (0.75 texel * tan(angle to the light), capped at tan 8); the lookup point is
// also moved one texel footprint along the normal towards the light (normal offset). Without
// the last two, grazing surfaces (the Cornell ceiling, just above the lamp's samples) show
// acne rings; with them the classification agrees with shadow rays on >99% of pixels.

// Colour attachments of the scene FBO, in fragment-output order (gl_shaders.h).
enum Target : int {
  kColour,
  kObjectId,
  kPrimitiveId,
  kViewDepth,
  kNormal,
  kLod,
  kCost,
  kTargetCount
};

constexpr std::array<GLenum, kTargetCount> kTargetFormats = {
    GL_RGBA32F, GL_R32UI, GL_R32UI, GL_R32F, GL_RGBA32F, GL_R32F, GL_R32F};

void append_mesh(const TriangleMesh& mesh, std::vector<Vertex>& out) {
  for (const glm::uvec3& t : mesh.triangles) {
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
}

// The texture coordinates (after the material's uv_transform, an affine map: transforming the
// corners is transforming every interpolated point) and vertex colours of `mesh`'s corners, in
// append_mesh's order; defaults for what the mesh does not have.
void append_surface(const TriangleMesh& mesh, const Material& m, bool textured,
                    std::vector<SurfaceVertex>& out) {
  for (const glm::uvec3& t : mesh.triangles)
    for (int c = 0; c < 3; ++c) {
      SurfaceVertex v;
      if (textured) v.uv = m.uv_transform.apply(mesh.uvs[t[c]]);
      if (mesh.coloured()) v.colour = mesh.colours[t[c]];
      out.push_back(v);
    }
}

// What upload() made of the scene: one draw per object, the CSG objects it could not draw, the
// light samples it put in the light buffer (none in visibility mode).
struct SceneUpload {
  std::vector<DrawItem> draws;  // the CSG solids' last
  size_t csg_solids = 0;
  // The vertices of every object but the CSG solids, which come after them: what the shadow
  // maps draw and triangles.submitted counts (the solids' leaves count in csg.*).
  GLsizei plain_vertices = 0;
  PreparedScene prepared;  // the draws' materials and the skipped CSG objects
  std::vector<LightSample> samples;
  bool textured = false;  // some object is textured: the lod target is drawn and read back
};

// What the CSG passes of one render did, over every view it drew.
struct CsgCounts {
  size_t leaf_passes = 0;
  double seconds = 0.0;
};

// Full mode's shadow maps: their side, how many light samples share one batch of maps, and the
// projection of every cube face. Disabled: no lights, or not full mode.
struct ShadowPlan {
  bool enabled = false;
  int map_size = 0;
  size_t batch = 1;
  glm::mat4 light_projection{1.0f};
};

// Everything a pass over the scene needs: what was uploaded and the camera it is drawn with.
struct ScenePass {
  const Scene& scene;
  const RenderOptions& options;
  const SceneUpload& upload;
  const ShadowPlan& shadows;
  glm::mat4 view, projection;
  DepthFormat depth_format;
  glm::vec3 eye;      // where the pass looks from: the camera's eye or a sample's lens point
  int width, height;  // the frame's size: the image's, or a cube map face's
  // A planar mirror's view (planar_mirrors.h): only what lies on the positive side of the world
  // plane `keep` is drawn (when `clipped`), and not the objects `hidden` (the mirror it is seen
  // in, the layers it is seen through, a cube map's object).
  bool clipped = false;
  glm::vec4 keep{0.0f, 0.0f, 0.0f, 1.0f};
  std::vector<uint32_t> hidden = {};
  bool drawn(uint32_t object) const {
    return std::find(hidden.begin(), hidden.end(), object) == hidden.end();
  }
};

// Renderbuffer format of a z-buffer format.
GLenum depth_internal_format(DepthFormat format) {
  return format == DepthFormat::D24 ? GLenum(GL_DEPTH_COMPONENT24) : GLenum(GL_DEPTH_COMPONENT32F);
}

// `projection` (OpenGL's, window z 0 at near and 1 at far) with its z row replaced so that, with
// glClipControl's GL_ZERO_TO_ONE depth, window z is n (f - d) / (d (f - n)) at view depth d:
// 1 at near, 0 at far. Only the z row changes, so x, y and w (and any jitter or shear of an
// image sample in the rows of x and y) are those of `projection`.
glm::mat4 reversed_z_projection(glm::mat4 projection, float near_plane, float far_plane) {
  const double n = near_plane, f = far_plane;
  projection[0][2] = 0.0f;
  projection[1][2] = 0.0f;
  projection[2][2] = float(n / (f - n));
  projection[3][2] = float(n * f / (f - n));
  return projection;
}

// What a z-buffer cannot do, named for this scene only (shadows it does, with shadow maps).
void note_what_a_zbuffer_leaves_out(const Scene& scene, const RenderOptions& options,
                                    const std::vector<EnvironmentMapped>& mapped,
                                    const std::vector<std::string>& left_out,
                                    std::vector<std::string>& warnings) {
  if (options.mode != RenderMode::Full) return;
  note_environment_maps(scene, options, mapped, left_out, warnings);
  if (scene.camera.aperture_radius > 0.0f) {
    if (scene.image.samples_per_pixel == 1)
      warnings.push_back(kDepthOfFieldNeedsSamples);
    else if (options.supersampling == Supersampling::Msaa &&
             options.zbuffer_dof == ZBufferDof::Accumulation)
      warnings.push_back(
          "depth of field (aperture_radius > 0) not rendered by --supersampling msaa: pinhole");
  }
}

}  // namespace

const char* to_string(GlBackend backend) {
  switch (backend) {
    case GlBackend::OsMesa:
      return "osmesa";
    case GlBackend::Egl:
      return "egl";
    case GlBackend::Default:
      break;
  }
  return "default";
}

Expected<GlInfo> query_gl_info(GlBackend backend) {
  GlInfo info;
  RVR_TRY_ASSIGN(context, create_gl_context(backend, info.warnings));
  auto strings = current_gl_strings();
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
  GlBackend backend = GlBackend::Default;
  std::unique_ptr<GlContext> context;
  std::vector<std::string> context_warnings;  // e.g. the default fell back to EGL
  GlProgram scene_program, cost_program, shadow_program;
  SceneUniforms su;
  GLint cost_view = -1, cost_projection = -1;
  GLint shadow_light = -1, shadow_rotation = -1, shadow_projection = -1, shadow_csg_half = -1,
        shadow_csg_centre = -1;
  GlVertexArray vao;
  GlBuffer vertex_buffer, light_buffer;
  GlTexture light_texture;
  GlQuery query;
  GlBuffer surface_buffer;  // SurfaceVertex per corner, when some object varies in colour
  // The scene's textures as GL textures (0: not used by a drawn object), and the mip chains they
  // hold, so a render of the same scene uploads none again.
  std::vector<GlTexture> textures;
  std::vector<std::shared_ptr<const MipChain>> texture_sources;
  bool query_lod = false;   // ARB_texture_query_lod: the lod AOV is the driver's own
  bool lod_target = false;  // this render draws the lod target
  GLint max_size = 0;       // largest framebuffer side the driver accepts
  GLint max_samples = 1, max_texture_size = 0, max_layers = 0;
  bool clip_control = false;  // ARB_clip_control: reversed-Z depth (d32f_reversed)

  // Render targets, re-made when the image size changes.
  int width = 0, height = 0;
  GlFramebuffer scene_fbo, cost_fbo;
  GlRenderbuffer depth_buffer;
  GLenum depth_format = GL_DEPTH_COMPONENT32F;  // of depth_buffer and msaa_depth
  GLint depth_bits = 0;                         // of depth_buffer, as the driver allocated it
  std::array<GlRenderbuffer, kTargetCount> targets;
  // Multisampled colour + depth (spp > 1), re-made when size or sample count change.
  GlFramebuffer msaa_fbo;
  GlRenderbuffer msaa_colour, msaa_depth;
  int msaa_samples = 0;
  // Shadow maps of one batch: size x size x layers (6 per sample).
  GlFramebuffer shadow_fbo;
  GlTexture shadow_texture;
  int shadow_size = 0, shadow_layers = 0;
  // The passes of one accumulation buffer share their shadow maps (they do not depend on the
  // view): set for the passes of one render, and once the first pass has drawn every sample's
  // maps in one batch. Reset by every render and whenever the maps are reallocated.
  bool keep_shadow_maps = false, shadow_maps_kept = false;

  // Kept to reuse their capacity across renders.
  std::vector<Vertex> vertices;
  std::vector<SurfaceVertex> surface_vertices;
  std::vector<uint32_t> scratch;  // one-channel readback
  std::vector<glm::vec4> scratch_rgba;
  // CSG: a winners texture per solid (resolve_csg), a scratch shadow face for the leaves' passes
  // (add_csg_to_shadow_face), and what the passes of one render counted.
  std::vector<GlTexture> csg_winners;
  GlFramebuffer csg_shadow_fbo;
  GlTexture csg_shadow_face;
  int csg_shadow_size = 0;
  CsgCounts csg_counts;

  ~Impl() { release(); }

  // Context, programs and buffers: done once per GlRasterizer.
  Status init();
  Status create_resources();
  Status resize(int w, int h, GLenum depth);
  // The clip-space depth convention of the camera passes (reversed: GL_ZERO_TO_ONE) or GL's
  // default (shadow maps, and between renders).
  void use_depth_convention(bool reversed);
  Status ensure_msaa(int samples);
  Status ensure_shadow_maps(int size, int layers);
  Status render_shadow_maps(const std::vector<LightSample>& samples, size_t first, size_t end,
                            const glm::mat4& projection, const SceneUpload& upload);
  Status add_csg_to_shadow_face(const SceneUpload& upload, const glm::vec3& light,
                                const glm::mat3& rotation, const glm::mat4& projection,
                                GLint layer);
  void release_msaa();
  void release_shadow_maps();
  void release_targets();
  void release();
  // Every GL object held, each once: f(handle) for release() to delete or forget them all.
  template <class F>
  void for_each_object(F f);
  Status upload_textures(const Scene& scene);

  // One frame, in the order render() runs them.
  Expected<RenderOutput> render(const Scene& scene, const RenderOptions& options);
  Expected<RenderOutput> render_pass(const Scene& scene, const RenderOptions& options);
  Expected<SceneUpload> upload(const Scene& scene, const RenderOptions& options);
  Expected<ShadowPlan> plan_shadows(const RenderOptions& options,
                                    const std::vector<LightSample>& samples, RenderOutput& out);
  Status scene_passes(const ScenePass& pass, int msaa, RenderOutput& out);
  void use_scene_program(const ScenePass& pass, bool shade_pass, size_t first, size_t end,
                         bool base);
  void draw_scene(const ScenePass& pass, bool shade_pass, size_t first, size_t end, bool base);
  Status resolve_csg(const ScenePass& pass, GLenum nearer, GLfloat depth_clear);
  void clear_scene_targets(const Scene& scene, GLfloat depth_clear);
  void draw_to_every_target();
  Status cost_pass(const ScenePass& pass);
  Status readback(int w, int h, const ScenePass& pass, FrameBuffers& fb, uint64_t& samples_passed);
  Status add_cube_maps(const ScenePass& camera, const std::vector<EnvironmentMapped>& mapped,
                       RenderOutput& out);
  Status add_mirrors(const ScenePass& camera, const std::vector<PlanarMirror>& mirrors,
                     RenderOutput& out);
};

Status GlRasterizer::Impl::init() {
  if (context) return context->make_current();
  Status s = create_resources();
  if (!s) release();  // half-made state must not be reused by the next render
  return s;
}

Status GlRasterizer::Impl::create_resources() {
  context_warnings.clear();
  auto created =
      create_gl_context(backend, context_warnings);  // 1x1: every pixel we keep goes to an FBO
  if (!created) return created.error();
  context = std::move(created.value());
  RVR_TRY_ASSIGN(strings, current_gl_strings());
  RVR_TRY(check_gl_driver(*strings));

  RVR_TRY_ASSIGN(scene, build_program("scene", shaders::kSceneVertex, shaders::kSceneFragment));
  scene_program = GlProgram(*scene);
  RVR_TRY_ASSIGN(cost, build_program("cost", shaders::kCostVertex, shaders::kCostFragment));
  cost_program = GlProgram(*cost);
  RVR_TRY_ASSIGN(shadow, build_program("shadow", shaders::kShadowVertex, shaders::kShadowFragment));
  shadow_program = GlProgram(*shadow);
  shadow_light = gl().GetUniformLocation(shadow_program, "u_light");
  shadow_rotation = gl().GetUniformLocation(shadow_program, "u_rotation");
  shadow_projection = gl().GetUniformLocation(shadow_program, "u_projection");
  shadow_csg_half = gl().GetUniformLocation(shadow_program, "u_csg_half");
  shadow_csg_centre = gl().GetUniformLocation(shadow_program, "u_csg_centre");

  auto loc = [&](const char* name) { return gl().GetUniformLocation(scene_program, name); };
  su.view = loc("u_view");
  su.projection = loc("u_projection");
  su.eye = loc("u_eye");
  su.keep = loc("u_keep");
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
  su.light_first = loc("u_light_first");
  su.light_end = loc("u_light_end");
  su.base = loc("u_base");
  su.shadows = loc("u_shadows");
  su.shadow_maps = loc("u_shadow_maps");
  su.face_rotation = loc("u_face_rotation");
  su.shadow_bias = loc("u_shadow_bias");
  su.shadow_texel = loc("u_shadow_texel");
  su.shadow_pcf = loc("u_shadow_pcf");
  su.textured = loc("u_textured");
  su.coloured = loc("u_coloured");
  su.texture = loc("u_texture");
  su.csg_half = loc("u_csg_half");
  su.csg_centre = loc("u_csg_centre");
  su.csg_masked = loc("u_csg_masked");
  su.csg_winners = loc("u_csg_winners");
  cost_view = gl().GetUniformLocation(cost_program, "u_view");
  cost_projection = gl().GetUniformLocation(cost_program, "u_projection");

  vao = GlVertexArray::generate();
  vertex_buffer = GlBuffer::generate();
  gl().BindVertexArray(vao);
  gl().BindBuffer(GL_ARRAY_BUFFER, vertex_buffer);
  auto attrib = [](GLuint index, size_t offset) {
    gl().EnableVertexAttribArray(index);
    gl().VertexAttribPointer(index, 3, GL_FLOAT, GL_FALSE, sizeof(Vertex),
                             reinterpret_cast<const void*>(offset));
  };
  attrib(shaders::kAttribPosition, offsetof(Vertex, position));
  attrib(shaders::kAttribNormal, offsetof(Vertex, normal));
  attrib(shaders::kAttribGeometricNormal, offsetof(Vertex, geometric_normal));
  surface_buffer = GlBuffer::generate();
  gl().BindBuffer(GL_ARRAY_BUFFER, surface_buffer);
  gl().VertexAttribPointer(shaders::kAttribUv, 2, GL_FLOAT, GL_FALSE, sizeof(SurfaceVertex),
                           reinterpret_cast<const void*>(offsetof(SurfaceVertex, uv)));
  gl().VertexAttribPointer(shaders::kAttribColour, 3, GL_FLOAT, GL_FALSE, sizeof(SurfaceVertex),
                           reinterpret_cast<const void*>(offsetof(SurfaceVertex, colour)));
  // Disabled until a scene varies in colour: the constant values of an untextured surface.
  gl().VertexAttrib2f(shaders::kAttribUv, 0.0f, 0.0f);
  gl().VertexAttrib3f(shaders::kAttribColour, 1.0f, 1.0f, 1.0f);
  GLint extensions = 0;
  gl().GetIntegerv(GL_NUM_EXTENSIONS, &extensions);
  for (GLint i = 0; i < extensions; ++i) {
    const auto* name = reinterpret_cast<const char*>(gl().GetStringi(GL_EXTENSIONS, GLuint(i)));
    if (name && std::string_view(name) == "GL_ARB_texture_query_lod") query_lod = true;
  }

  light_buffer = GlBuffer::generate();
  light_texture = GlTexture::generate();
  query = GlQuery::generate();

  GLint max_renderbuffer = 0;
  GLint max_viewport[2] = {0, 0};
  gl().GetIntegerv(GL_MAX_RENDERBUFFER_SIZE, &max_renderbuffer);
  gl().GetIntegerv(GL_MAX_VIEWPORT_DIMS, max_viewport);
  max_size = std::min({max_renderbuffer, max_viewport[0], max_viewport[1]});
  gl().GetIntegerv(GL_MAX_SAMPLES, &max_samples);
  gl().GetIntegerv(GL_MAX_TEXTURE_SIZE, &max_texture_size);
  gl().GetIntegerv(GL_MAX_ARRAY_TEXTURE_LAYERS, &max_layers);
  max_samples = std::max(max_samples, 1);
  clip_control = gl().ARB_clip_control && gl().ClipControl != nullptr;
  RVR_GL_CHECK("GL setup");
  return ok_status();
}

void GlRasterizer::Impl::use_depth_convention(bool reversed) {
  if (clip_control)
    gl().ClipControl(GL_LOWER_LEFT, reversed ? GL_ZERO_TO_ONE : GL_NEGATIVE_ONE_TO_ONE);
}

Status GlRasterizer::Impl::resize(int w, int h, GLenum depth) {
  if (w == width && h == height && depth == depth_format && scene_fbo != 0) return ok_status();
  if (w > max_size || h > max_size)
    return internal_error(fmt::format(
        "image {}x{} exceeds the GL driver's largest framebuffer ({} per side)", w, h, max_size));
  release_targets();
  for (int i = 0; i < kTargetCount; ++i) {
    targets[size_t(i)] = GlRenderbuffer::generate();
    gl().BindRenderbuffer(GL_RENDERBUFFER, targets[size_t(i)]);
    gl().RenderbufferStorage(GL_RENDERBUFFER, kTargetFormats[size_t(i)], w, h);
  }
  depth_buffer = GlRenderbuffer::generate();
  gl().BindRenderbuffer(GL_RENDERBUFFER, depth_buffer);
  gl().RenderbufferStorage(GL_RENDERBUFFER, depth, w, h);
  depth_format = depth;
  // The driver may store more bits than the format asks for ("at least 24").
  gl().GetRenderbufferParameteriv(GL_RENDERBUFFER, GL_RENDERBUFFER_DEPTH_SIZE, &depth_bits);
  RVR_GL_CHECK("allocating render targets");

  scene_fbo = GlFramebuffer::generate();
  gl().BindFramebuffer(GL_FRAMEBUFFER, scene_fbo);
  std::array<GLenum, kCost> draw_buffers{};
  for (int i = 0; i < kCost; ++i) {
    gl().FramebufferRenderbuffer(GL_FRAMEBUFFER, GLenum(GL_COLOR_ATTACHMENT0 + i), GL_RENDERBUFFER,
                                 targets[size_t(i)]);
    draw_buffers[size_t(i)] = GLenum(GL_COLOR_ATTACHMENT0 + i);
  }
  gl().FramebufferRenderbuffer(GL_FRAMEBUFFER, GL_DEPTH_ATTACHMENT, GL_RENDERBUFFER, depth_buffer);
  gl().DrawBuffers(GLsizei(draw_buffers.size()), draw_buffers.data());
  GLenum status = gl().CheckFramebufferStatus(GL_FRAMEBUFFER);
  if (status != GL_FRAMEBUFFER_COMPLETE)
    return internal_error(fmt::format("scene framebuffer incomplete (0x{:04x})", status));

  // The overdraw pass has its own FBO: it blends and ignores depth.
  cost_fbo = GlFramebuffer::generate();
  gl().BindFramebuffer(GL_FRAMEBUFFER, cost_fbo);
  gl().FramebufferRenderbuffer(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, GL_RENDERBUFFER,
                               targets[kCost]);
  GLenum cost_buffer = GL_COLOR_ATTACHMENT0;
  gl().DrawBuffers(1, &cost_buffer);
  status = gl().CheckFramebufferStatus(GL_FRAMEBUFFER);
  if (status != GL_FRAMEBUFFER_COMPLETE)
    return internal_error(fmt::format("cost framebuffer incomplete (0x{:04x})", status));
  RVR_GL_CHECK("creating framebuffers");
  width = w;
  height = h;
  return ok_status();
}

Status GlRasterizer::Impl::ensure_msaa(int samples) {
  if (msaa_fbo != 0 && msaa_samples == samples) return ok_status();
  release_msaa();
  msaa_colour = GlRenderbuffer::generate();
  gl().BindRenderbuffer(GL_RENDERBUFFER, msaa_colour);
  gl().RenderbufferStorageMultisample(GL_RENDERBUFFER, samples, GL_RGBA32F, width, height);
  msaa_depth = GlRenderbuffer::generate();
  gl().BindRenderbuffer(GL_RENDERBUFFER, msaa_depth);
  gl().RenderbufferStorageMultisample(GL_RENDERBUFFER, samples, depth_format, width, height);
  msaa_fbo = GlFramebuffer::generate();
  gl().BindFramebuffer(GL_FRAMEBUFFER, msaa_fbo);
  gl().FramebufferRenderbuffer(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, GL_RENDERBUFFER, msaa_colour);
  gl().FramebufferRenderbuffer(GL_FRAMEBUFFER, GL_DEPTH_ATTACHMENT, GL_RENDERBUFFER, msaa_depth);
  GLenum colour_buffer = GL_COLOR_ATTACHMENT0;
  gl().DrawBuffers(1, &colour_buffer);
  GLenum status = gl().CheckFramebufferStatus(GL_FRAMEBUFFER);
  RVR_GL_CHECK("creating the multisampled framebuffer");
  if (status != GL_FRAMEBUFFER_COMPLETE)
    return internal_error(fmt::format("multisampled framebuffer ({} samples) incomplete (0x{:04x})",
                                      samples, status));
  msaa_samples = samples;
  return ok_status();
}

void GlRasterizer::Impl::release_msaa() {
  msaa_fbo.reset();
  msaa_colour.reset();
  msaa_depth.reset();
  msaa_samples = 0;
}

Status GlRasterizer::Impl::ensure_shadow_maps(int size, int layers) {
  if (shadow_texture != 0 && shadow_size == size && shadow_layers == layers) return ok_status();
  release_shadow_maps();
  shadow_maps_kept = false;
  shadow_texture = GlTexture::generate();
  gl().ActiveTexture(GLenum(GL_TEXTURE0 + kShadowUnit));
  gl().BindTexture(GL_TEXTURE_2D_ARRAY, shadow_texture);
  gl().TexImage3D(GL_TEXTURE_2D_ARRAY, 0, GL_R32F, size, size, layers, 0, GL_RED, GL_FLOAT,
                  nullptr);
  // Read with texelFetch only; nearest, one level, so the texture is complete.
  gl().TexParameteri(GL_TEXTURE_2D_ARRAY, GL_TEXTURE_MIN_FILTER, GL_NEAREST);
  gl().TexParameteri(GL_TEXTURE_2D_ARRAY, GL_TEXTURE_MAG_FILTER, GL_NEAREST);
  gl().TexParameteri(GL_TEXTURE_2D_ARRAY, GL_TEXTURE_MAX_LEVEL, 0);
  gl().ActiveTexture(GL_TEXTURE0);
  shadow_fbo = GlFramebuffer::generate();
  gl().BindFramebuffer(GL_FRAMEBUFFER, shadow_fbo);
  gl().FramebufferTextureLayer(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, shadow_texture, 0, 0);
  GLenum colour_buffer = GL_COLOR_ATTACHMENT0;
  gl().DrawBuffers(1, &colour_buffer);
  GLenum status = gl().CheckFramebufferStatus(GL_FRAMEBUFFER);
  RVR_GL_CHECK("allocating shadow maps");
  if (status != GL_FRAMEBUFFER_COMPLETE)
    return internal_error(fmt::format("shadow-map framebuffer incomplete (0x{:04x})", status));
  shadow_size = size;
  shadow_layers = layers;
  return ok_status();
}

void GlRasterizer::Impl::release_shadow_maps() {
  shadow_fbo.reset();
  shadow_texture.reset();
  shadow_size = shadow_layers = 0;
}

// Renders the cubes of samples [first, end) into layers 0 .. 6 (end - first) - 1: every
// triangle into every face, keeping the smallest distance per texel (GL_MIN blending).
Status GlRasterizer::Impl::render_shadow_maps(const std::vector<LightSample>& samples, size_t first,
                                              size_t end, const glm::mat4& projection,
                                              const SceneUpload& upload) {
  const std::array<glm::mat3, 6>& rotations = cube_face_rotations();
  gl().BindFramebuffer(GL_FRAMEBUFFER, shadow_fbo);
  gl().Viewport(0, 0, shadow_size, shadow_size);
  gl().Disable(GL_DEPTH_TEST);
  gl().DepthMask(GL_FALSE);
  gl().Enable(GL_BLEND);
  gl().BlendEquation(GL_MIN);
  gl().BlendFunc(GL_ONE, GL_ONE);
  gl().UseProgram(shadow_program);
  gl().UniformMatrix4fv(shadow_projection, 1, GL_FALSE, glm::value_ptr(projection));
  const GLfloat nothing[4] = {std::numeric_limits<float>::max(), 0.0f, 0.0f, 0.0f};
  for (size_t i = first; i < end; ++i) {
    gl().Uniform3fv(shadow_light, 1, glm::value_ptr(samples[i].position));
    for (size_t f = 0; f < 6; ++f) {
      gl().FramebufferTextureLayer(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, shadow_texture, 0,
                                   GLint(6 * (i - first) + f));
      gl().ClearBufferfv(GL_COLOR, 0, nothing);
      gl().UniformMatrix3fv(shadow_rotation, 1, GL_FALSE, glm::value_ptr(rotations[f]));
      gl().Uniform1i(shadow_csg_half, 0);
      if (upload.plain_vertices > 0) gl().DrawArrays(GL_TRIANGLES, 0, upload.plain_vertices);
      if (upload.csg_solids > 0)
        RVR_TRY(add_csg_to_shadow_face(upload, samples[i].position, rotations[f], projection,
                                       GLint(6 * (i - first) + f)));
    }
  }
  gl().BlendEquation(GL_FUNC_ADD);
  gl().Disable(GL_BLEND);
  gl().DepthMask(GL_TRUE);
  RVR_GL_CHECK("shadow maps");
  return ok_status();
}

// The CSG solids of `upload` into one face of a light sample's shadow cube: layer `layer` of
// shadow_texture, attached to shadow_fbo and holding the nearest distance of every other
// triangle. Each leaf's halves (facing the light, then away) are drawn alone into a scratch face
// and read back over the leaf's box, the intervals combined per texel by the tree as the camera's
// pass combines them, and the first boundary's distance kept where it is nearer than the face's.
Status GlRasterizer::Impl::add_csg_to_shadow_face(const SceneUpload& upload, const glm::vec3& light,
                                                  const glm::mat3& rotation,
                                                  const glm::mat4& projection, GLint layer) {
  const auto t = Clock::now();
  const int size = shadow_size;
  if (csg_shadow_size != size) {
    csg_shadow_face = GlTexture::generate();
    gl().ActiveTexture(GLenum(GL_TEXTURE0 + kCsgUnit));
    gl().BindTexture(GL_TEXTURE_2D, csg_shadow_face);
    gl().TexImage2D(GL_TEXTURE_2D, 0, GL_R32F, size, size, 0, GL_RED, GL_FLOAT, nullptr);
    gl().TexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER, GL_NEAREST);
    gl().TexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAG_FILTER, GL_NEAREST);
    gl().TexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAX_LEVEL, 0);
    gl().ActiveTexture(GL_TEXTURE0);
    csg_shadow_fbo = GlFramebuffer::generate();
    gl().BindFramebuffer(GL_FRAMEBUFFER, csg_shadow_fbo);
    gl().FramebufferTexture2D(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, GL_TEXTURE_2D, csg_shadow_face,
                              0);
    const GLenum colour_buffer = GL_COLOR_ATTACHMENT0;
    gl().DrawBuffers(1, &colour_buffer);
    if (gl().CheckFramebufferStatus(GL_FRAMEBUFFER) != GL_FRAMEBUFFER_COMPLETE)
      return internal_error("csg shadow-face framebuffer incomplete");
    csg_shadow_size = size;
  }
  const float none = std::numeric_limits<float>::max();  // what no triangle left (GL_MIN)
  const GLfloat nothing[4] = {none, 0.0f, 0.0f, 0.0f};
  const glm::dmat4 view_projection = glm::dmat4(projection) * glm::dmat4(glm::dmat3(rotation)) *
                                     glm::translate(glm::dmat4(1.0), -glm::dvec3(light));
  gl().PixelStorei(GL_PACK_ALIGNMENT, 4);
  gl().PixelStorei(GL_UNPACK_ALIGNMENT, 4);
  gl().Enable(GL_SCISSOR_TEST);
  for (const DrawItem& d : upload.draws) {
    if (!d.csg) continue;
    const std::vector<Sphere> leaves = csg_leaves(d.csg);
    // Per leaf: its box in GL's rows (from the bottom), and each half's distances there.
    std::vector<PixelBox> boxes(leaves.size());
    std::vector<std::vector<float>> halves(2 * leaves.size());
    PixelBox all{size, size, 0, 0};
    gl().BindFramebuffer(GL_FRAMEBUFFER, csg_shadow_fbo);
    for (size_t k = 0; k < leaves.size(); ++k) {
      const PixelBox top_down = leaf_box(leaves[k], view_projection, size, size);
      PixelBox& box = boxes[k];
      box = {top_down.x0, size - top_down.y1, top_down.x1, size - top_down.y0};
      if (box.empty()) continue;
      all = {std::min(all.x0, box.x0), std::min(all.y0, box.y0), std::max(all.x1, box.x1),
             std::max(all.y1, box.y1)};
      const int w = box.x1 - box.x0, h = box.y1 - box.y0;
      gl().Scissor(box.x0, box.y0, w, h);
      gl().Uniform3fv(shadow_csg_centre, 1, glm::value_ptr(leaves[k].center));
      for (size_t half = 0; half < 2; ++half) {
        gl().ClearBufferfv(GL_COLOR, 0, nothing);
        gl().Uniform1i(shadow_csg_half, GLint(half + 1));
        gl().DrawArrays(GL_TRIANGLES, d.first + GLint(3 * k * d.leaf_triangles),
                        GLsizei(3 * d.leaf_triangles));
        std::vector<float>& read = halves[2 * k + half];
        read.resize(size_t(w) * size_t(h));
        gl().ReadPixels(box.x0, box.y0, w, h, GL_RED, GL_FLOAT, read.data());
        csg_counts.leaf_passes++;
      }
    }
    if (all.empty()) continue;
    // The face over the leaves' boxes, the solid's first boundary kept where nearer.
    const int w = all.x1 - all.x0, h = all.y1 - all.y0;
    std::vector<float> face(size_t(w) * size_t(h));
    gl().BindFramebuffer(GL_FRAMEBUFFER, shadow_fbo);
    gl().ReadPixels(all.x0, all.y0, w, h, GL_RED, GL_FLOAT, face.data());
    const double infinity = std::numeric_limits<double>::infinity();
    std::vector<CsgInterval> intervals(leaves.size());
    for (int y = all.y0; y < all.y1; ++y)
      for (int x = all.x0; x < all.x1; ++x) {
        bool seen = false;
        for (size_t k = 0; k < leaves.size(); ++k) {
          const PixelBox& box = boxes[k];
          double distance[2] = {infinity, infinity};
          if (x >= box.x0 && x < box.x1 && y >= box.y0 && y < box.y1)
            for (size_t half = 0; half < 2; ++half) {
              const float v = halves[2 * k + half][size_t(y - box.y0) * size_t(box.x1 - box.x0) +
                                                   size_t(x - box.x0)];
              if (v < none) distance[half] = double(v);
            }
          intervals[k] = pixel_interval(distance[0], distance[1], 0, 0);
          seen = seen || intervals[k].hit;
        }
        CsgBoundary b;
        if (!seen || !first_csg_boundary(d.csg, intervals.data(),
                                         std::numeric_limits<double>::lowest(), infinity, b))
          continue;
        float& nearest = face[size_t(y - all.y0) * size_t(w) + size_t(x - all.x0)];
        nearest = std::min(nearest, float(b.t));
      }
    gl().ActiveTexture(GLenum(GL_TEXTURE0 + kShadowUnit));
    gl().BindTexture(GL_TEXTURE_2D_ARRAY, shadow_texture);
    gl().TexSubImage3D(GL_TEXTURE_2D_ARRAY, 0, all.x0, all.y0, layer, w, h, 1, GL_RED, GL_FLOAT,
                       face.data());
    gl().ActiveTexture(GL_TEXTURE0);
  }
  gl().Disable(GL_SCISSOR_TEST);
  gl().Uniform1i(shadow_csg_half, 0);
  gl().BindFramebuffer(GL_FRAMEBUFFER, shadow_fbo);
  RVR_GL_CHECK("csg in a shadow face");
  csg_counts.seconds += seconds_since(t);
  return ok_status();
}

void GlRasterizer::Impl::release_targets() {
  release_msaa();
  scene_fbo.reset();
  cost_fbo.reset();
  depth_buffer.reset();
  for (GlRenderbuffer& target : targets) target.reset();
  width = height = 0;
}

template <class F>
void GlRasterizer::Impl::for_each_object(F f) {
  for (GlProgram* p : {&scene_program, &cost_program, &shadow_program}) f(*p);
  f(vao);
  for (GlBuffer* b : {&vertex_buffer, &light_buffer, &surface_buffer}) f(*b);
  f(light_texture);
  f(query);
  for (GlTexture& texture : textures) f(texture);
  for (GlTexture& texture : csg_winners) f(texture);
  f(csg_shadow_fbo);
  f(csg_shadow_face);
  for (GlFramebuffer* fbo : {&scene_fbo, &cost_fbo, &msaa_fbo, &shadow_fbo}) f(*fbo);
  for (GlRenderbuffer* rb : {&depth_buffer, &msaa_colour, &msaa_depth}) f(*rb);
  for (GlRenderbuffer& target : targets) f(target);
  f(shadow_texture);
}

void GlRasterizer::Impl::release() {
  if (!context) return;
  // Deleting needs the context current; if that fails, destroying the context frees it all and
  // the names are forgotten.
  if (context->make_current())
    for_each_object([](auto& object) { object.reset(); });
  else
    for_each_object([](auto& object) { object.forget(); });
  context->destroy();
  context.reset();
  msaa_samples = 0;
  shadow_size = shadow_layers = 0;
  textures.clear();
  texture_sources.clear();
  csg_winners.clear();
  csg_shadow_size = 0;
  width = height = 0;
}

// --- upload: every object expanded to triangles in one vertex buffer, the lights in one buffer
Expected<SceneUpload> GlRasterizer::Impl::upload(const Scene& scene, const RenderOptions& options) {
  SceneUpload up;
  vertices.clear();
  vertices.reserve(3 * scene.triangle_count());  // meshes; tessellated shapes add a little
  surface_vertices.clear();
  bool varies = false;
  for (const Object& o : scene.objects) varies = varies || varies_in_colour(scene, o);
  if (varies) RVR_TRY(upload_textures(scene));
  RVR_TRY_ASSIGN(prepared, prepare_objects(scene, options.spheres, options.sphere_segments,
                                           options.zbuffer_left_out));
  up.prepared = std::move(*prepared);
  // The CSG solids after every other object: the shadow maps draw the vertices before them.
  std::vector<size_t> order;
  for (bool csg : {false, true})
    for (size_t i = 0; i < scene.objects.size(); ++i)
      if ((up.prepared.objects[i].csg != nullptr) == csg) order.push_back(i);
  for (size_t i : order) {
    const Object& o = scene.objects[i];
    const PreparedObject& p = up.prepared.objects[i];
    if (!p.mesh) continue;
    if (!p.csg) up.plain_vertices = GLsizei(vertices.size() + 3 * p.mesh->triangles.size());
    DrawItem d;
    d.object = uint32_t(i);
    d.first = GLint(vertices.size());
    d.material = p.material;
    d.smooth = p.smooth;
    d.use_primitive_id = p.names_triangles;
    d.csg = p.csg;
    d.leaf_triangles = p.csg_leaf_triangles;
    if (p.csg) d.csg_slot = up.csg_solids++;
    append_mesh(*p.mesh, vertices);
    if (varies && p.own_mesh) {
      const bool tex = textured(scene, o);
      if (tex) d.texture = textures[size_t(d.material->texture)];
      d.coloured = o.mesh.coloured();
      up.textured = up.textured || tex;
      append_surface(o.mesh, *d.material, tex, surface_vertices);
    }
    d.count = GLsizei(GLint(vertices.size()) - d.first);
    if (varies) surface_vertices.resize(vertices.size());  // shapes: the defaults
    if (d.count > 0) up.draws.push_back(d);
  }
  gl().BindVertexArray(vao);
  gl().BindBuffer(GL_ARRAY_BUFFER, vertex_buffer);
  gl().BufferData(GL_ARRAY_BUFFER, GLsizeiptr(vertices.size() * sizeof(Vertex)), vertices.data(),
                  GL_STATIC_DRAW);
  for (GLuint a : {shaders::kAttribUv, shaders::kAttribColour}) {
    if (varies)
      gl().EnableVertexAttribArray(a);
    else
      gl().DisableVertexAttribArray(a);
  }
  if (varies) {
    gl().BindBuffer(GL_ARRAY_BUFFER, surface_buffer);
    gl().BufferData(GL_ARRAY_BUFFER, GLsizeiptr(surface_vertices.size() * sizeof(SurfaceVertex)),
                    surface_vertices.data(), GL_STATIC_DRAW);
  }

  if (options.mode != RenderMode::Visibility) up.samples = light_samples(scene.lights);
  std::vector<glm::vec4> light_texels;
  light_texels.reserve(2 * up.samples.size() + 2);
  for (const LightSample& s : up.samples) {
    light_texels.emplace_back(s.position, 1.0f);
    light_texels.emplace_back(s.intensity, 0.0f);
  }
  if (light_texels.empty()) light_texels.resize(2, glm::vec4(0.0f));  // never an empty buffer
  gl().BindBuffer(GL_TEXTURE_BUFFER, light_buffer);
  gl().BufferData(GL_TEXTURE_BUFFER, GLsizeiptr(light_texels.size() * sizeof(glm::vec4)),
                  light_texels.data(), GL_STATIC_DRAW);
  gl().ActiveTexture(GLenum(GL_TEXTURE0 + kLightUnit));
  gl().BindTexture(GL_TEXTURE_BUFFER, light_texture);
  gl().TexBuffer(GL_TEXTURE_BUFFER, GL_RGBA32F, light_buffer);
  RVR_GL_CHECK("uploading geometry and lights");
  return up;
}

// --- textures: each textured material's mip chain, level by level (the very texels every
// renderer samples, not the driver's own reductions), filtered LINEAR_MIPMAP_LINEAR
Status GlRasterizer::Impl::upload_textures(const Scene& scene) {
  std::vector<bool> used(scene.textures.size(), false);
  for (const Object& o : scene.objects)
    if (textured(scene, o)) used[size_t(scene.materials[o.material].texture)] = true;
  textures.resize(scene.textures.size());
  texture_sources.resize(scene.textures.size(), nullptr);
  auto wrap_mode = [](TextureWrap w) -> GLint {
    switch (w) {
      case TextureWrap::ClampToEdge:
        return GL_CLAMP_TO_EDGE;
      case TextureWrap::MirroredRepeat:
        return GL_MIRRORED_REPEAT;
      case TextureWrap::Repeat:
        break;
    }
    return GL_REPEAT;
  };
  gl().ActiveTexture(GLenum(GL_TEXTURE0 + kTextureUnit));
  gl().PixelStorei(GL_UNPACK_ALIGNMENT, 4);  // rows of float RGB texels: multiples of 4 bytes
  for (size_t i = 0; i < scene.textures.size(); ++i) {
    const Texture& t = scene.textures[i];
    if (!used[i] || (textures[i] && texture_sources[i] == t.mips)) continue;
    if (t.mips->width() > max_texture_size || t.mips->height() > max_texture_size)
      return bad_input(fmt::format("texture '{}' is {}x{}: this GL's largest is {} per side",
                                   t.file, t.mips->width(), t.mips->height(), max_texture_size));
    if (!textures[i]) textures[i] = GlTexture::generate();
    gl().BindTexture(GL_TEXTURE_2D, textures[i]);
    const std::vector<TextureLevel>& levels = t.mips->levels;
    for (size_t k = 0; k < levels.size(); ++k)
      gl().TexImage2D(GL_TEXTURE_2D, GLint(k), GL_RGB32F, levels[k].width, levels[k].height, 0,
                      GL_RGB, GL_FLOAT, levels[k].texels.data());
    gl().TexParameteri(GL_TEXTURE_2D, GL_TEXTURE_BASE_LEVEL, 0);
    gl().TexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAX_LEVEL, GLint(levels.size()) - 1);
    gl().TexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER, GL_LINEAR_MIPMAP_LINEAR);
    gl().TexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAG_FILTER, GL_LINEAR);
    gl().TexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_S, wrap_mode(t.wrap_u));
    gl().TexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_T, wrap_mode(t.wrap_v));
    texture_sources[i] = t.mips;
  }
  gl().ActiveTexture(GL_TEXTURE0);
  RVR_GL_CHECK("uploading textures");
  return ok_status();
}

// --- shadow-map plan (full mode): resolution, batches, light-space projection
Expected<ShadowPlan> GlRasterizer::Impl::plan_shadows(const RenderOptions& options,
                                                      const std::vector<LightSample>& samples,
                                                      RenderOutput& out) {
  ShadowPlan plan;
  plan.enabled = options.mode == RenderMode::Full && !samples.empty();
  plan.batch = std::max<size_t>(samples.size(), 1);
  if (!plan.enabled) return plan;
  glm::vec3 lo(std::numeric_limits<float>::max()), hi(-std::numeric_limits<float>::max());
  for (const Vertex& v : vertices) {
    lo = glm::min(lo, v.position);
    hi = glm::max(hi, v.position);
  }
  RVR_TRY_ASSIGN(maps, plan_shadow_maps(options, samples, max_texture_size,
                                        size_t(std::max(max_layers / 6, 1)), lo, hi,
                                        !vertices.empty(), out.warnings));
  plan.light_projection =
      glm::perspective(glm::radians(90.0f), 1.0f, maps->near_plane, maps->far_plane);
  plan.map_size = maps->size;
  plan.batch = maps->batch;
  RVR_TRY(ensure_shadow_maps(plan.map_size, int(6 * plan.batch)));
  return plan;
}

// The scene program's uniforms for a pass, but the object's.
void GlRasterizer::Impl::use_scene_program(const ScenePass& pass, bool shade_pass, size_t first,
                                           size_t end, bool base) {
  const std::array<glm::mat3, 6>& rotations = cube_face_rotations();
  const Scene& scene = pass.scene;
  gl().UseProgram(scene_program);
  gl().UniformMatrix4fv(su.view, 1, GL_FALSE, glm::value_ptr(pass.view));
  gl().UniformMatrix4fv(su.projection, 1, GL_FALSE, glm::value_ptr(pass.projection));
  gl().Uniform3fv(su.eye, 1, glm::value_ptr(pass.eye));
  gl().Uniform4fv(su.keep, 1, glm::value_ptr(pass.keep));
  gl().Uniform3fv(su.ambient, 1, glm::value_ptr(scene.ambient));
  gl().Uniform3fv(su.background, 1, glm::value_ptr(scene.image.background));
  gl().Uniform1i(su.shade, shade_pass ? 1 : 0);
  gl().Uniform1i(su.lights, kLightUnit);
  gl().Uniform1i(su.light_first, GLint(first));
  gl().Uniform1i(su.light_end, GLint(end));
  gl().Uniform1i(su.base, base ? 1 : 0);
  gl().Uniform1i(su.shadows, pass.shadows.enabled ? 1 : 0);
  gl().Uniform1i(su.shadow_maps, kShadowUnit);
  gl().UniformMatrix3fv(su.face_rotation, 6, GL_FALSE, glm::value_ptr(rotations[0]));
  gl().Uniform1f(su.shadow_bias, pass.options.shadow_bias);
  // A texel spans at most 2/size in tan units (at a face centre): normal offset and slope bias
  // are measured in it (gl_shaders.h, shadow_visibility).
  gl().Uniform1f(su.shadow_texel,
                 pass.shadows.map_size > 0 ? 2.0f / float(pass.shadows.map_size) : 0.0f);
  gl().Uniform1i(su.shadow_pcf, pass.options.shadow_pcf ? 1 : 0);
  gl().Uniform1i(su.texture, kTextureUnit);
  gl().Uniform1i(su.csg_winners, kCsgUnit);
  gl().Uniform1i(su.csg_half, 0);
}

// One draw of every object with the scene program; the caller sets the pass's state. A CSG
// solid is drawn masked by its winners (resolve_csg).
void GlRasterizer::Impl::draw_scene(const ScenePass& pass, bool shade_pass, size_t first,
                                    size_t end, bool base) {
  use_scene_program(pass, shade_pass, first, end, base);
  for (const DrawItem& d : pass.upload.draws) {
    if (!pass.drawn(d.object)) continue;
    gl().Uniform1i(su.csg_masked, d.csg ? 1 : 0);
    if (d.csg) {
      gl().ActiveTexture(GLenum(GL_TEXTURE0 + kCsgUnit));
      gl().BindTexture(GL_TEXTURE_2D, csg_winners[d.csg_slot]);
    }
    gl().ActiveTexture(GLenum(GL_TEXTURE0 + kTextureUnit));
    gl().Uniform1i(su.textured, d.texture != 0 ? 1 : 0);
    gl().Uniform1i(su.coloured, d.coloured ? 1 : 0);
    gl().BindTexture(GL_TEXTURE_2D, d.texture);
    gl().Uniform1ui(su.object_id, d.object);
    gl().Uniform1i(su.smooth, d.smooth ? 1 : 0);
    gl().Uniform1i(su.use_primitive_id, d.use_primitive_id ? 1 : 0);
    gl().Uniform3fv(su.diffuse, 1, glm::value_ptr(d.material->diffuse));
    gl().Uniform3fv(su.specular, 1, glm::value_ptr(d.material->specular));
    gl().Uniform3fv(su.emission, 1, glm::value_ptr(d.material->emission));
    gl().Uniform1f(su.shininess, d.material->shininess);
    gl().DrawArrays(GL_TRIANGLES, d.first, d.count);
  }
  gl().ActiveTexture(GL_TEXTURE0);
}

// CSG solids in this pass's view (csg_leaves.h): each leaf's two halves drawn alone into the
// view-depth and primitive targets and read back, the leaves' intervals combined per pixel by
// the tree (first_csg_boundary, as the tracer combines a ray's), and the triangle of each
// pixel's first boundary put in the solid's winners texture. The passes that draw the frame
// then draw the solid's triangles masked by it, shaded and depth-tested like any triangle.
Status GlRasterizer::Impl::resolve_csg(const ScenePass& pass, GLenum nearer, GLfloat depth_clear) {
  const auto t = Clock::now();
  const int w = pass.width, h = pass.height;
  const size_t n = size_t(w) * size_t(h);
  const float infinity = std::numeric_limits<float>::infinity();
  const GLfloat far_view[4] = {infinity, 0.0f, 0.0f, 0.0f};
  use_scene_program(pass, false, 0, 0, true);
  gl().Uniform1i(su.csg_masked, 0);
  gl().Uniform1i(su.use_primitive_id, 1);
  gl().Uniform1i(su.textured, 0);
  gl().Uniform1i(su.coloured, 0);
  gl().BindFramebuffer(GL_FRAMEBUFFER, scene_fbo);
  const std::array<GLenum, kViewDepth + 1> outputs{GL_NONE, GL_NONE,
                                                   GLenum(GL_COLOR_ATTACHMENT0 + kPrimitiveId),
                                                   GLenum(GL_COLOR_ATTACHMENT0 + kViewDepth)};
  gl().DrawBuffers(GLsizei(outputs.size()), outputs.data());
  gl().DepthFunc(nearer);
  gl().DepthMask(GL_TRUE);
  gl().PixelStorei(GL_PACK_ALIGNMENT, 1);
  csg_winners.resize(pass.upload.csg_solids);
  std::vector<float> depth;       // per half of each leaf, n each
  std::vector<uint32_t> facet;    // the triangle there, in the leaf
  std::vector<uint32_t> winners;  // per pixel
  for (const DrawItem& d : pass.upload.draws) {
    if (!d.csg || !pass.drawn(d.object)) continue;
    const std::vector<Sphere> leaves = csg_leaves(d.csg);
    depth.resize(2 * leaves.size() * n);
    facet.resize(2 * leaves.size() * n);
    for (size_t k = 0; k < leaves.size(); ++k)
      for (size_t half = 0; half < 2; ++half) {
        gl().ClearBufferfv(GL_COLOR, kViewDepth, far_view);
        gl().ClearBufferfv(GL_DEPTH, 0, &depth_clear);
        gl().Uniform3fv(su.csg_centre, 1, glm::value_ptr(leaves[k].center));
        gl().Uniform1i(su.csg_half, GLint(half + 1));
        gl().DrawArrays(GL_TRIANGLES, d.first + GLint(3 * k * d.leaf_triangles),
                        GLsizei(3 * d.leaf_triangles));
        const size_t layer = (2 * k + half) * n;
        gl().ReadBuffer(GLenum(GL_COLOR_ATTACHMENT0 + kViewDepth));
        gl().ReadPixels(0, 0, w, h, GL_RED, GL_FLOAT, depth.data() + layer);
        gl().ReadBuffer(GLenum(GL_COLOR_ATTACHMENT0 + kPrimitiveId));
        gl().ReadPixels(0, 0, w, h, GL_RED_INTEGER, GL_UNSIGNED_INT, facet.data() + layer);
        csg_counts.leaf_passes++;
      }
    winners.assign(n, 0);
    std::vector<CsgInterval> intervals(leaves.size());
    for (size_t i = 0; i < n; ++i) {
      bool seen = false;
      for (size_t k = 0; k < leaves.size(); ++k) {
        const size_t front = 2 * k * n + i, back = front + n;
        intervals[k] = pixel_interval(depth[front], depth[back], facet[front], facet[back]);
        seen = seen || intervals[k].hit;
      }
      CsgBoundary b;
      if (seen && first_csg_boundary(d.csg, intervals.data(), std::numeric_limits<double>::lowest(),
                                     std::numeric_limits<double>::infinity(), b))
        winners[i] = b.leaf * d.leaf_triangles + b.facet + 1;
    }
    GlTexture& texture = csg_winners[d.csg_slot];
    if (!texture) texture = GlTexture::generate();
    gl().ActiveTexture(GLenum(GL_TEXTURE0 + kCsgUnit));
    gl().BindTexture(GL_TEXTURE_2D, texture);
    gl().PixelStorei(GL_UNPACK_ALIGNMENT, 4);
    gl().TexImage2D(GL_TEXTURE_2D, 0, GL_R32UI, w, h, 0, GL_RED_INTEGER, GL_UNSIGNED_INT,
                    winners.data());
    gl().TexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER, GL_NEAREST);
    gl().TexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAG_FILTER, GL_NEAREST);
    gl().TexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAX_LEVEL, 0);
    gl().ActiveTexture(GL_TEXTURE0);
  }
  gl().Uniform1i(su.csg_half, 0);
  draw_to_every_target();
  RVR_GL_CHECK("csg passes");
  csg_counts.seconds += seconds_since(t);
  return ok_status();
}

void GlRasterizer::Impl::clear_scene_targets(const Scene& scene, GLfloat depth_clear) {
  const float inf = std::numeric_limits<float>::infinity();
  const glm::vec4 background(scene.image.background, 1.0f);
  const glm::vec4 zero(0.0f);
  const GLuint no_id[4] = {kNoId, kNoId, kNoId, kNoId};
  const GLfloat far_view[4] = {inf, 0.0f, 0.0f, 0.0f};
  gl().BindFramebuffer(GL_FRAMEBUFFER, scene_fbo);
  draw_to_every_target();
  gl().ClearBufferfv(GL_COLOR, kColour, glm::value_ptr(background));
  gl().ClearBufferuiv(GL_COLOR, kObjectId, no_id);
  gl().ClearBufferuiv(GL_COLOR, kPrimitiveId, no_id);
  gl().ClearBufferfv(GL_COLOR, kViewDepth, far_view);
  gl().ClearBufferfv(GL_COLOR, kNormal, glm::value_ptr(zero));
  if (lod_target) {
    const GLfloat not_textured[4] = {std::numeric_limits<float>::quiet_NaN(), 0.0f, 0.0f, 0.0f};
    gl().ClearBufferfv(GL_COLOR, kLod, not_textured);
  }
  gl().ClearBufferfv(GL_DEPTH, 0, &depth_clear);
}

void GlRasterizer::Impl::draw_to_every_target() {
  std::array<GLenum, kCost> all_outputs{};
  for (int i = 0; i < kCost; ++i) all_outputs[size_t(i)] = GLenum(GL_COLOR_ATTACHMENT0 + i);
  if (!lod_target) all_outputs[kLod] = GL_NONE;  // untextured: the lod output is dropped
  gl().DrawBuffers(GLsizei(all_outputs.size()), all_outputs.data());
}

// --- scene passes: z-buffer visibility, ids, depth, normal, shading; shadow maps per batch
Status GlRasterizer::Impl::scene_passes(const ScenePass& pass, int msaa, RenderOutput& out) {
  const int w = pass.width, h = pass.height;
  const std::vector<LightSample>& samples = pass.upload.samples;
  const ShadowPlan& shadows = pass.shadows;
  const bool shade = pass.options.mode != RenderMode::Visibility;
  const glm::vec4 background(pass.scene.image.background, 1.0f);
  // Reversed-Z: the far plane is 0 and nearer is greater.
  const bool reversed = pass.depth_format == DepthFormat::D32FReversed;
  const GLfloat depth_clear = reversed ? 0.0f : 1.0f;
  const GLenum nearer = reversed ? GL_GREATER : GL_LESS;
  const GLenum colour_only = GL_COLOR_ATTACHMENT0;
  ProgressSink* progress = pass.options.progress;
  double shadow_time = 0.0;
  auto t = Clock::now();

  gl().Disable(GL_CULL_FACE);  // two-sided, like the tracer
  gl().Disable(GL_BLEND);
  if (pass.clipped) gl().Enable(GL_CLIP_DISTANCE0);
  gl().ActiveTexture(GLenum(GL_TEXTURE0 + kShadowUnit));
  gl().BindTexture(GL_TEXTURE_2D_ARRAY, shadow_texture);
  gl().ActiveTexture(GL_TEXTURE0);
  const size_t batches = shadows.enabled ? (samples.size() + shadows.batch - 1) / shadows.batch : 1;
  // With several batches of light samples, progress counts passes (the speed, triangles drawn,
  // shadow maps' six faces per sample included); one pass shows its time only. GL is
  // asynchronous: a pass counts when submitted; the next batch's glFinish waits for it.
  if (progress) {
    if (batches > 1)
      progress->begin("render", batches, "passes", "triangles");
    else
      progress->begin("render");
  }
  for (size_t b = 0; b < batches; ++b) {
    if (is_cancelled(progress)) return cancelled_error();
    const size_t first = b * shadows.batch, end = std::min(samples.size(), first + shadows.batch);
    const bool reuse = shadows.enabled && batches == 1 && keep_shadow_maps && shadow_maps_kept;
    if (shadows.enabled && !reuse) {
      auto ts = Clock::now();
      use_depth_convention(false);
      RVR_TRY(render_shadow_maps(samples, first, end, shadows.light_projection, pass.upload));
      gl().Finish();
      shadow_time += seconds_since(ts);
      shadow_maps_kept = batches == 1 && keep_shadow_maps;
    }
    use_depth_convention(reversed);
    gl().Viewport(0, 0, w, h);
    gl().Enable(GL_DEPTH_TEST);
    if (b == 0) {
      if (pass.upload.csg_solids > 0) RVR_TRY(resolve_csg(pass, nearer, depth_clear));
      // Base pass: emission, ambient and the first batch of lights; ids etc. when single-sampled.
      gl().DepthFunc(nearer);
      gl().DepthMask(GL_TRUE);
      if (msaa > 1) {
        gl().BindFramebuffer(GL_FRAMEBUFFER, msaa_fbo);
        gl().ClearBufferfv(GL_COLOR, 0, glm::value_ptr(background));
        gl().ClearBufferfv(GL_DEPTH, 0, &depth_clear);
      } else {
        clear_scene_targets(pass.scene, depth_clear);
        gl().BeginQuery(GL_SAMPLES_PASSED, query);
      }
      draw_scene(pass, shade, first, end, true);
      if (msaa == 1) gl().EndQuery(GL_SAMPLES_PASSED);
    } else {
      // Additive pass for this batch's lights, on exactly the surfaces the base pass kept.
      gl().BindFramebuffer(GL_FRAMEBUFFER, msaa > 1 ? msaa_fbo : scene_fbo);
      gl().DrawBuffers(1, &colour_only);
      gl().DepthFunc(GL_EQUAL);
      gl().DepthMask(GL_FALSE);
      gl().Enable(GL_BLEND);
      gl().BlendFunc(GL_ONE, GL_ONE);
      draw_scene(pass, true, first, end, false);
      gl().Disable(GL_BLEND);
      gl().DepthMask(GL_TRUE);
      gl().DepthFunc(nearer);
    }
    if (progress && batches > 1) {
      const uint64_t triangles = vertices.size() / 3;
      progress->advance(1, triangles * (1 + (shadows.enabled ? 6 * (end - first) : 0)));
    }
  }
  if (msaa > 1) {
    // The per-pixel AOVs (ids, depth, normal) come from one sample at the pixel centre; the
    // colour is the multisampled one, resolved (averaged) over each pixel's samples.
    clear_scene_targets(pass.scene, depth_clear);
    gl().BeginQuery(GL_SAMPLES_PASSED, query);
    draw_scene(pass, false, 0, 0, true);
    gl().EndQuery(GL_SAMPLES_PASSED);
    gl().BindFramebuffer(GL_READ_FRAMEBUFFER, msaa_fbo);
    gl().ReadBuffer(GL_COLOR_ATTACHMENT0);
    gl().BindFramebuffer(GL_DRAW_FRAMEBUFFER, scene_fbo);
    gl().DrawBuffers(1, &colour_only);
    gl().BlitFramebuffer(0, 0, w, h, 0, 0, w, h, GL_COLOR_BUFFER_BIT, GL_NEAREST);
  }
  gl().BindFramebuffer(GL_FRAMEBUFFER, scene_fbo);
  draw_to_every_target();
  gl().Finish();
  gl().Disable(GL_CLIP_DISTANCE0);
  use_depth_convention(false);
  RVR_GL_CHECK("scene pass");
  out.stats["time.render"] = seconds_since(t) - shadow_time;
  out.stats["zbuffer.depth_bits"] = double(depth_bits);
  if (shadows.enabled) {
    out.stats["time.shadow_maps"] = shadow_time;
    out.stats["shadow_map.maps"] = double(samples.size());
    out.stats["shadow_map.faces"] = 6.0 * double(samples.size());
    out.stats["shadow_map.size"] = double(shadows.map_size);
    out.stats["shadow_map.texels"] =
        6.0 * double(shadows.map_size) * double(shadows.map_size) * double(samples.size());
    out.stats["shadow_map.batches"] = double(batches);
  }
  return ok_status();
}

// --- cost pass: every fragment generated, whatever the depth test would say
Status GlRasterizer::Impl::cost_pass(const ScenePass& pass) {
  const glm::vec4 zero(0.0f);
  gl().BindFramebuffer(GL_FRAMEBUFFER, cost_fbo);
  gl().ClearBufferfv(GL_COLOR, 0, glm::value_ptr(zero));
  gl().Disable(GL_DEPTH_TEST);
  gl().Enable(GL_BLEND);
  gl().BlendFunc(GL_ONE, GL_ONE);
  gl().UseProgram(cost_program);
  gl().UniformMatrix4fv(cost_view, 1, GL_FALSE, glm::value_ptr(pass.view));
  gl().UniformMatrix4fv(cost_projection, 1, GL_FALSE, glm::value_ptr(pass.projection));
  // The same clipping as the scene passes (their projection's z range).
  use_depth_convention(pass.depth_format == DepthFormat::D32FReversed);
  if (!vertices.empty()) gl().DrawArrays(GL_TRIANGLES, 0, GLsizei(vertices.size()));
  use_depth_convention(false);
  gl().Disable(GL_BLEND);
  gl().Finish();
  RVR_GL_CHECK("cost pass");
  return ok_status();
}

// --- readback: the targets into the FrameBuffers, rows flipped (GL rows are bottom-up). Every
// target in local and full mode; in visibility mode ids and depth only, the colour filled with
// the background and the normal with 0 here. The cost target only after a cost pass, else 0.
Status GlRasterizer::Impl::readback(int w, int h, const ScenePass& pass, FrameBuffers& fb,
                                    uint64_t& samples_passed) {
  fb.width = w;
  fb.height = h;
  const size_t n = fb.pixel_count();
  fb.colour.resize(n);
  fb.depth.resize(n);
  fb.object_id.resize(n);
  fb.primitive_id.resize(n);
  fb.normal.resize(n);
  fb.cost.resize(n);
  gl().PixelStorei(GL_PACK_ALIGNMENT, 1);
  // Each attachment is read in its stored layout into reused scratch memory, then copied once
  // into the FrameBuffers with rows flipped.
  auto read_scalar = [&](GLuint fbo, int attachment, GLenum format, GLenum type, auto& dst) {
    using T = typename std::decay_t<decltype(dst)>::value_type;
    static_assert(sizeof(T) == 4);
    scratch.resize(n);
    gl().BindFramebuffer(GL_READ_FRAMEBUFFER, fbo);
    gl().ReadBuffer(GLenum(GL_COLOR_ATTACHMENT0 + attachment));
    gl().ReadPixels(0, 0, w, h, format, type, scratch.data());
    for (int y = 0; y < h; ++y)
      std::memcpy(dst.data() + size_t(y) * size_t(w),
                  scratch.data() + size_t(h - 1 - y) * size_t(w), size_t(w) * sizeof(T));
  };
  auto read_rgb = [&](int attachment, PixelVector<glm::vec3>& dst) {
    scratch_rgba.resize(n);
    gl().BindFramebuffer(GL_READ_FRAMEBUFFER, scene_fbo);
    gl().ReadBuffer(GLenum(GL_COLOR_ATTACHMENT0 + attachment));
    gl().ReadPixels(0, 0, w, h, GL_RGBA, GL_FLOAT, scratch_rgba.data());
    for (int y = 0; y < h; ++y) {
      const glm::vec4* src = scratch_rgba.data() + size_t(h - 1 - y) * size_t(w);
      glm::vec3* row = dst.data() + size_t(y) * size_t(w);
      for (int x = 0; x < w; ++x) row[x] = glm::vec3(src[x]);
    }
  };
  if (pass.options.mode == RenderMode::Visibility) {
    std::fill(fb.colour.begin(), fb.colour.end(), pass.scene.image.background);
    std::fill(fb.normal.begin(), fb.normal.end(), glm::vec3(0.0f));
  } else {
    read_rgb(kColour, fb.colour);
    read_rgb(kNormal, fb.normal);
  }
  read_scalar(scene_fbo, kObjectId, GL_RED_INTEGER, GL_UNSIGNED_INT, fb.object_id);
  read_scalar(scene_fbo, kPrimitiveId, GL_RED_INTEGER, GL_UNSIGNED_INT, fb.primitive_id);
  read_scalar(scene_fbo, kViewDepth, GL_RED, GL_FLOAT, fb.depth);
  fb.lod.clear();
  if (lod_target) {
    fb.lod.resize(n);
    read_scalar(scene_fbo, kLod, GL_RED, GL_FLOAT, fb.lod);
  }
  if (pass.options.cost_aov)
    read_scalar(cost_fbo, 0, GL_RED, GL_FLOAT, fb.cost);
  else
    std::fill(fb.cost.begin(), fb.cost.end(), 0.0f);
  GLuint64 passed = 0;
  gl().GetQueryObjectui64v(query, GL_QUERY_RESULT, &passed);
  RVR_GL_CHECK("readback");
  samples_passed = uint64_t(passed);
  return ok_status();
}

Expected<RenderOutput> GlRasterizer::Impl::render(const Scene& scene,
                                                  const RenderOptions& options) {
  // Several samples per pixel: the accumulation buffer, a pass per sample (unless msaa).
  // The passes of one render (its samples' and its mirrors') share their shadow maps.
  const bool accumulate =
      accumulates(scene, options) && options.supersampling == Supersampling::Accumulation;
  keep_shadow_maps = true;
  shadow_maps_kept = false;
  Expected<RenderOutput> out =
      accumulate
          ? render_accumulated(scene, options,
                               [&](const RenderOptions& pass) { return render_pass(scene, pass); })
          : render_pass(scene, options);
  keep_shadow_maps = shadow_maps_kept = false;
  if (out) add_depth_of_field_blur(scene, options, *out);
  return out;
}

Expected<RenderOutput> GlRasterizer::Impl::render_pass(const Scene& scene,
                                                       const RenderOptions& options) {
  const int w = scene.image.width, h = scene.image.height;
  if (w < 1 || h < 1) return bad_input(fmt::format("image size {}x{} is empty", w, h));
  RenderOutput out;
  ProgressSink* progress = options.progress;  // null when nobody is watching
  csg_counts = CsgCounts{};

  // --- setup: context, programs (first call only), render targets (on size change)
  if (progress) progress->begin("setup");
  auto t = Clock::now();
  RVR_TRY(init());
  out.warnings = context_warnings;
  // Unset: the most precise this GL offers. Reversed-Z needs ARB_clip_control: without it
  // window z is (z_ndc + 1) / 2, whose float rounding near 1 undoes the reversal.
  const DepthFormat depth_format =
      options.depth_format.value_or(clip_control ? DepthFormat::D32FReversed : DepthFormat::D32F);
  if (depth_format == DepthFormat::D32FReversed && !clip_control)
    return bad_input("--depth-format d32f_reversed: this GL does not offer ARB_clip_control");
  out.info["depth_format"] = to_string(depth_format);
  RVR_TRY(resize(w, h, depth_internal_format(depth_format)));
  out.stats["time.setup"] = seconds_since(t);

  if (progress) progress->begin("upload");  // mostly one glBufferData: time only
  t = Clock::now();
  RVR_TRY_ASSIGN(uploaded, upload(scene, options));
  out.stats["time.upload"] = seconds_since(t);

  lod_target =
      uploaded->textured && (options.mode != RenderMode::Visibility || options.visibility_lod);
  if (lod_target)
    out.info["lod"] = query_lod ? "textureQueryLOD (ARB_texture_query_lod)"
                                : "log2 of the longer of dFdx, dFdy in texels";
  RVR_TRY_ASSIGN(shadows, plan_shadows(options, uploaded->samples, out));

  // --- multisampling: colour into a multisampled FBO, resolved into the colour target
  int msaa = 1;
  if (options.mode != RenderMode::Visibility && scene.image.samples_per_pixel > 1 &&
      options.supersampling == Supersampling::Msaa && !options.image_sample) {
    msaa = std::min(scene.image.samples_per_pixel, int(max_samples));
    if (msaa < scene.image.samples_per_pixel)
      out.warnings.push_back(
          fmt::format("{} samples per pixel requested; the GL allows {}, rendered {}",
                      scene.image.samples_per_pixel, max_samples, msaa));
    RVR_TRY(ensure_msaa(msaa));
  }

  // One accumulation-buffer pass (the hybrid's): the camera as that sample sees it.
  const glm::mat4 camera_projection =
      options.image_sample ? sample_projection_matrix(scene.camera, w, h, *options.image_sample)
                           : projection_matrix(scene.camera, w, h);
  const ScenePass pass{
      scene,
      options,
      *uploaded,
      *shadows,
      options.image_sample ? sample_view_matrix(scene.camera, *options.image_sample)
                           : view_matrix(scene.camera),
      depth_format == DepthFormat::D32FReversed
          ? reversed_z_projection(camera_projection, scene.camera.near, scene.camera.far)
          : camera_projection,
      depth_format,
      options.image_sample ? sample_eye(scene.camera, *options.image_sample) : scene.camera.eye,
      w,
      h};
  RVR_TRY(scene_passes(pass, msaa, out));
  if (is_cancelled(progress)) return cancelled_error();

  if (options.cost_aov) {
    if (progress) progress->begin("cost");
    t = Clock::now();
    RVR_TRY(cost_pass(pass));
    out.stats["time.cost"] = seconds_since(t);
  }

  if (progress) progress->begin("readback");
  t = Clock::now();
  FrameBuffers& fb = out.buffers;
  uint64_t passed = 0;
  RVR_TRY(readback(w, h, pass, fb, passed));
  out.stats["time.readback"] = seconds_since(t);

  double generated = 0.0;
  size_t covered = 0;
  for (size_t i = 0; i < fb.pixel_count(); ++i) {
    generated += double(fb.cost[i]);
    covered += fb.object_id[i] != kNoId ? 1 : 0;
  }
  const size_t triangles_submitted = size_t(uploaded->plain_vertices) / 3;  // no index
  out.stats["triangles.submitted"] = double(triangles_submitted);
  if (options.cost_aov) {  // counted by the cost pass only
    out.stats["fragments.generated"] = generated;
    out.stats["overdraw"] = covered > 0 ? generated / double(covered) : 0.0;
  }
  out.stats["fragments.passed"] = double(passed);
  out.stats["pixels.covered"] = double(covered);
  size_t csg_pixels = 0;
  for (uint32_t id : fb.object_id) csg_pixels += id != kNoId && uploaded->prepared.objects[id].csg;

  std::vector<EnvironmentMapped> mapped;
  std::vector<std::string> left_out;  // transparent planar mirrors
  if (options.mode == RenderMode::Full) {
    const std::vector<PlanarMirror> mirrors = planar_mirrors(uploaded->prepared);
    if (!mirrors.empty()) RVR_TRY(add_mirrors(pass, mirrors, out));
    mapped = environment_mapped(scene, uploaded->prepared, mirrors, left_out);
    // Last: its faces resize the targets.
    if (!mapped.empty() && options.cube_map_size > 0) RVR_TRY(add_cube_maps(pass, mapped, out));
    if (!mapped.empty() && options.cube_map_size == 0) mark_left_out(mapped, out.buffers);
  }
  note_what_a_zbuffer_leaves_out(scene, options, mapped, left_out, out.warnings);
  if (uploaded->csg_solids > 0) {  // over every view drawn, the shadow cubes' faces too
    out.stats["csg.objects"] = double(uploaded->csg_solids);
    out.stats["csg.leaf_passes"] = double(csg_counts.leaf_passes);
    out.stats["csg.pixels"] = double(csg_pixels);
    out.stats["time.csg"] = csg_counts.seconds;
  }
  return out;
}

// Full mode's planar mirrors: a view per mirror seen, drawn and shaded single-sampled as the
// camera's pass is, read back and composited into `out` (planar_mirrors.h).
Status GlRasterizer::Impl::add_mirrors(const ScenePass& camera,
                                       const std::vector<PlanarMirror>& mirrors,
                                       RenderOutput& out) {
  const auto t = Clock::now();
  const int w = camera.scene.image.width, h = camera.scene.image.height;
  MirrorStats stats;
  const MirrorViewPass draw_view = [&](const MirrorView& view) -> Expected<FrameBuffers> {
    ScenePass pass = camera;
    pass.view = glm::mat4(glm::dmat4(camera.view) * view.reflection);
    pass.eye = view.eye;
    pass.clipped = view.keep.has_value();
    if (view.keep) pass.keep = glm::vec4(*view.keep);
    pass.hidden = view.hidden;
    RenderOutput reflected;
    RVR_TRY(scene_passes(pass, 1, reflected));
    uint64_t passed = 0;
    RVR_TRY(readback(w, h, pass, reflected.buffers, passed));
    return std::move(reflected.buffers);
  };
  MirrorView view;
  view.eye = camera.eye;
  RVR_TRY(add_planar_reflections(mirrors, camera.options.max_depth, view, draw_view, out.buffers,
                                 stats));
  record_mirror_stats(stats, seconds_since(t), out);
  return ok_status();
}

// Full mode's curved mirrors and transparent objects: six single-sampled faces per object seen,
// drawn and shaded as the camera's pass is into targets resized to the face, read back and
// looked up at the object's pixels (environment_maps.h).
Status GlRasterizer::Impl::add_cube_maps(const ScenePass& camera,
                                         const std::vector<EnvironmentMapped>& mapped,
                                         RenderOutput& out) {
  const auto t = Clock::now();
  EnvironmentStats stats;
  // The faces' own shadow maps, at the map's resolution: drawn by the first face and kept for
  // the others when they fit one batch.
  RenderOptions face_options = camera.options;
  face_options.shadow_map_size = cube_face_shadow_map_size(camera.options);
  RenderOutput planned;
  RVR_TRY_ASSIGN(face_shadows, plan_shadows(face_options, camera.upload.samples, planned));
  for (const std::string& w : planned.warnings)
    if (std::find(out.warnings.begin(), out.warnings.end(), w) == out.warnings.end())
      out.warnings.push_back(w);
  const CubeFacePass draw_face = [&](const CubeFace& face) -> Expected<FrameBuffers> {
    RVR_TRY(resize(face.size, face.size, depth_internal_format(camera.depth_format)));
    ScenePass pass{camera.scene, camera.options,    camera.upload,       *face_shadows,
                   camera.view,  camera.projection, camera.depth_format, camera.eye,
                   camera.width, camera.height};
    pass.view = glm::mat4(face.view);
    pass.projection = camera.depth_format == DepthFormat::D32FReversed
                          ? reversed_z_projection(glm::mat4(face.projection), face.near, face.far)
                          : glm::mat4(face.projection);
    pass.eye = face.eye;
    pass.width = pass.height = face.size;
    pass.hidden = {face.hidden};
    RenderOutput drawn;
    RVR_TRY(scene_passes(pass, 1, drawn));
    uint64_t passed = 0;
    RVR_TRY(readback(face.size, face.size, pass, drawn.buffers, passed));
    return std::move(drawn.buffers);
  };
  RVR_TRY(
      add_environment_maps(camera.scene, camera.options, mapped, draw_face, out.buffers, stats));
  record_environment_stats(stats, seconds_since(t), out);
  return ok_status();
}

GlRasterizer::GlRasterizer(GlBackend backend) : impl_(std::make_unique<Impl>()) {
  impl_->backend = backend;
}

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
