#include "rvr/raster/soft_rasterizer.h"

#include <fmt/format.h>
#include <stddef.h>
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

#include <algorithm>
#include <chrono>
#include <cstdint>
#include <glm/glm.hpp>
#include <glm/gtc/matrix_transform.hpp>
#include <limits>
#include <map>
#include <new>
#include <optional>
#include <string>
#include <utility>
#include <variant>
#include <vector>

#include "accumulation_buffer.h"
#include "depth_of_field_blur.h"
#include "draw_list_prep.h"
#include "environment_maps.h"
#include "planar_mirrors.h"
#include "rvr/core/camera.h"
#include "rvr/core/framebuffers.h"
#include "rvr/core/image_sample.h"
#include "rvr/core/isa.h"
#include "rvr/core/progress.h"
#include "rvr/core/shade_kernel.h"
#include "rvr/core/shading.h"
#include "rvr/core/shapes/triangle_mesh.h"
#include "rvr/core/surface_colour.h"
#include "rvr/core/timer.h"
#include "shadow_plan.h"
#include "soft/csg_pass.h"
#include "soft/deferred_shading.h"
#include "soft/draw_triangles.h"
#include "soft/fill_dispatch.h"
#include "soft/fill_kernel.h"
#include "soft/shadow_cube.h"
#include "soft/surface_texture.h"
#include "soft/tile_raster.h"
#include "soft/triangle_setup.h"

