// rvr_bench: what each loop order costs. Names are stable (bench/README.md documents them):
//   BM_Frame/<renderer>/<scene>/<n>/<width>   a whole frame, height = width * 3/4
//   BM_Visibility/<renderer>/<scene>/<n>/<width>  the same frames, ids and depth only
//   BM_DepthComplexity/<renderer>/<N>          occluders:N at 512x384, front to back
//   BM_DepthComplexityBackToFront/<renderer>/<N>  the same quads rearmost first
//   BM_Effects/<effect>                        the tracer on cornell, one effect at a time
//   BM_Effects/hybrid[_soft]/<effect>          the same frames with the hybrids
//   BM_Mirrors/<renderer>/<N>                  builtin:mirrors:N, full mode: rays vs views
//   BM_CurvedMirrors/<renderer>/<N>            builtin:mirror_balls:N, full mode: rays vs cube maps
//   BM_Trace/<accel>/<rays>/<scene>/<n>        one thread, rays only, no shading
//   BM_Build/<accel>/<n>                       acceleration structure build
//   BM_Texture/<renderer>/<lod>                builtin:textured at 640x480, local mode; lod is
//     the z-buffers' own (zbuffer) or the tracers' --texture-lod (cones, differentials, none);
//     counter texel_bytes/pixel: texel bytes one frame's trilinear filter reads per pixel,
//     counted from its lod AOV (8 texels of 12 bytes where two levels blend, 4 where one does)
//   BM_Threads/<renderer>/<threads>            tessphere:100000 at 1024x768 on 1 or 2 threads
//   BM_WriteAovs/<aovs>                        writing what `rvr render --aov` writes for
//     cornell at 640x480 (the image, then the AOVs); counters render_ms (the frame itself) and
//     write/render
// Scenes and acceleration structures are built outside the timed loops (FrameRenderer).
// Counters of every frame benchmark: rays/s, triangles/s, pixels/s; from the renderer's phase
// stats, each the mean over the timed frames in ms and only when the renderer reports it:
//   visibility_ms (time.visibility), shade_ms (time.shade): the z-buffer or primary-ray pass
//     and the shading after it (softraster, raytrace);
//   zbuffer_ms (time.zbuffer), trace_ms (time.trace): the hybrids' z-buffer passes and the
//     tracer's part (hits rebuilt, shading, rays).
// softraster also: raster_MiB, hiz_blocks_rejected, fragments (of the last frame).
// Renderers and their variants (raytrace_bvh2, softraster_nohiz) come from the renderer table,
// rvr/renderers/registry.h.
#include <benchmark/benchmark.h>
#include <tbb/global_control.h>
#include <unistd.h>

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <glm/glm.hpp>
#include <initializer_list>
#include <map>
#include <memory>
#include <mutex>
#include <optional>
#include <random>
#include <string>
#include <utility>
#include <vector>

#include "rvr/compare/compare.h"
#include "rvr/compare/effect_errors.h"
#include "rvr/core/camera.h"
#include "rvr/core/check.h"
#include "rvr/core/expected.h"
#include "rvr/core/framebuffers.h"
#include "rvr/core/isa.h"
#include "rvr/core/ray.h"
#include "rvr/core/renderer.h"
#include "rvr/core/scene.h"
#include "rvr/core/shapes/csg.h"
#include "rvr/core/shapes/sphere.h"
#include "rvr/core/shapes/triangle_mesh.h"
#include "rvr/core/texture.h"
#include "rvr/image_codec/image_io.h"
#include "rvr/raytrace/bvh.h"
#include "rvr/raytrace/intersect.h"
#include "rvr/raytrace/primary_rays.h"
#include "rvr/raytrace/ray_tracer.h"
#include "rvr/raytrace/trace_geometry.h"
#include "rvr/raytrace/wide_bvh.h"
#include "rvr/raytrace/wide_bvh_layout.h"
#include "rvr/renderers/prepared_renderer.h"
#include "rvr/renderers/registry.h"
#include "rvr/scene_io/scene_loader.h"

using namespace rvr;

namespace {

// Built scenes are cached: soup:1000000 takes a while to make.
const Scene& builtin(const std::string& name) {
  static std::mutex mutex;
  static std::map<std::string, std::unique_ptr<Scene>> cache;
  std::lock_guard<std::mutex> lock(mutex);
  auto& slot = cache[name];
  if (!slot) slot = std::make_unique<Scene>(make_builtin_scene(name).value());
  return *slot;
}

void add_counters(benchmark::State& state, const RenderOutput& out, double pixels) {
  auto get = [&](const char* k) {
    auto it = out.stats.find(k);
    return it == out.stats.end() ? 0.0 : it->second;
  };
  double rays =
      get("rays.primary") + get("rays.shadow") + get("rays.reflection") + get("rays.refraction");
  using C = benchmark::Counter;
  if (rays > 0) state.counters["rays/s"] = C(rays, C::kIsIterationInvariantRate);
  double tris = get("triangles.submitted") > 0 ? get("triangles.submitted") : get("triangles");
  state.counters["triangles/s"] = C(tris, C::kIsIterationInvariantRate);
  state.counters["pixels/s"] = C(pixels, C::kIsIterationInvariantRate);
}

// The renderer's phase stats (seconds) summed over the timed frames, reported as counters: the
// mean over the frames that reported each, in ms. A stat no frame reported gives no counter.
class PhaseTimes {
 public:
  void add(const RenderOutput& out) {
    for (size_t i = 0; i < kPhases.size(); ++i) {
      auto it = out.stats.find(kPhases[i].stat);
      if (it == out.stats.end()) continue;
      seconds_[i] += it->second;
      frames_[i] += 1;
    }
  }
  void report(benchmark::State& state) const {
    for (size_t i = 0; i < kPhases.size(); ++i)
      if (frames_[i] > 0) state.counters[kPhases[i].counter] = 1e3 * seconds_[i] / frames_[i];
  }

