// The options render and compare share (see commands.h).
#include <CLI/CLI.hpp>
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <glm/glm.hpp>
#include <optional>
#include <stdexcept>
#include <string>
#include <tuple>
#include <utility>

#include "cli_exit.h"
#include "commands.h"
#include "one_of.h"
#include "rvr/core/expected.h"
#include "rvr/core/gl_backend.h"
#include "rvr/core/limits.h"
#include "rvr/core/renderer.h"
#include "rvr/core/scene.h"
#include "rvr/core/texture.h"
#include "rvr/scene_io/scene_for_render.h"
#include "rvr/scene_io/scene_loader.h"

namespace rvr::cli {

void add_common_options(CLI::App& cmd, CommonOptions& o) {
  cmd.add_option("scene", o.scene, "scene file or builtin:NAME (default builtin:cornell)");
  cmd.add_option("--mode", o.mode, "visibility | local | full")
      ->check(one_of({"visibility", "local", "full"}));
  cmd.add_option("--width", o.width, "image width (overrides the scene)")
      ->check(CLI::Range(1, 16384));
  cmd.add_option("--height", o.height, "image height (overrides the scene)")
      ->check(CLI::Range(1, 16384));
  cmd.add_option("--image", o.image, "image size WxH, e.g. 800x600 (overrides the scene)")
      ->excludes(cmd.get_option("--width"))
      ->excludes(cmd.get_option("--height"));
  cmd.add_option("--camera-from", o.camera_from,
                 "X,Y,Z: look at the scene's (or model's) bounding sphere from this direction, "
                 "framing it (replaces the scene's camera)");
  cmd.add_option("--exposure", o.exposure,
                 "EV: multiply every renderer's linear colour by 2^EV after shading (replaces the "
                 "scene's, or a model file's automatic exposure)")
      ->check(CLI::Range(-kMaxExposure, kMaxExposure));
  cmd.add_option("--up", o.up,
                 "model files: the up axis of the file's coordinates, turned to +y: auto (the "
                 "file's metadata; +y where it has none) | y | z")
      ->check(one_of({"auto", "y", "z"}));
  cmd.add_option("--camera", o.camera,
                 "model files: file (the file's own camera where it frames the model) | auto "
                 "(the framing camera) | file-always (the file's own camera whatever it shows)")
      ->check(one_of({"file", "auto", "file-always"}));
  cmd.add_option("--lights", o.lights,
                 "model files: file (the file's own lights where it has them) | auto (the "
                 "default key light and ambient)")
      ->check(one_of({"file", "auto"}));
  cmd.add_option("--spp", o.spp, "samples per pixel (overrides the scene)")
      ->check(CLI::Range(1, 65536));
  cmd.add_option("--threads", o.threads, "worker threads, 0 = every core")
      ->check(CLI::Range(0, 1024));
  cmd.add_option("--accel", o.accel,
                 "tracer acceleration: bvh (wide SIMD BVH, default) | bvh2 (binary, one box at a "
                 "time) | none (every object for every ray)")
      ->check(one_of({"bvh", "bvh2", "none"}));
  cmd.add_option("--spheres", o.spheres,
                 "tracer spheres: analytic | mesh (the raster's tessellation)")
      ->check(one_of({"analytic", "mesh"}));
  cmd.add_option("--sphere-segments", o.sphere_segments, "sphere tessellation: longitudes")
      ->check(CLI::Range(3, 4096));
  cmd.add_option("--triangle-test", o.triangle_test,
                 "tracer ray-triangle test: mt (Moller-Trumbore) | chapter (plane, then edges)")
      ->check(one_of({"mt", "chapter"}));
  cmd.add_option("--texture-lod", o.texture_lod,
                 "tracers' texture level of detail: cones (ray cones, default) | differentials "
                 "(ray differentials) | none (level 0, bilinear)")
      ->check(one_of({"cones", "differentials", "none"}));
  cmd.add_option("--max-depth", o.max_depth, "recursion limit for bounce rays")
      ->check(CLI::Range(0, 64));
  cmd.add_option("--seed", o.seed, "seed of the per-pixel random streams");
  cmd.add_option("--gl", o.gl,
                 "raster GL back end: osmesa | egl (default osmesa, egl when OSMesa is missing)")
      ->check(one_of({"osmesa", "egl"}));
  cmd.add_option("--shadow-map-size", o.shadow_map_size, "raster shadow maps: texels per side")
      ->check(CLI::Range(16, 8192));
  cmd.add_option("--shadow-bias", o.shadow_bias, "raster shadow maps: depth bias (scene units)")
      ->check(CLI::Range(0.0f, 10.0f));
  cmd.add_flag("--shadow-pcf", o.shadow_pcf, "raster shadow maps: 3x3 percentage-closer filtering");
  cmd.add_option("--hiz", o.hiz,
                 "softraster: hierarchical z, each 8x8 block's farthest depth rejecting what lies "
                 "behind it: on | off (the textbook z-buffer)")
      ->check(one_of({"on", "off"}));
  cmd.add_option("--depth-format", o.depth_format,
                 "rasterizers' z-buffer: d24 | d32f | d32f_reversed (default: the most precise "
                 "the renderer has)")
      ->check(one_of({"d24", "d32f", "d32f_reversed"}));
  cmd.add_flag("--quiet,-q", o.quiet, "no progress output");
  cmd.add_option("--max-samples", o.limits.max_samples,
                 "refuse more than N pixels x samples (default 2^30)")
      ->check(CLI::PositiveNumber);
  cmd.add_option("--max-triangles", o.limits.max_triangles,
                 "refuse more than N triangles, tessellation included (default 50000000)")
      ->check(CLI::PositiveNumber);
  cmd.add_option("--max-memory-mb", o.max_memory_mb,
                 "refuse renders estimated to need more MiB (default 3/4 of physical memory)")
      ->check(CLI::PositiveNumber);
}

GlBackend gl_backend(const CommonOptions& o) {
  if (o.gl == "osmesa") return GlBackend::OsMesa;
  if (o.gl == "egl") return GlBackend::Egl;
  return GlBackend::Default;
}

RenderMode parse_mode(const std::string& s) {
  if (s == "visibility") return RenderMode::Visibility;
  if (s == "full") return RenderMode::Full;
  return RenderMode::Local;
}

RenderOptions render_options(const CommonOptions& o, const std::string& default_mode) {
  RenderOptions r;
  r.mode = parse_mode(o.mode.empty() ? default_mode : o.mode);
  r.spheres = o.spheres == "mesh" ? SphereMode::Mesh : SphereMode::Analytic;
  r.sphere_segments = o.sphere_segments;
  r.threads = o.threads;
  r.max_depth = o.max_depth;
  r.seed = o.seed;
  r.accel = o.accel == "none"   ? AccelKind::None
            : o.accel == "bvh2" ? AccelKind::Bvh2
                                : AccelKind::Bvh;
  r.triangle_test =
      o.triangle_test == "chapter" ? TriangleTest::Chapter : TriangleTest::MollerTrumbore;
  r.texture_lod = o.texture_lod == "differentials" ? TextureLod::Differentials
                  : o.texture_lod == "none"        ? TextureLod::None
                                                   : TextureLod::Cones;
  r.shadow_map_size = o.shadow_map_size;
  r.shadow_bias = o.shadow_bias;
  r.shadow_pcf = o.shadow_pcf;
  r.hiz = o.hiz == "on";
  if (!o.depth_format.empty()) r.depth_format = parse_depth_format(o.depth_format);
  return r;
}

namespace {

// "X,Y,Z" as three finite numbers, not all zero.
glm::vec3 parse_direction(const std::string& text) {
  glm::vec3 d;
  char end = 0;
  if (std::sscanf(text.c_str(), " %f , %f , %f %c", &d.x, &d.y, &d.z, &end) != 3 ||
      !std::isfinite(d.x) || !std::isfinite(d.y) || !std::isfinite(d.z) ||
      !(glm::length(d) > 0.0f)) {
    fail(bad_input("--camera-from: expected a direction X,Y,Z (not all zero), got '" + text + "'"));
  }
  return d;
}

// "WxH", each in [1, 16384].
std::pair<int, int> parse_image_size(const std::string& text) {
  int w = 0, h = 0;
  char end = 0;
  if (std::sscanf(text.c_str(), " %d x %d %c", &w, &h, &end) != 2 || w < 1 || h < 1 || w > 16384 ||
      h > 16384) {
    fail(bad_input("--image: expected WIDTHxHEIGHT, each 1 to 16384, got '" + text + "'"));
  }
  return {w, h};
}

}  // namespace

Scene load(const CommonOptions& o, const RenderOptions& options, double& load_seconds) {
  SceneRequest request;
  request.spec = o.scene;
  SceneOverrides& overrides = request.overrides;
  overrides.width = o.width;
  overrides.height = o.height;
  if (!o.image.empty()) std::tie(overrides.width, overrides.height) = parse_image_size(o.image);
  if (!o.camera_from.empty()) overrides.view_from = parse_direction(o.camera_from);
  overrides.exposure = o.exposure;
  overrides.up = o.up == "z" ? UpAxis::Z : o.up == "y" ? UpAxis::Y : UpAxis::Auto;
  overrides.camera = o.camera == "auto" ? FromFile::Auto : FromFile::File;
  overrides.judge_file_camera = o.camera != "file-always";
  overrides.lights = o.lights == "auto" ? FromFile::Auto : FromFile::File;
  request.spp = o.spp;
  request.limits = o.limits;
  request.limits.max_memory_bytes = std::min<uint64_t>(o.max_memory_mb, uint64_t(1) << 40) << 20;
  return take(load_scene_for_render(request, options, &load_seconds));
}

}  // namespace rvr::cli