namespace rvr {

namespace {

using Clock = std::chrono::steady_clock;

using soft::DepthTarget;
using soft::DrawList;
using soft::DrawObject;
using soft::DrawResult;

Status check_image_size(int w, int h) {
  if (w < 1 || h < 1) return bad_input(fmt::format("image size {}x{} is empty", w, h));
  if (w > soft::kMaxImageSide || h > soft::kMaxImageSide)
    return bad_input(fmt::format("image size {}x{}: softraster draws at most {} pixels a side", w,
                                 h, soft::kMaxImageSide));
  return ok_status();
}

// The draw list of the prepared objects (a CSG object: no mesh, nothing drawn), and whether some
// drawn material is a mirror or transparent (effects a z-buffer leaves out).
struct SceneDraws {
  DrawList list;
  bool mirror = false, transparency = false, csg = false;
};

SceneDraws scene_draws(const PreparedScene& prepared) {
  SceneDraws draws;
  std::vector<DrawObject> objects(prepared.objects.size());
  for (size_t i = 0; i < objects.size(); ++i) {
    const PreparedObject& p = prepared.objects[i];
    DrawObject& d = objects[i];
    d.material = p.material;
    if (!p.mesh) continue;
    d.mesh = p.mesh;
    d.smooth = p.smooth;
    d.use_primitive_id = p.names_triangles;
    d.csg = p.csg;
    draws.csg |= p.csg != nullptr;
    d.csg_leaf_triangles = p.csg_leaf_triangles;
    draws.mirror |= d.material->mirror > 0.0f;
    draws.transparency |= d.material->transparency > 0.0f;
  }
  draws.list = soft::make_draw_list(std::move(objects));
  return draws;
}

// The camera's view-projection; for one accumulation-buffer pass (the hybrid's), the camera as
// that sample sees it.
glm::dmat4 camera_view_projection(const Scene& scene, const RenderOptions& options, int w, int h) {
  return options.image_sample
             ? glm::dmat4(sample_projection_matrix(scene.camera, w, h, *options.image_sample)) *
                   glm::dmat4(sample_view_matrix(scene.camera, *options.image_sample))
             : glm::dmat4(projection_matrix(scene.camera, w, h)) *
                   glm::dmat4(view_matrix(scene.camera));
}

// The kept target cleared, or built anew when its setup changed; inside the arena, so that its
// parallel clear uses the threads the options allow. The camera pass's depth test as the format
// would store depth (unset: the view depth in double precision); shadow maps keep exact
// distances.
DepthTarget& camera_target(const RenderOptions& options, int w, int h, float near, float far,
                           const soft::FillKernels& kernels, tbb::task_arena& arena,
                           std::optional<DepthTarget>& kept) {
  // Barycentrics for shading, fragment counts for the cost AOV: a visibility pass without it
  // (the hybrids') writes depth and ids alone.
  const soft::TargetArrays arrays{/*ids=*/true, options.mode != RenderMode::Visibility,
                                  options.cost_aov};
  arena.execute([&] {
    if (kept && kept->same_setup(w, h, near, far, options.hiz, kernels, arrays))
      kept->clear();
    else
      kept.emplace(w, h, near, far, options.hiz, kernels, arrays);
  });
  kept->set_depth_format(!options.depth_format                        ? soft::kDepthExact
                         : *options.depth_format == DepthFormat::D24  ? soft::kDepthD24
                         : *options.depth_format == DepthFormat::D32F ? soft::kDepthD32F
                                                                      : soft::kDepthD32FReversed);
  return *kept;
}

// The visible surface at pixel o (covered): position, normals, direction to the eye. The shadow
// pass adds the lights with it; the shading kernels do the same float operations.
struct Surface {
  const DrawObject* object;
  uint32_t primitive;
  glm::vec3 P, N, V, geometric;
  bool varies = false;  // textured or vertex-coloured: `own` is its material at P
  Material own;         // the object's, with the base colour at P as its diffuse
  const Material& material() const { return varies ? own : *object->material; }
};

// What the visible surfaces of a shaded frame are rebuilt from.
struct VisibleFrame {
  const Scene& scene;
  const DrawList& list;
  const DepthTarget& target;
  const soft::SurfaceColours* surfaces;
  const FrameBuffers& fb;
  glm::vec3 eye;  // where the pass looks from: the camera's eye or a sample's lens point
};

Surface surface_at(const VisibleFrame& frame, size_t o) {
  const DepthTarget& target = frame.target;
  Surface s;
  const uint32_t id = target.object(o);
  s.object = &frame.list.objects[id];
  s.primitive = target.primitive(o);
  const TriangleMesh& mesh = *s.object->mesh;
  const glm::vec3 b = target.barycentric(o);
  const glm::uvec3& tri = mesh.triangles[s.primitive];
  const glm::vec3 &p0 = mesh.positions[tri.x], &p1 = mesh.positions[tri.y],
                  &p2 = mesh.positions[tri.z];
  s.P = b.x * p0 + b.y * p1 + b.z * p2;
  s.geometric = glm::normalize(glm::cross(p1 - p0, p2 - p0));
  const glm::vec3 shading =
      s.object->smooth ? glm::normalize(b.x * mesh.normals[tri.x] + b.y * mesh.normals[tri.y] +
                                        b.z * mesh.normals[tri.z])
                       : s.geometric;
  s.V = glm::normalize(frame.eye - s.P);
  s.N = face_viewer(shading, s.geometric, s.V);
  if (frame.surfaces && frame.surfaces->varies(id)) {
    // The level of detail the deferred pass sampled at (kept in fb.lod when textured).
    const float lod = frame.fb.lod.empty() ? 0.0f : frame.fb.lod[o];
    s.varies = true;
    s.own = with_diffuse(*s.object->material,
                         base_colour(frame.scene, frame.scene.objects[id], *s.object->material,
                                     s.primitive, b.y, b.z, lod));
  }
  return s;
}

// The shadow cubes' plan (shadow_plan.h) for the scene's meshes, as this z-buffer's settings.
Expected<soft::ShadowSettings> shadow_settings(const RenderOptions& options, const DrawList& list,
                                               const std::vector<LightSample>& samples,
                                               ShadowMapPlan& plan,
                                               std::vector<std::string>& warnings) {
  glm::vec3 lo(std::numeric_limits<float>::max()), hi(-std::numeric_limits<float>::max());
  bool any = false;
  for (const DrawObject& d : list.objects)
    if (d.mesh)
      for (const glm::vec3& p : d.mesh->positions) {
        lo = glm::min(lo, p);
        hi = glm::max(hi, p);
        any = true;
      }
  RVR_TRY_ASSIGN(planned, plan_shadow_maps(options, samples, soft::kMaxImageSide, samples.size(),
                                           lo, hi, any, warnings));
  plan = *planned;
  soft::ShadowSettings settings;
  settings.size = plan.size;
  settings.bias = options.shadow_bias;
  settings.pcf = options.shadow_pcf;
  settings.projection =
      glm::dmat4(glm::perspective(glm::radians(90.0f), 1.0f, plan.near_plane, plan.far_plane));
  return settings;
}

// The shadow cubes the passes of one accumulation buffer share: they do not depend on the view,
// so when every sample's cube fits in one batch the first pass draws them and the others sample
// the same cubes (one render's passes only: the same scene and options).
struct KeptShadowCubes {
  std::vector<soft::ShadowCube> cubes;
  bool drawn = false;
};

// Full mode's shadows: a cube of distance maps per light sample, drawn by this z-buffer, in
// batches that fit kShadowBatchBytes; each batch then adds its samples' light to the covered
// pixels. With `kept` and one batch, the cubes are drawn once into it and reused.
Status add_shadowed_light(const VisibleFrame& frame, const std::vector<LightSample>& samples,
                          const RenderOptions& options, const soft::FillKernels& kernels,
                          tbb::task_arena& arena, KeptShadowCubes* kept, FrameBuffers& fb,
                          RenderOutput& out) {
  ShadowMapPlan plan;
  RVR_TRY_ASSIGN(planned, shadow_settings(options, frame.list, samples, plan, out.warnings));
  const auto t = Clock::now();
  const soft::ShadowSettings settings = *planned;
  const float near_plane = plan.near_plane, far_plane = plan.far_plane;
  const size_t per_sample = 6 * size_t(settings.size) * size_t(settings.size) * sizeof(float);
  const size_t batch = plan.batch;
  const bool keep = kept && batch >= samples.size();
  const bool reuse = keep && kept->drawn;
  std::optional<DepthTarget> scratch_built;
  if (!reuse)
    arena.execute([&] {
      scratch_built.emplace(settings.size, settings.size, near_plane, far_plane, options.hiz,
                            kernels, soft::kDepthOnly);
    });
  std::vector<soft::ShadowCube> own_cubes;
  std::vector<soft::ShadowCube>& cubes = keep ? kept->cubes : own_cubes;
  if (!reuse) cubes.assign(batch, soft::ShadowCube{});
  DrawResult shadow_work;
  double draw_seconds = 0;
  ProgressSink* const progress = options.progress;
  if (progress) progress->begin("shadows", samples.size(), "light samples");
  for (size_t first = 0; first < samples.size(); first += batch) {
    if (is_cancelled(progress)) return cancelled_error();
    const size_t end = std::min(samples.size(), first + batch);
    auto t_draw = Clock::now();
    if (!reuse)
      for (size_t i = first; i < end; ++i)
        cubes[i - first].build(frame.list, samples[i].position, settings, *scratch_built, arena,
                               shadow_work);
    draw_seconds += seconds_since(t_draw);
    arena.execute([&] {
      tbb::parallel_for(tbb::blocked_range<size_t>(0, fb.pixel_count()),
                        [&](const tbb::blocked_range<size_t>& r) {
                          for (size_t o = r.begin(); o != r.end(); ++o) {
                            if (!frame.target.covered(o)) continue;
                            const Surface s = surface_at(frame, o);
                            add_light_samples(
                                s.material(), s.P, s.N, s.V, samples, first, end,
                                [&](size_t i, const glm::vec3& P, const glm::vec3& L) {
                                  return cubes[i - first].visibility(P, L, s.geometric, settings);
                                },
                                fb.colour[o]);
                          }
                        });
    });
    if (progress) progress->advance(end - first);
  }
  out.stats["time.shadows"] = seconds_since(t);
  out.stats["time.shadow_maps"] = draw_seconds;
  out.stats["shadows.map_size"] = double(settings.size);
  out.stats["shadows.cubes"] = double(samples.size());
  out.stats["shadows.triangles_setup"] = double(shadow_work.set_up);
  out.stats["shadows.fragments"] = double(shadow_work.counters.generated);
  out.stats["shadows.hiz_blocks_rejected"] = double(shadow_work.counters.blocks_rejected);
  if (keep) kept->drawn = true;
  out.stats["memory.shadow_bytes"] =
      double(batch * per_sample + (scratch_built ? scratch_built->bytes() : 0) +
             shadow_work.peak_chunk_bytes);
  return ok_status();
}

// The camera pass's counts: triangles, fragments, covered pixels, blocks, memory.
void record_draw_stats(const DrawResult& drawn, const DepthTarget& target, size_t submitted,
                       bool shaded, RenderOutput& out) {
  const soft::TileCounters& sum = drawn.counters;
  const size_t covered = target.covered_pixels();
  out.stats["triangles.submitted"] = double(submitted);
  out.stats["triangles.clipped"] = double(drawn.clipped);
  out.stats["triangles.setup"] = double(drawn.set_up);
  out.stats["fragments.generated"] = double(sum.generated);
  out.stats["fragments.shaded"] = shaded ? double(covered) : 0.0;
  out.stats["pixels.covered"] = double(covered);
  out.stats["overdraw"] = covered > 0 ? double(sum.generated) / double(covered) : 0.0;
  out.stats["blocks.full"] = double(sum.blocks_full);
  out.stats["hiz.blocks_rejected"] = double(sum.blocks_rejected);
  out.stats["hiz.triangles_rejected"] = double(sum.triangles_rejected);
  out.stats["memory.raster_bytes"] = double(target.bytes() + drawn.peak_chunk_bytes);
}

// The CSG pass's counts: its leaf passes' work and the pixels it wrote.
void record_csg_stats(const soft::CsgPassResult& csg, double seconds, RenderOutput& out) {
  out.stats["csg.objects"] = double(csg.objects);
  out.stats["csg.leaf_passes"] = double(csg.leaf_passes);
  out.stats["csg.fragments"] = double(csg.drawn.counters.generated);
  out.stats["csg.pixels"] = double(csg.pixels);
  out.stats["time.csg"] = seconds;
}

// What this z-buffer leaves out of the scene. The warnings do not name the renderer: whoever
// prints them says whose they are.
void note_what_is_left_out(const Scene& scene, const RenderOptions& options,
                           const std::vector<EnvironmentMapped>& mapped,
                           const std::vector<std::string>& left_out,
                           std::vector<std::string>& warnings) {
  if (options.mode == RenderMode::Full) {
    note_environment_maps(scene, options, mapped, left_out, warnings);
    if (scene.camera.aperture_radius > 0.0f && scene.image.samples_per_pixel == 1)
      warnings.push_back(kDepthOfFieldNeedsSamples);
  }
}

// One pass's eye: the camera's, or the lens point of the accumulation-buffer sample it draws.
glm::vec3 pass_eye(const Scene& scene, const RenderOptions& options) {
  return options.image_sample ? sample_eye(scene.camera, *options.image_sample) : scene.camera.eye;
}

// What a render sets up once for every view it draws (the camera's and its mirrors').
struct RenderSetup {
  const Scene& scene;
  const RenderOptions& options;
  Isa isa;
  const soft::FillKernels& kernels;
  tbb::task_arena& arena;
  const DrawList& list;
  bool csg;                                 // some object of `list` is a CSG solid
  const std::vector<LightSample>& samples;  // empty: no shading
  std::optional<DepthTarget>& kept;
  KeptShadowCubes& kept_shadows;
};

// Where a view is drawn: its view-projection, its frame's size, near and far planes and the
// target kept for it.
struct ViewFrame {
  glm::dmat4 view_projection;
  int width, height;
  float near, far;
  std::optional<DepthTarget>& kept;
};

// The camera's frame for a view seen through mirrors (`reflection`, identity for the camera's).
ViewFrame camera_frame(const RenderSetup& setup, const glm::dmat4& reflection) {
  const Scene& scene = setup.scene;
  const int w = scene.image.width, h = scene.image.height;
  return {camera_view_projection(scene, setup.options, w, h) * reflection,
          w,
          h,
          scene.camera.near,
          scene.camera.far,
          setup.kept};
}

// `list` without the objects `hidden` (a mirror's view does not draw the mirror, nor a view
// behind a layer the layer); ids stay the same.
DrawList without_objects(const DrawList& list, const std::vector<uint32_t>& hidden) {
  std::vector<DrawObject> objects = list.objects;
  for (uint32_t object : hidden) objects[object].mesh = nullptr;
  return soft::make_draw_list(std::move(objects));
}

// One view (the camera's, one seen through mirrors, or a cube map's face: `view` through
// `frame`), drawn into the frame's kept target and, per mode, read back (visibility) or shaded
// once per visible pixel with, in full mode, the shadowed lights. `drawn` receives the draw's
// counts.
Status draw_view(const RenderSetup& setup, const MirrorView& view, const ViewFrame& frame,
                 RenderOutput& out, DrawResult& drawn) {
  const Scene& scene = setup.scene;
  const RenderOptions& options = setup.options;
  tbb::task_arena& arena = setup.arena;
  const int w = frame.width, h = frame.height;
  ProgressSink* const progress = options.progress;
  auto t = Clock::now();
  const auto t_visibility = t;
  std::optional<DrawList> own_list;
  if (!view.hidden.empty()) own_list = without_objects(setup.list, view.hidden);
  const DrawList& list = own_list ? *own_list : setup.list;
  const glm::dmat4& view_projection = frame.view_projection;
  // Textured and vertex-coloured objects (none: no per-pixel work at all).
  std::optional<soft::SurfaceColours> surfaces;
  if (options.mode != RenderMode::Visibility || options.visibility_lod) {
    surfaces.emplace(scene, view_projection, w, h);
    if (!surfaces->any()) surfaces.reset();
  }
  out.stats["time.setup"] = seconds_since(t);

  // Draw: every triangle into the camera's target.
  DepthTarget& target =
      camera_target(options, w, h, frame.near, frame.far, setup.kernels, arena, frame.kept);
  // The fraction in triangles, the speed in fragments.
  if (progress) progress->begin("draw", list.triangles(), "triangles", "fragments");
  drawn = soft::draw_triangles(list, view_projection, target, arena, progress, view.keep);
  if (is_cancelled(progress)) return cancelled_error();
  if (setup.csg) {
    const auto t_csg = Clock::now();
    const soft::CsgPassResult csg =
        soft::draw_csg_objects(list, view_projection, view.eye, view.keep, target, arena);
    record_csg_stats(csg, seconds_since(t_csg), out);
  }
  out.stats["time.setup"] += drawn.setup_seconds;
  out.stats["time.bin"] = drawn.bin_seconds;
  out.stats["time.raster"] = drawn.raster_seconds;
  // Everything before shading: setup, clearing the target, binning, raster.
  out.stats["time.visibility"] = seconds_since(t_visibility);
  FrameBuffers& fb = out.buffers;

  // Visibility mode: the target's depth, ids and cost into the frame buffers, no shading.
  if (options.mode == RenderMode::Visibility) {
    t = Clock::now();
    if (progress) progress->begin("readback", uint64_t(w) * uint64_t(h), "pixels");
    const soft::SurfaceColours* lod_surfaces = surfaces ? &*surfaces : nullptr;
    if (options.visibility_ids_only)
      soft::give_visibility_ids(list, target, lod_surfaces, arena, progress, fb);
    else
      soft::write_visibility(list, target, scene.image.background, options.cost_aov, lod_surfaces,
                             arena, progress, fb);
    out.stats["time.readback"] = seconds_since(t);
    return ok_status();
  }

  // Shade (local and full mode): deferred, each visible pixel once.
  t = Clock::now();
  const bool shadows = options.mode == RenderMode::Full && !setup.samples.empty();
  if (progress) progress->begin("shade", uint64_t(w) * uint64_t(h), "pixels");
  soft::DeferredShading shading;
  shading.eye = view.eye;
  shading.ambient = scene.ambient;
  shading.background = scene.image.background;
  shading.colour = shadows ? soft::ShadedColour::Base : soft::ShadedColour::Local;
  shading.samples = &setup.samples;
  shading.cost = options.cost_aov;
  shading.surfaces = surfaces ? &*surfaces : nullptr;
  soft::shade_pixels(list, target, shading, shade_kernels(setup.isa), arena, progress, fb);
  if (is_cancelled(progress)) return cancelled_error();
  out.stats["time.shade"] = seconds_since(t);

  // Shadows (full mode): the lights, seen through this z-buffer's shadow cubes.
  if (shadows) {
    // The lights' shadow cubes hold every object, the one this view hides included.
    const VisibleFrame visible{scene, setup.list, target, surfaces ? &*surfaces : nullptr,
                               fb,    view.eye};
    RVR_TRY(add_shadowed_light(visible, setup.samples, options, setup.kernels, arena,
                               &setup.kept_shadows, fb, out));
  }
  return ok_status();
}

// Full mode's planar mirrors: a view per mirror seen, drawn and shaded as the camera's is,
// composited into `out` (planar_mirrors.h). The reflected views' own counts are not the
// camera pass's: they go to the mirror stats only.
Status add_mirrors(const RenderSetup& setup, const std::vector<PlanarMirror>& mirrors,
                   const MirrorView& camera, RenderOutput& out) {
  const auto t = Clock::now();
  MirrorStats stats;
  const MirrorViewPass pass = [&](const MirrorView& view) -> Expected<FrameBuffers> {
    RenderOutput reflected;
    DrawResult drawn;
    RVR_TRY(draw_view(setup, view, camera_frame(setup, view.reflection), reflected, drawn));
    for (const std::string& w : reflected.warnings)
      if (std::find(out.warnings.begin(), out.warnings.end(), w) == out.warnings.end())
        out.warnings.push_back(w);
    return std::move(reflected.buffers);
  };
  RVR_TRY(
      add_planar_reflections(mirrors, setup.options.max_depth, camera, pass, out.buffers, stats));
  record_mirror_stats(stats, seconds_since(t), out);
  return ok_status();
}

// Full mode's curved mirrors and transparent objects: six faces per object seen, each drawn and
// shaded as the camera's view is into a square target of its own, then looked up at the
// object's pixels (environment_maps.h). The faces' counts go to the cube-map stats only.
Status add_cube_maps(const RenderSetup& setup, const std::vector<EnvironmentMapped>& mapped,
                     RenderOutput& out) {
  const auto t = Clock::now();
  EnvironmentStats stats;
  std::optional<DepthTarget> face_target;
  // The faces' own shadow cubes, at the map's resolution: drawn once when they fit one batch.
  RenderOptions face_options = setup.options;
  face_options.shadow_map_size = cube_face_shadow_map_size(setup.options);
  KeptShadowCubes face_shadows;
  const RenderSetup face_setup{setup.scene, face_options, setup.isa, setup.kernels,
                               setup.arena, setup.list,   setup.csg, setup.samples,
                               setup.kept,  face_shadows};
  const CubeFacePass pass = [&](const CubeFace& face) -> Expected<FrameBuffers> {
    MirrorView view;
    view.eye = face.eye;
    view.hidden = {face.hidden};
    const ViewFrame frame{
        face.projection * face.view, face.size, face.size, face.near, face.far, face_target};
    RenderOutput drawn_face;
    DrawResult drawn;
    RVR_TRY(draw_view(face_setup, view, frame, drawn_face, drawn));
    for (const std::string& w : drawn_face.warnings)
      if (std::find(out.warnings.begin(), out.warnings.end(), w) == out.warnings.end())
        out.warnings.push_back(w);
    return std::move(drawn_face.buffers);
  };
  RVR_TRY(add_environment_maps(setup.scene, setup.options, mapped, pass, out.buffers, stats));
  record_environment_stats(stats, seconds_since(t), out);
  return ok_status();
}

// Setup (objects to triangles, then transform, clip, bin in submission order in the draw), the
// camera's view drawn and shaded, then in full mode the views its planar mirrors show.
Expected<RenderOutput> render_impl(const Scene& scene, const RenderOptions& options,
                                   std::optional<DepthTarget>& kept,
                                   KeptShadowCubes* kept_shadows = nullptr) {
  const int w = scene.image.width, h = scene.image.height;
  RVR_TRY(check_image_size(w, h));
  RenderOutput out;
  // The per-pixel kernels: RenderOptions::isa, else RVR_ISA, else the best this CPU runs.
  RVR_TRY_ASSIGN(resolved_isa, resolve_isa(options.isa));
  const Isa isa = *resolved_isa;
  const soft::FillKernels& kernels = soft::fill_kernels(isa);
  out.info["kernel"] = kernels.isa;
  tbb::task_arena arena(options.threads > 0 ? options.threads : tbb::task_arena::automatic);

  // Setup: the objects' meshes and materials (the tessellations live until shading ends).
  const auto t = Clock::now();
  RVR_TRY_ASSIGN(prepared, prepare_objects(scene, options.spheres, options.sphere_segments,
                                           options.zbuffer_left_out));
  const SceneDraws draws = scene_draws(*prepared);
  const bool shade = options.mode != RenderMode::Visibility;
  const std::vector<LightSample> samples =
      shade ? light_samples(scene.lights) : std::vector<LightSample>{};
  const double prepare_seconds = seconds_since(t);
  KeptShadowCubes own_shadows;  // shared by the camera's view and its mirrors' views
  const RenderSetup setup{
      scene,      options,   isa,     kernels, arena,
      draws.list, draws.csg, samples, kept,    kept_shadows ? *kept_shadows : own_shadows};
  out.info["depth_format"] =
      options.depth_format ? to_string(*options.depth_format) : "exact (view depth, double)";

  MirrorView camera;
  camera.eye = pass_eye(scene, options);
  DrawResult drawn;
  RVR_TRY(draw_view(setup, camera, camera_frame(setup, camera.reflection), out, drawn));
  out.stats["time.setup"] += prepare_seconds;
  out.stats["time.visibility"] += prepare_seconds;
  record_draw_stats(drawn, *kept, draws.list.triangles(), shade, out);

  std::vector<EnvironmentMapped> mapped;
  std::vector<std::string> left_out;  // transparent planar mirrors
  if (options.mode == RenderMode::Full && (draws.mirror || draws.transparency)) {
    const std::vector<PlanarMirror> mirrors = planar_mirrors(*prepared);
    if (!mirrors.empty()) RVR_TRY(add_mirrors(setup, mirrors, camera, out));
    mapped = environment_mapped(scene, *prepared, mirrors, left_out);
    if (!mapped.empty() && options.cube_map_size > 0) RVR_TRY(add_cube_maps(setup, mapped, out));
    if (!mapped.empty() && options.cube_map_size == 0) mark_left_out(mapped, out.buffers);
  }
  out.info["hiz"] = options.hiz ? "on" : "off";
  note_what_is_left_out(scene, options, mapped, left_out, out.warnings);
  return out;
}

}  // namespace

struct SoftRasterizer::Frame {
  std::optional<DepthTarget> target;
};

SoftRasterizer::SoftRasterizer() : frame_(std::make_unique<Frame>()) {}
SoftRasterizer::~SoftRasterizer() = default;

Expected<RenderOutput> SoftRasterizer::render(const Scene& scene, const RenderOptions& options) {
  try {
    // Several samples per pixel: the accumulation buffer, a pass per sample.
    // The passes share their shadow cubes.
    KeptShadowCubes shadows;
    Expected<RenderOutput> out =
        accumulates(scene, options)
            ? render_accumulated(scene, options,
                                 [&](const RenderOptions& pass) {
                                   return render_impl(scene, pass, frame_->target, &shadows);
                                 })
            : render_impl(scene, options, frame_->target);
    if (out) add_depth_of_field_blur(scene, options, *out);
    return out;
  } catch (const std::bad_alloc&) {
    frame_->target.reset();  // possibly half resized
    return internal_error(fmt::format("out of memory rendering {}x{} with {} objects",
                                      scene.image.width, scene.image.height, scene.objects.size()));
  }
}

}  // namespace rvr