 private:
  struct Phase {
    const char* stat;
    const char* counter;
  };
  static constexpr std::array<Phase, 7> kPhases = {{{"time.visibility", "visibility_ms"},
                                                    {"time.shade", "shade_ms"},
                                                    {"time.zbuffer", "zbuffer_ms"},
                                                    {"time.trace", "trace_ms"},
                                                    {"time.setup", "setup_ms"},
                                                    {"time.bin", "bin_ms"},
                                                    {"time.raster", "raster_ms"}}};
  std::array<double, kPhases.size()> seconds_{};
  std::array<double, kPhases.size()> frames_{};
};

// Renders frames of one scene with one renderer of the table, or a variant of one. What the
// renderer builds beforehand (the tracers' BVH) is built here, outside the timed loop.
class FrameRenderer {
 public:
  FrameRenderer(const std::string& name, const Scene& scene, const RenderOptions& options)
      : prepared_(
            prepare_renderer(find_renderer_choice(name).value(), scene, {}, options).value()) {}
  RenderOutput frame() { return prepared_->render().value(); }

 private:
  std::unique_ptr<PreparedRenderer> prepared_;
};

// The timed loop: one frame rendered untimed first (warming caches), then a frame per
// iteration, its phase times added to `phases`; returns the last frame.
RenderOutput time_frames(benchmark::State& state, FrameRenderer& renderer, PhaseTimes& phases) {
  RenderOutput out = renderer.frame();
  for (auto _ : state) {
    out = renderer.frame();
    benchmark::DoNotOptimize(out.buffers.colour.data());
    phases.add(out);
  }
  return out;
}

// Every renderer of the table, each followed by its variants of one kind, if any: the sweeps
// that vary an early rejection include the renderers without it.
std::vector<RendererChoice> choices_with(std::optional<VariantOf> of) {
  std::vector<RendererChoice> chosen;
  for (const RendererChoice& c : renderer_choices())
    if (!c.variant || (of && c.variant->of == *of)) chosen.push_back(c);
  return chosen;
}

// The chapter's loop, every object for every ray: O(pixels x triangles).
bool every_object_every_ray(const RendererChoice& c) {
  RendererConfig config;
  RenderOptions options;
  c.apply(config, options);
  return options.accel == AccelKind::None;
}

// Times whole frames of `scene` (already sized) in `mode`, with or without the cost AOV. The
// first frame (GL shader JIT, TBB threads) is not timed.
void time_frames(benchmark::State& state, const std::string& renderer_name, const Scene& scene,
                 RenderMode mode, bool cost_aov, int threads = 0) {
  RenderOptions options;
  options.mode = mode;
  options.cost_aov = cost_aov;
  options.threads = threads;
  FrameRenderer renderer(renderer_name, scene, options);
  PhaseTimes phases;
  RenderOutput out = time_frames(state, renderer, phases);
  add_counters(state, out, double(scene.image.width) * scene.image.height);
  phases.report(state);
  if (auto it = out.stats.find("memory.raster_bytes"); it != out.stats.end())
    state.counters["raster_MiB"] = it->second / double(1 << 20);
  if (auto it = out.stats.find("hiz.blocks_rejected"); it != out.stats.end())
    state.counters["hiz_blocks_rejected"] = it->second;
  if (auto it = out.stats.find("fragments.generated"); it != out.stats.end())
    state.counters["fragments"] = it->second;
}

// Texel bytes the sampler reads, per pixel of the frame, from the levels of detail it sampled
// at: LINEAR_MIPMAP_LINEAR reads 4 RGB32F texels of each level it blends, one level where the
// clamped lod is a whole number (at or below level 0, at or above the last level).
double texel_bytes_per_pixel(const FrameBuffers& fb, float max_lod) {
  if (fb.lod.empty() || fb.pixel_count() == 0) return 0.0;
  double bytes = 0.0;
  for (float lod : fb.lod) {
    if (std::isnan(lod)) continue;
    const float clamped = std::clamp(lod, 0.0f, max_lod);
    bytes += (clamped == std::floor(clamped) ? 4.0 : 8.0) * 12.0;
  }
  return bytes / double(fb.pixel_count());
}

// builtin:textured with one renderer and level-of-detail rule.
void BM_Texture(benchmark::State& state, const std::string& renderer_name, TextureLod lod) {
  Scene scene = builtin("textured");
  scene.image.width = 640;
  scene.image.height = 480;
  RenderOptions options;
  options.mode = RenderMode::Local;
  options.texture_lod = lod;
  FrameRenderer renderer(renderer_name, scene, options);
  PhaseTimes phases;
  RenderOutput out = time_frames(state, renderer, phases);
  add_counters(state, out, double(scene.image.width) * scene.image.height);
  phases.report(state);
  float max_lod = 0.0f;
  for (const Texture& t : scene.textures)
    if (t.mips) max_lod = std::max(max_lod, t.mips->max_lod());
  state.counters["texel_bytes/pixel"] = texel_bytes_per_pixel(out.buffers, max_lod);
}

// The frame sweeps over renderers, scenes, triangle counts and widths: BM_Frame renders whole
// frames in local mode, BM_Visibility ids and depth only, without the cost AOV (the loop
// without the shading).
struct FrameSweep {
  const char* family;
  RenderMode mode;
  bool cost_aov;
};
constexpr FrameSweep kFrameSweep{"BM_Frame", RenderMode::Local, true};
constexpr FrameSweep kVisibilitySweep{"BM_Visibility", RenderMode::Visibility, false};

// A frame of the sweep with one renderer: <scene>:<n> at width x width * 3/4.
void BM_Frame(benchmark::State& state, FrameSweep sweep, const std::string& renderer_name,
              const std::string& scene_name) {
  Scene scene = builtin(scene_name + ":" + std::to_string(state.range(0)));
  scene.image.width = int(state.range(1));
  scene.image.height = int(state.range(1) * 3 / 4);
  time_frames(state, renderer_name, scene, sweep.mode, sweep.cost_aov);
}

// Parallel scaling of our own loops: the same frame with 1 and with 2 worker threads.
void BM_Threads(benchmark::State& state, const std::string& renderer_name) {
  Scene scene = builtin("tessphere:100000");
  scene.image.width = 1024;
  scene.image.height = 768;
  time_frames(state, renderer_name, scene, RenderMode::Local, true, int(state.range(0)));
}

// occluders:N, N quads one behind another, submitted front to back (hi-z skips the hidden ones)
// or, with back_to_front, rearmost first (every quad is nearer than what is there: nothing to
// skip).
void BM_DepthComplexity(benchmark::State& state, const std::string& renderer_name,
                        bool back_to_front) {
  Scene scene =
      builtin((back_to_front ? "occluders_back:" : "occluders:") + std::to_string(state.range(0)));
  scene.image.width = 512;
  scene.image.height = 384;
  time_frames(state, renderer_name, scene, RenderMode::Local, true);
}

// Cornell with exactly one effect switched on (BM_Effects): the scene and options.
void effect_scene(const std::string& effect, Scene& scene, RenderOptions& options) {
  scene = builtin("cornell");
  for (Material& m : scene.materials) m.mirror = m.transparency = 0.0f;
  Light point{LightType::Point, {2.78f, 5.3f, 2.795f}, {}, {}, {}, glm::vec3(12.0f), 1};
  Light area = scene.lights[0];
  scene.lights = {point};
  options.mode = RenderMode::Full;
  if (effect == "primary") {
    options.mode = RenderMode::Local;
  } else if (effect == "area_light_4x4") {
    scene.lights = {area};
  } else if (effect.rfind("mirror_depth_", 0) == 0) {
    options.max_depth = std::stoi(effect.substr(13));
    for (Material& m : scene.materials)
      if (m.name == "mirror") m.mirror = 0.85f;
    // A second mirror facing the first one: depth matters only between mirrors.
    for (Object& o : scene.objects)
      if (o.name == "back wall") o.material = scene.objects[6].material;
  } else if (effect == "planar_mirror") {
    // The back wall a mirror (flat: every renderer reflects it, the z-buffers by a reflected
    // view), the ball matt.
    for (Material& m : scene.materials)
      if (m.name == "mirror") m.mirror = 0.85f;
    for (Object& o : scene.objects) {
      if (o.name == "back wall") o.material = scene.objects[6].material;
      if (o.name == "mirror ball") o.material = scene.objects[0].material;
    }
  } else if (effect == "curved_mirror") {
    // The ball a mirror, nothing else: the z-buffers answer it with a cube map.
    for (Material& m : scene.materials)
      if (m.name == "mirror") m.mirror = 0.85f;
  } else if (effect == "glass") {
    for (Material& m : scene.materials)
      if (m.name == "glass") m.transparency = 0.9f;
  } else if (effect == "clear_pane") {
    // A tinted pane of ior 1 standing in front of both balls: the tracer's transmitted rays go
    // straight on, the z-buffers draw the view again without it (the over operator).
    Material tint;
    tint.name = "tinted pane";
    tint.diffuse = {0.3f, 0.55f, 0.8f};
    tint.transparency = 0.6f;
    tint.ior = 1.0f;
    scene.materials.push_back(tint);
    Object pane;
    pane.name = "pane";
    pane.type = ObjectType::Triangles;
    pane.material = uint32_t(scene.materials.size() - 1);
    pane.mesh.positions = {
        {4.0f, 0.0f, 1.5f}, {1.5f, 0.0f, 1.5f}, {1.5f, 3.0f, 1.5f}, {4.0f, 3.0f, 1.5f}};
    pane.mesh.triangles = {{0, 1, 2}, {0, 2, 3}};
    scene.objects.push_back(std::move(pane));
  } else if (effect == "csg") {
    // The mirror ball, matt, with a ball of 0.7 its radius cut out of its front: a CSG
    // difference the z-buffers draw leaf by leaf.
    for (Object& o : scene.objects)
      if (o.name == "mirror ball") {
        const Sphere ball = o.sphere;
        auto leaf = [](const Sphere& s) {
          auto n = std::make_shared<CsgNode>();
          n->sphere = s;
          return n;
        };
        auto cut = std::make_shared<CsgNode>();
        cut->is_leaf = false;
        cut->op = CsgOp::Difference;
        cut->a = leaf(ball);
        cut->b =
            leaf({ball.center + glm::vec3(0.0f, 0.3f, 0.8f) * ball.radius, 0.7f * ball.radius});
        o.type = ObjectType::Csg;
        o.csg = cut;
        o.material = scene.objects[0].material;
      }
  } else if (effect == "dof_16") {
    scene.camera.aperture_radius = 0.08f;
    scene.camera.focus_distance = 9.5f;
    scene.image.samples_per_pixel = 16;
  }  // "hard_shadows": the point light in full mode
}

// builtin:<family>:N at 640x480 in full mode, N = the benchmark's argument: the tracer's
// reflection rays (one per mirror pixel, whatever N) against a z-buffer's views of the mirrors.
// The renderer's stat `views` (when it reports it) becomes the counter `counter`.
void BM_MirrorCount(benchmark::State& state, const std::string& renderer_name,
                    const std::string& family, const std::string& views,
                    const std::string& counter) {
  Scene scene = builtin(family + ":" + std::to_string(state.range(0)));
  scene.image.width = 640;
  scene.image.height = 480;
  RenderOptions options;
  options.mode = RenderMode::Full;
  FrameRenderer renderer(renderer_name, scene, options);
  PhaseTimes phases;
  RenderOutput out = time_frames(state, renderer, phases);
  add_counters(state, out, double(scene.image.width) * scene.image.height);
  if (auto it = out.stats.find(views); it != out.stats.end()) state.counters[counter] = it->second;
}

// BM_Mirrors: builtin:mirrors:N, flat mirrors, a whole reflected view per mirror seen
// (mirror_views). BM_CurvedMirrors: builtin:mirror_balls:N, a cube map of six views per ball
// seen (cube_faces).
void BM_Mirrors(benchmark::State& state, const std::string& renderer_name) {
  BM_MirrorCount(state, renderer_name, "mirrors", "mirror.views", "mirror_views");
}

void BM_CurvedMirrors(benchmark::State& state, const std::string& renderer_name) {
  BM_MirrorCount(state, renderer_name, "mirror_balls", "cube_map.faces", "cube_faces");
}

// The tracer on cornell with exactly one effect switched on.
void BM_Effects(benchmark::State& state, const std::string& effect) {
  Scene scene;
  RenderOptions options;
  effect_scene(effect, scene, options);
  RayTracer tracer;
  RenderOutput out = tracer.render(scene, options).value();
  PhaseTimes phases;
  for (auto _ : state) {
    out = tracer.render(scene, options).value();
    benchmark::DoNotOptimize(out.buffers.colour.data());
    phases.add(out);
  }
  add_counters(state, out, double(scene.image.width) * scene.image.height);
  phases.report(state);
}

// What `rvr render builtin:cornell -r raytrace --aov depth,id,normal,cost` writes after its
// frame (640x480, full mode): OUT.png, then each AOV named in `aovs` ("" for the image alone),
// into a scratch folder. The frame is rendered before the timed loop; render_ms is the median
// of three such frames, write/render the time of one write over it: writing must not cost more
// than rendering. In a fresh process the first write also loads the image writer module (the
// whole runs of bench/JOURNAL.md show that part).
void BM_WriteAovs(benchmark::State& state, const std::vector<std::string>& aovs) {
  Scene scene = builtin("cornell");
  scene.image.width = 640;
  scene.image.height = 480;
  RenderOptions options;
  options.mode = RenderMode::Full;
  RayTracer tracer;
  std::vector<double> render_seconds;
  RenderOutput out;
  for (int k = 0; k < 3; ++k) {
    const auto start = std::chrono::steady_clock::now();
    out = tracer.render(scene, options).value();
    render_seconds.push_back(
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count());
  }
  std::sort(render_seconds.begin(), render_seconds.end());
  namespace fs = std::filesystem;
  const fs::path dir = fs::temp_directory_path() / ("rvr_bench_aovs_" + std::to_string(::getpid()));
  fs::create_directories(dir);
  const std::string image = (dir / "cornell.png").string();
  const Image colour = colour_image(out.buffers);
  double seconds = 0.0;
  for (auto _ : state) {
    const auto start = std::chrono::steady_clock::now();
    if (!write_image(image, colour).ok() ||
        (!aovs.empty() && !write_aovs(image, out.buffers, aovs).ok())) {
      state.SkipWithError("cannot write the AOVs");
      break;
    }
    seconds += std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  }
  double bytes = 0.0;
  for (const auto& entry : fs::directory_iterator(dir)) bytes += double(entry.file_size());
  fs::remove_all(dir);
  const double render = render_seconds[1];
  state.counters["render_ms"] = 1e3 * render;
  if (state.iterations() > 0)
    state.counters["write/render"] = seconds / double(state.iterations()) / render;
  state.counters["MB"] = bytes / 1e6;
}

// The frame's error against the tracer's frame of the same scene and options, rendered once
// and untimed: psnr_db over the whole image and, when the effect has a mask (effect_errors.h:
// reflection, refraction, lens, csg), effect_psnr_db inside it over effect_pixels pixels; 999
// for identical, as metrics.json writes it. So each technique's row holds its cost and error.
void add_error_counters(benchmark::State& state, const Scene& scene, const RenderOptions& options,
                        const RenderOutput& out) {
  RayTracer tracer;
  Expected<RenderOutput> reference = tracer.render(scene, options);
  if (!reference) {
    state.SkipWithError("the tracer's reference frame failed");
    return;
  }
  RVR_CHECK(reference->buffers.pixel_count() == out.buffers.pixel_count(),
            "the reference frame has the frame's size");
  auto finite = [](double db) { return std::isfinite(db) ? db : 999.0; };
  const ComparisonMetrics m = compare_buffers(out.buffers, reference->buffers);
  state.counters["psnr_db"] = finite(m.colour.psnr_db);
  const std::vector<EffectError> effects =
      effect_errors(scene, options.mode, reference->buffers, out.buffers, reference->buffers);
  if (effects.empty()) return;
  state.counters["effect_psnr_db"] = finite(effects.front().psnr_db);
  state.counters["effect_pixels"] = double(effects.front().pixels);
}

// The same frames with another renderer of the table (the hybrid: the z-buffer finds the
// primary hits, the tracer does the effect; a z-buffer's technique), built afresh each frame as
// the tracer's are. The split of its time: zbuffer_ms (visibility passes) and trace_ms (hits
// rebuilt, shading, rays); its error against the tracer (add_error_counters).
void BM_EffectsWith(benchmark::State& state, const std::string& renderer_name,
                    const std::string& effect, Supersampling supersampling, ZBufferDof dof,
                    ZBufferReflection reflection) {
  Scene scene;
  RenderOptions options;
  effect_scene(effect, scene, options);
  options.supersampling = supersampling;
  options.zbuffer_dof = dof;
  options.zbuffer_reflection = reflection;
  std::unique_ptr<Renderer> renderer = make_renderer(renderer_name).value();
  RenderOutput out = renderer->render(scene, options).value();
  PhaseTimes phases;
  for (auto _ : state) {
    out = renderer->render(scene, options).value();
    benchmark::DoNotOptimize(out.buffers.colour.data());
    phases.add(out);
  }
  add_counters(state, out, double(scene.image.width) * scene.image.height);
  phases.report(state);
  add_error_counters(state, scene, options, out);
}

std::vector<Ray> make_rays(const Scene& scene, const std::string& kind) {
  std::vector<Ray> rays;
  rays.reserve(1024 * 768);
  if (kind == "primary") {  // coherent: through every pixel centre of a 1024x768 frame
    CameraFrame f = make_camera_frame(scene.camera, 1024, 768);
    for (int y = 0; y < 768; ++y)
      for (int x = 0; x < 1024; ++x)
        rays.push_back({f.eye, camera_ray_direction(f, x + 0.5f, y + 0.5f), scene.camera.near,
                        scene.camera.far});
    return rays;
  }
  std::mt19937 rng(42);  // incoherent: random origins in the scene's box, random directions
  std::uniform_real_distribution<float> U(-1.0f, 1.0f);
  for (int i = 0; i < 1024 * 768; ++i) {
    glm::vec3 d(U(rng), U(rng), U(rng));
    if (glm::dot(d, d) < 1e-6f) d = {0, 0, 1};
    rays.push_back({{U(rng), U(rng), U(rng)}, d, 0.0f, INFINITY});
  }
  return rays;
}

AccelKind accel_kind(const std::string& name) {
  if (name == "embree" || name == "embree_medium" || name == "embree_high")
    return AccelKind::Embree;
  if (name == "bvh2") return AccelKind::Bvh2;
  return AccelKind::Bvh;
}

struct TraceAnswer {
  bool hit;
  HitRecord h;
};

// Embree's answers for one scene and set of rays, computed once: the reference every other
// accelerator's answers are checked against.
// Embree's answers, or null with `error` set when Embree cannot trace here (no plugin).
const std::vector<TraceAnswer>* embree_answers(const std::string& key, const Scene& scene,
                                               const std::vector<Ray>& rays, std::string& error) {
  static std::mutex mutex;
  static std::map<std::string, std::vector<TraceAnswer>> cache;
  std::lock_guard<std::mutex> lock(mutex);
  auto& slot = cache[key];
  if (slot.empty()) {
    TraceGeometry embree(scene, SphereMode::Analytic, 64, AccelKind::Embree);
    if (!embree.error().empty()) {
      error = "Embree cannot trace: " + embree.error();
      return nullptr;
    }
    slot.resize(rays.size());
    for (size_t i = 0; i < rays.size(); ++i) slot[i].hit = embree.closest(rays[i], slot[i].h);
  }
  return &slot;
}

// Checks that `answers` are Embree's, ray for ray: the same primitive (or the same miss) and t
// within 1e-5 relative. Exceptions, counted, each a limit of float arithmetic rather than a
// disagreement about what is there:
//  - edge: the nearer hit of the two lies within 1e-4 (in barycentrics) of its triangle's edge:
//    the two tests put the ray on different sides of that edge (exact arithmetic sides with
//    either one, as checked by hand on soup:1000000);
//  - crossing: two triangles at the same t to 1e-6 (they cross; the ray meets them there);
//  - ill-conditioned: the same primitive, t apart by more than 1e-5 relative but within the
//    float error bound of Moller-Trumbore's t, 16 eps kappa t, where kappa =
//    |e1||e2| (|s| / |s.n| + |d| / |d.n|) (s = origin - v0, n = e1 x e2) grows at grazing
//    angles and for small triangles far from the origin (soup:1000000's are 0.01 across).
struct TraceCheck {
  size_t edge = 0, crossing = 0, ill_conditioned = 0, wrong = 0, first_wrong = 0;
};

TraceCheck check_against_embree(const std::vector<TraceAnswer>& answers,
                                const std::vector<TraceAnswer>& embree, const TraceGeometry& g,
                                const std::vector<Ray>& rays) {
  auto near_edge = [](const HitRecord& h) {
    constexpr float kEdge = 1e-4f;
    return h.u < kEdge || h.v < kEdge || 1.0f - h.u - h.v < kEdge;
  };
  TraceCheck c;
  for (size_t i = 0; i < answers.size(); ++i) {
    const TraceAnswer& a = answers[i];
    const TraceAnswer& e = embree[i];
    if (!a.hit && !e.hit) continue;
    if (a.hit && e.hit && a.h.primitive == e.h.primitive) {
      float dt = std::abs(a.h.t - e.h.t);
      if (dt <= 1e-5f * std::abs(e.h.t)) continue;
      const Ray& r = rays[i];
      const TrianglePrecomputed& tri = g.triangle(a.h.primitive);
      glm::dvec3 n = glm::cross(glm::dvec3(tri.e1), glm::dvec3(tri.e2));
      glm::dvec3 sv = glm::dvec3(r.origin) - glm::dvec3(tri.v0), d(r.dir);
      double kappa =
          glm::length(glm::dvec3(tri.e1)) * glm::length(glm::dvec3(tri.e2)) *
          (glm::length(sv) / std::abs(glm::dot(sv, n)) + glm::length(d) / std::abs(glm::dot(d, n)));
      if (dt <= 16.0 * 0x1p-24 * kappa * std::abs(e.h.t)) {
        ++c.ill_conditioned;
        continue;
      }
    } else {
      // The nearer of the two hits (or the only one) decides.
      bool ours_nearer = a.hit && (!e.hit || a.h.t <= e.h.t);
      if (near_edge(ours_nearer ? a.h : e.h)) {
        ++c.edge;
        continue;
      }
      // Two triangles crossing each other (soups have them), the ray through the crossing.
      if (a.hit && e.hit && std::abs(a.h.t - e.h.t) <= 1e-6f * std::abs(e.h.t)) {
        ++c.crossing;
        continue;
      }
    }
    if (std::getenv("RVR_BENCH_DEBUG"))
      std::fprintf(
          stderr, "ray %zu: ours %d p%u t%.9g u%.6g v%.6g  embree %d p%u t%.9g u%.6g v%.6g\n", i,
          a.hit, a.h.primitive, a.h.t, a.h.u, a.h.v, e.hit, e.h.primitive, e.h.t, e.h.u, e.h.v);
    if (c.wrong++ == 0) c.first_wrong = i;
  }
  return c;
}

// Rays only, one thread: closest-hit queries through bvh (the wide BVH, the SIMD kernels
// chosen for this CPU), bvh2 (the binary tree) or embree (rtcIntersect1), over the same rays.
// Before timing, every answer is checked against Embree's and the traversal counted (the timed
// loop counts nothing).
void BM_Trace(benchmark::State& state, const std::string& accel, const std::string& rays_kind,
              const std::string& scene_name) {
  std::string name = scene_name + ":" + std::to_string(state.range(0));
  const Scene& scene = builtin(name);
  TraceGeometry geometry(scene, SphereMode::Analytic, 64, accel_kind(accel),
                         TriangleTest::MollerTrumbore, std::nullopt,
                         accel == "embree_medium" ? EmbreeQuality::Medium : EmbreeQuality::High);
  if (!geometry.error().empty()) {  // e.g. Embree without its plugin: nothing to measure
    state.SkipWithError(geometry.error().c_str());
    return;
  }
  std::vector<Ray> rays = make_rays(scene, rays_kind);
  tbb::global_control one_thread(tbb::global_control::max_allowed_parallelism, 1);

  std::vector<TraceAnswer> answers(rays.size());
  TraversalCounters counters;
  for (size_t i = 0; i < rays.size(); ++i)
    answers[i].hit = geometry.closest(rays[i], answers[i].h, counters);
  if (accel_kind(accel) != AccelKind::Embree) {
    std::string embree_error;
    const std::vector<TraceAnswer>* embree =
        embree_answers(name + rays_kind, scene, rays, embree_error);
    if (!embree) {
      state.SkipWithError(embree_error.c_str());
      return;
    }
    TraceCheck check = check_against_embree(answers, *embree, geometry, rays);
    // Edge cases are rare: a ray must pass within 1e-4 of an edge (in barycentrics).
    if (check.wrong > 0 ||
        check.edge + check.crossing + check.ill_conditioned > rays.size() / 1000) {
      std::string error = "answers differ from Embree's on " + std::to_string(check.wrong) +
                          " rays (first: ray " + std::to_string(check.first_wrong) + "), " +
                          std::to_string(check.edge) + " edge cases, " +
                          std::to_string(check.crossing) + " crossings, " +
                          std::to_string(check.ill_conditioned) + " ill-conditioned";
      state.SkipWithError(error.c_str());
      return;
    }
    state.counters["check.edge"] = double(check.edge);
    state.counters["check.crossing"] = double(check.crossing);
    state.counters["check.ill_conditioned"] = double(check.ill_conditioned);
  }

  size_t hits = 0;
  for (auto _ : state) {
    for (const Ray& r : rays) {
      HitRecord h;
      hits += geometry.closest(r, h);
    }
  }
  benchmark::DoNotOptimize(hits);
  using C = benchmark::Counter;
  state.counters["rays/s"] = C(double(rays.size()), C::kIsIterationInvariantRate);
  if (accel_kind(accel) != AccelKind::Embree) {
    state.counters["nodes/ray"] = double(counters.nodes_visited) / double(rays.size());
    state.counters["tests/ray"] = double(counters.primitive_tests) / double(rays.size());
  }
  if (accel == "bvh") state.SetLabel(std::string("kernel ") + geometry.kernel_isa());
}

// Primary rays of a 1024x768 frame as 8x8 tiles (row-major inside a tile), the packets the
// raytrace renderer traces. tile_first[k] is the index of tile k's first ray in make_rays order.
std::vector<RayPacket> make_tiles(const Scene& scene, std::vector<std::vector<int>>& ray_index) {
  const PrimaryRays primary(make_camera_frame(scene.camera, 1024, 768), scene.camera.near,
                            scene.camera.far);
  std::vector<RayPacket> tiles;
  for (int y0 = 0; y0 < 768; y0 += 8) {
    for (int x0 = 0; x0 < 1024; x0 += 8) {
      RayPacket p = primary.packet(x0, y0, 8, 8);
      std::vector<int> index;
      index.reserve(64);
      for (int k = 0; k < 64; ++k) index.push_back((y0 + k / 8) * 1024 + x0 + k % 8);
      tiles.push_back(p);
      ray_index.push_back(index);
    }
  }
  return tiles;
}

// Primary rays, one thread, as packets: bvh (our packet traversal of the wide BVH) or embree
// (rtcIntersect8 or rtcIntersect16, its native width on this CPU), over the same 8x8 tiles.
// Answers are checked against Embree's single-ray ones first.
void BM_TracePacket(benchmark::State& state, const std::string& accel,
                    const std::string& scene_name) {
  std::string name = scene_name + ":" + std::to_string(state.range(0));
  const Scene& scene = builtin(name);
  TraceGeometry geometry(scene, SphereMode::Analytic, 64, accel_kind(accel));
  if (!geometry.error().empty()) {
    state.SkipWithError(geometry.error().c_str());
    return;
  }
  std::vector<std::vector<int>> ray_index;
  std::vector<RayPacket> tiles = make_tiles(scene, ray_index);
  std::vector<Ray> rays = make_rays(scene, "primary");
  tbb::global_control one_thread(tbb::global_control::max_allowed_parallelism, 1);

  std::vector<TraceAnswer> answers(rays.size());
  std::vector<TraversalCounters> counters(kPacketRays);
  TraversalCounters total;
  for (size_t t = 0; t < tiles.size(); ++t) {
    HitRecord hits[kPacketRays];
    for (auto& c : counters) c = {};
    geometry.closest_packet(tiles[t], hits, counters.data());
    for (int k = 0; k < tiles[t].count; ++k) {
      TraceAnswer& a = answers[size_t(ray_index[t][size_t(k)])];
      a.hit = hits[k].primitive != kNoPrimitive;
      a.h = hits[k];
      total.nodes_visited += counters[size_t(k)].nodes_visited;
      total.primitive_tests += counters[size_t(k)].primitive_tests;
    }
  }
  std::string embree_error;
  const std::vector<TraceAnswer>* embree =
      embree_answers(name + "primary", scene, rays, embree_error);
  if (!embree) {
    state.SkipWithError(embree_error.c_str());
    return;
  }
  TraceCheck check = check_against_embree(answers, *embree, geometry, rays);
  if (check.wrong > 0 || check.edge + check.crossing + check.ill_conditioned > rays.size() / 1000) {
    std::string error = "packet answers differ from Embree's single-ray ones on " +
                        std::to_string(check.wrong) + " rays (first: ray " +
                        std::to_string(check.first_wrong) + ")";
    state.SkipWithError(error.c_str());
    return;
  }
  size_t hit_count = 0;
  for (auto _ : state) {
    for (const RayPacket& tile : tiles) {
      HitRecord hits[kPacketRays];
      geometry.closest_packet(tile, hits, nullptr);
      hit_count += hits[0].primitive != kNoPrimitive;
    }
  }
  benchmark::DoNotOptimize(hit_count);
  using C = benchmark::Counter;
  state.counters["rays/s"] = C(double(rays.size()), C::kIsIterationInvariantRate);
  if (accel == "bvh") {
    state.counters["nodes/ray"] = double(total.nodes_visited) / double(rays.size());
    state.counters["tests/ray"] = double(total.primitive_tests) / double(rays.size());
    state.SetLabel(std::string("kernel ") + geometry.kernel_isa());
  } else {
    state.SetLabel("rtcIntersect" + std::to_string(geometry.embree_packet_width()));
  }
}

// Acceleration structure build, one thread for all (Embree builds with TBB too): bvh (the
// binned-SAH binary tree collapsed to the wide BVH and its triangle blocks), bvh2 (the binary
// tree alone), embree_medium (Embree's binned SAH, the same kind of tree as ours) and
// embree_high (with spatial splits; what the embree renderer uses).
void BM_Build(benchmark::State& state, const std::string& accel) {
  tbb::global_control one_thread(tbb::global_control::max_allowed_parallelism, 1);
  const Scene& scene = builtin("soup:" + std::to_string(state.range(0)));
  double nodes = 0, sah = 0, bytes = 0;
  for (auto _ : state) {
    TraceGeometry g(scene, SphereMode::Analytic, 64, accel_kind(accel),
                    TriangleTest::MollerTrumbore, std::nullopt,
                    accel == "embree_medium" ? EmbreeQuality::Medium : EmbreeQuality::High);
    if (!g.error().empty()) {
      state.SkipWithError(g.error().c_str());
      break;
    }
    bytes = double(g.acceleration_bytes());
    if (accel == "bvh") {
      nodes = double(g.wide_bvh().stats().nodes);
      sah = g.wide_bvh().stats().binary_sah_cost;
    } else if (accel == "bvh2") {
      nodes = double(g.bvh().stats().nodes);
      sah = g.bvh().stats().sah_cost;
    }
    benchmark::DoNotOptimize(&g);
  }
  using C = benchmark::Counter;
  state.counters["prims/s"] = C(double(state.range(0)), C::kIsIterationInvariantRate);
  state.counters["bytes/tri"] = bytes / double(state.range(0));
  if (accel_kind(accel) != AccelKind::Embree) {
    state.counters["nodes"] = nodes;
    state.counters["sah_cost"] = sah;
  }
}

// One frame sweep: <family>/<renderer>/<scene>/<n>/<width>.
// A benchmark's name: its parts joined by '/' ("BM_Trace/bvh/primary/soup").
std::string bench_name(std::initializer_list<std::string> parts) {
  std::string name;
  for (const std::string& part : parts) {
    if (!name.empty()) name += '/';
    name += part;
  }
  return name;
}

void register_frame_sweep(const FrameSweep& sweep) {
  auto add = [&](const std::string& r, const std::string& s, long n, long w) {
    benchmark::RegisterBenchmark((sweep.family + ("/" + r + "/" + s)).c_str(), BM_Frame, sweep, r,
                                 s)
        ->Args({n, w})
        ->Unit(benchmark::kMillisecond)
        ->UseRealTime();
  };
  // raster, softraster, raytrace, raytrace_bvh2, raytrace_none, embree, hybrid, hybrid_soft.
  for (const RendererChoice& c : choices_with(VariantOf::Accelerator))
    for (std::string s : {"tessphere", "soup"})
      for (long n : {100L, 1000L, 10000L, 100000L, 1000000L}) {
        if (every_object_every_ray(c) && n > 1000) continue;
        for (long w : {256L, 1024L, 2048L}) add(c.name, s, n, w);
      }
  // Ten million triangles, at 1024 wide only: the z-buffers' linear cost against the tracers'.
  for (const RendererInfo& info : renderers())
    for (std::string s : {"tessphere", "soup"}) add(info.name, s, 10000000L, 1024L);
}

// The z-buffers' own answers to the effects they render, by technique: primary visibility,
// shadow maps, a flat mirror by reflected views, a curved mirror by a cube map or screen-space
// reflections, glass by a cube map, a clear pane of ior 1 by the view behind it, a CSG solid
// by its leaves' intervals, and depth of field by the accumulation
// buffer (raster also by MSAA: a pinhole) or a blur.
void register_zbuffer_effects() {
  struct ZBufferEffect {
    std::string renderer, effect, technique;
    Supersampling supersampling = Supersampling::Accumulation;
    ZBufferDof dof = ZBufferDof::Accumulation;
    ZBufferReflection reflection = ZBufferReflection::CubeMap;
  };
  for (const std::string z : {"raster", "softraster"}) {
    std::vector<ZBufferEffect> cases = {
        {z, "primary", "zbuffer"},
        {z, "hard_shadows", "shadow_maps"},
        {z, "area_light_4x4", "shadow_maps"},
        {z, "planar_mirror", "reflected_views"},
        {z, "curved_mirror", "cube_map"},
        {z, "curved_mirror", "ssr", Supersampling::Accumulation, ZBufferDof::Accumulation,
         ZBufferReflection::Ssr},
        {z, "glass", "cube_map"},
        {z, "clear_pane", "layer_views"},
        {z, "dof_16", "accumulation"},
        {z, "csg", "leaf_intervals"},
        {z, "dof_16", "blur", Supersampling::Accumulation, ZBufferDof::Blur}};
    if (z == "raster") cases.push_back({z, "dof_16", "msaa", Supersampling::Msaa});
    for (const ZBufferEffect& c : cases)
      benchmark::RegisterBenchmark(
          bench_name({"BM_Effects", c.renderer, c.effect, c.technique}).c_str(), BM_EffectsWith,
          c.renderer, c.effect, c.supersampling, c.dof, c.reflection)
          ->Unit(benchmark::kMillisecond)
          ->UseRealTime();
  }
}

void register_all() {
  register_frame_sweep(kFrameSweep);
  register_frame_sweep(kVisibilitySweep);
  // raster, softraster, softraster_nohiz, raytrace, embree.
  for (bool back : {false, true})
    for (const RendererChoice& c : choices_with(VariantOf::HierarchicalZ))
      for (long n : {1L, 2L, 4L, 8L, 16L, 32L, 64L, 128L, 256L})
        benchmark::RegisterBenchmark(
            ((back ? "BM_DepthComplexityBackToFront/" : "BM_DepthComplexity/") + c.name).c_str(),
            BM_DepthComplexity, c.name, back)
            ->Arg(n)
            ->Unit(benchmark::kMillisecond)
            ->UseRealTime();
  for (std::string e : {"primary", "hard_shadows", "area_light_4x4", "mirror_depth_1",
                        "mirror_depth_2", "mirror_depth_3", "mirror_depth_4", "mirror_depth_5",
                        "planar_mirror", "curved_mirror", "glass", "clear_pane", "csg", "dof_16"}) {
    benchmark::RegisterBenchmark(("BM_Effects/" + e).c_str(), BM_Effects, e)
        ->Unit(benchmark::kMillisecond)
        ->UseRealTime();
    // Beside the tracer's: the hybrids (GL's z-buffer, softraster's) on the same frames.
    for (std::string h : {"hybrid", "hybrid_soft"})
      benchmark::RegisterBenchmark(bench_name({"BM_Effects", h, e}).c_str(), BM_EffectsWith, h, e,
                                   Supersampling::Accumulation, ZBufferDof::Accumulation,
                                   ZBufferReflection::CubeMap)
          ->Unit(benchmark::kMillisecond)
          ->UseRealTime();
  }
  // The crossover in the number of mirrors.
  for (std::string r : {"raytrace", "softraster", "raster", "hybrid_soft"})
    benchmark::RegisterBenchmark(("BM_Mirrors/" + r).c_str(), BM_Mirrors, r)
        ->RangeMultiplier(4)
        ->Range(1, 256)
        ->Unit(benchmark::kMillisecond)
        ->UseRealTime();
  for (std::string r : {"raytrace", "softraster", "raster", "hybrid_soft"})
    benchmark::RegisterBenchmark(("BM_CurvedMirrors/" + r).c_str(), BM_CurvedMirrors, r)
        ->RangeMultiplier(4)
        ->Range(1, 64)
        ->Unit(benchmark::kMillisecond)
        ->UseRealTime();
  register_zbuffer_effects();
  for (const auto& [name, aovs] : std::vector<std::pair<std::string, std::vector<std::string>>>{
           {"image", {}},
           {"depth", {"depth"}},
           {"id", {"id"}},
           {"normal", {"normal"}},
           {"cost", {"cost"}},
           {"depth,id,normal,cost", {"depth", "id", "normal", "cost"}}})
    benchmark::RegisterBenchmark(("BM_WriteAovs/" + name).c_str(), BM_WriteAovs, aovs)
        ->Unit(benchmark::kMillisecond)
        ->UseRealTime();
  for (std::string a : {"bvh", "bvh2", "embree"})
    for (std::string rays : {"primary", "random"}) {
      benchmark::RegisterBenchmark(bench_name({"BM_Trace", a, rays, "tessphere"}).c_str(), BM_Trace,
                                   a, rays, std::string("tessphere"))
          ->Arg(100000)
          ->Unit(benchmark::kMillisecond);
      benchmark::RegisterBenchmark(bench_name({"BM_Trace", a, rays, "soup"}).c_str(), BM_Trace, a,
                                   rays, std::string("soup"))
          ->Arg(1000000)
          ->Unit(benchmark::kMillisecond);
    }
  for (std::string a : {"bvh", "embree"})
    for (std::string scene : {"tessphere", "soup"})
      benchmark::RegisterBenchmark(bench_name({"BM_TracePacket", a, scene}).c_str(), BM_TracePacket,
                                   a, scene)
          ->Arg(scene == "soup" ? 1000000 : 100000)
          ->Unit(benchmark::kMillisecond);
  // Textures: the z-buffers' own level of detail, the tracers' three.
  for (const RendererInfo& info : renderers()) {
    const bool tracer = info.order == LoopOrder::PixelMajor;
    const std::vector<std::pair<std::string, TextureLod>> lods =
        tracer ? std::vector<std::pair<std::string, TextureLod>>{{"cones", TextureLod::Cones},
                                                                 {"differentials",
                                                                  TextureLod::Differentials},
                                                                 {"none", TextureLod::None}}
               : std::vector<std::pair<std::string, TextureLod>>{{"zbuffer", TextureLod::Cones}};
    for (const auto& [lod_name, lod] : lods)
      benchmark::RegisterBenchmark(("BM_Texture/" + info.name + "/" + lod_name).c_str(), BM_Texture,
                                   info.name, lod)
          ->Unit(benchmark::kMillisecond)
          ->UseRealTime();
  }
  // Our own loops (raster's threads are llvmpipe's, embree's partly Embree's).
  for (std::string r : {"raytrace", "softraster"})
    for (long threads : {1L, 2L})
      benchmark::RegisterBenchmark(("BM_Threads/" + r).c_str(), BM_Threads, r)
          ->Arg(threads)
          ->Unit(benchmark::kMillisecond)
          ->UseRealTime();
  for (std::string a : {"bvh", "bvh2", "embree_medium", "embree_high"})
    for (long n : {10000L, 100000L, 1000000L})
      benchmark::RegisterBenchmark(("BM_Build/" + a).c_str(), BM_Build, a)
          ->Arg(n)
          ->Unit(benchmark::kMillisecond)
          ->UseRealTime();
}

}  // namespace

int main(int argc, char** argv) {
  register_all();
  // Which kernels ran, in the JSON's context: ours (chosen from the CPU, or RVR_ISA) and
  // Embree's (its own choice, from its verbose report).
  benchmark::AddCustomContext("rvr_kernel", describe_isa_choice());
  benchmark::AddCustomContext("embree_kernel", embree_kernel_isa());
  benchmark::AddCustomContext("embree_version", embree_version());
  benchmark::Initialize(&argc, argv);
  if (benchmark::ReportUnrecognizedArguments(argc, argv)) return 1;
  benchmark::RunSpecifiedBenchmarks();
  benchmark::Shutdown();
  return 0;
}
