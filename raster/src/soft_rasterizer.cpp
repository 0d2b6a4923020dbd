#include "rvr/raster/soft_rasterizer.h"

#include <fmt/format.h>
#include <tbb/blocked_range.h>
#include <tbb/enumerable_thread_specific.h>
#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

#include <algorithm>
#include <array>
#include <atomic>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <limits>
#include <new>
#include <string>
#include <vector>

#include "rvr/shared/camera.h"
#include "rvr/shared/shading.h"
#include "rvr/shared/tessellate.h"
#include "soft/draw_triangles.h"
#include "soft/tile_raster.h"

namespace rvr {

namespace {

using Clock = std::chrono::steady_clock;
using soft::DepthTarget;
using soft::DrawList;
using soft::DrawObject;
using soft::DrawResult;

double seconds_since(Clock::time_point start) {
  return std::chrono::duration<double>(Clock::now() - start).count();
}

std::string object_label(const Object& o, size_t index) {
  return o.name.empty() ? fmt::format("csg#{}", index) : o.name;
}

Expected<RenderOutput> render_impl(const Scene& scene, const RenderOptions& options) {
  const int w = scene.image.width, h = scene.image.height;
  if (w < 1 || h < 1) return bad_input(fmt::format("image size {}x{} is empty", w, h));
  if (w > soft::kMaxImageSide || h > soft::kMaxImageSide)
    return bad_input(fmt::format("image size {}x{}: softraster draws at most {} pixels a side", w,
                                 h, soft::kMaxImageSide));
  RenderOutput out;
  ProgressSink* const progress = options.progress;
  tbb::task_arena arena(options.threads > 0 ? options.threads : tbb::task_arena::automatic);

  // --- setup: objects to triangles, transform, clip, bin (in submission order)
  auto t = Clock::now();
  std::vector<TriangleMesh> tessellated;  // sphere and plane meshes, alive until shading ends
  tessellated.reserve(scene.objects.size());
  std::vector<DrawObject> objects(scene.objects.size());
  std::vector<std::string> skipped_csg;
  bool mirror = false, transparency = false;
  const Material fallback = default_material();
  for (size_t i = 0; i < scene.objects.size(); ++i) {
    const Object& o = scene.objects[i];
    DrawObject& d = objects[i];
    if (o.material < scene.materials.size()) {
      d.material = &scene.materials[o.material];
    } else if (scene.materials.empty()) {
      d.material = &fallback;  // a hand-made scene with no material list: the built-in grey
    } else {
      return bad_input(
          fmt::format("object '{}': material index {} out of range", o.name, o.material));
    }
    switch (o.type) {
      case ObjectType::Triangles:
        d.mesh = &o.mesh;
        d.use_primitive_id = true;
        break;
      case ObjectType::Sphere:
        tessellated.push_back(tessellate_sphere(o.sphere, options.sphere_segments));
        d.mesh = &tessellated.back();
        break;
      case ObjectType::Plane:
        tessellated.push_back(tessellate_plane(o.plane));
        d.mesh = &tessellated.back();
        break;
      case ObjectType::Csg:
        skipped_csg.push_back(object_label(o, i));
        continue;
    }
    const TriangleMesh& m = *d.mesh;
    d.smooth = m.smooth();
    if (m.smooth() && m.normals.size() != m.positions.size())
      return bad_input(fmt::format("object '{}': {} normals for {} positions", o.name,
                                   m.normals.size(), m.positions.size()));
    for (const glm::uvec3& tri : m.triangles)
      if (std::max({tri.x, tri.y, tri.z}) >= m.positions.size())
        return bad_input(fmt::format("object '{}': triangle index out of range ({} positions)",
                                     o.name, m.positions.size()));
    mirror |= d.material->mirror > 0.0f;
    transparency |= d.material->transparency > 0.0f;
  }

  const glm::dmat4 view_projection =
      glm::dmat4(projection_matrix(scene.camera, w, h)) * glm::dmat4(view_matrix(scene.camera));
  const DrawList list = soft::make_draw_list(std::move(objects));
  const size_t submitted = list.triangles();
  out.stats["time.setup"] = seconds_since(t);

  DepthTarget target(w, h, scene.camera.near, scene.camera.far, options.hiz);
  // The fraction in triangles, the speed in fragments.
  if (progress) progress->begin("draw", submitted, "triangles", "fragments");
  const DrawResult drawn = soft::draw_triangles(list, view_projection, target, arena, progress);
  out.stats["time.setup"] += drawn.setup_seconds;
  out.stats["time.bin"] = drawn.bin_seconds;
  out.stats["time.raster"] = drawn.raster_seconds;

  // --- shade: deferred, each visible pixel once
  t = Clock::now();
  FrameBuffers& fb = out.buffers;
  fb.allocate(w, h);  // every pixel is written below
  const std::vector<LightSample> samples = options.mode == RenderMode::Visibility
                                               ? std::vector<LightSample>{}
                                               : light_samples(scene.lights);
  const glm::vec3 eye = scene.camera.eye;
  if (progress) progress->begin("shade", uint64_t(w) * uint64_t(h), "pixels");
  arena.execute([&] {
    tbb::parallel_for(tbb::blocked_range<int>(0, h), [&](const tbb::blocked_range<int>& r) {
      for (int y = r.begin(); y != r.end(); ++y) {
        for (int x = 0; x < w; ++x) {
          const size_t o = fb.index(x, y);
          fb.set_background(o, scene.image.background);
          fb.cost[o] = target.cost(o);
          if (!target.covered(o)) continue;
          const DrawObject& d = list.objects[target.object(o)];
          const uint32_t primitive = target.primitive(o);
          const glm::vec3 b = target.barycentric(o);
          const glm::uvec3& tri = d.mesh->triangles[primitive];
          const glm::vec3 &p0 = d.mesh->positions[tri.x], &p1 = d.mesh->positions[tri.y],
                          &p2 = d.mesh->positions[tri.z];
          const glm::vec3 P = b.x * p0 + b.y * p1 + b.z * p2;
          const glm::vec3 g = glm::normalize(glm::cross(p1 - p0, p2 - p0));
          const glm::vec3 shading =
              d.smooth ? glm::normalize(b.x * d.mesh->normals[tri.x] +
                                        b.y * d.mesh->normals[tri.y] + b.z * d.mesh->normals[tri.z])
                       : g;
          const glm::vec3 V = glm::normalize(eye - P);
          const glm::vec3 N = face_viewer(shading, g, V);
          fb.depth[o] = float(target.depth(o));
          fb.object_id[o] = target.object(o);
          fb.primitive_id[o] = d.use_primitive_id ? primitive : 0u;
          fb.normal[o] = N;
          if (options.mode != RenderMode::Visibility)
            fb.color[o] = shade_local(*d.material, P, N, V, scene.ambient, samples);
        }
      }
      if (progress) progress->advance(uint64_t(r.size()) * uint64_t(w));
    });
  });
  out.stats["time.shade"] = seconds_since(t);

  const soft::TileCounters& sum = drawn.counters;
  uint64_t covered = 0;
  for (size_t i = 0; i < fb.pixel_count(); ++i) covered += target.covered(i) ? 1 : 0;
  out.stats["triangles.submitted"] = double(submitted);
  out.stats["triangles.clipped"] = double(drawn.clipped);
  out.stats["triangles.setup"] = double(drawn.set_up);
  out.stats["fragments.generated"] = double(sum.generated);
  out.stats["fragments.shaded"] = double(covered);
  out.stats["pixels.covered"] = double(covered);
  out.stats["overdraw"] = covered > 0 ? double(sum.generated) / double(covered) : 0.0;
  out.stats["blocks.full"] = double(sum.blocks_full);
  out.stats["hiz.blocks_rejected"] = double(sum.blocks_rejected);
  out.stats["hiz.triangles_rejected"] = double(sum.triangles_rejected);
  out.stats["memory.raster_bytes"] = double(target.bytes() + drawn.peak_chunk_bytes);
  out.info["hiz"] = options.hiz ? "on" : "off";

  if (!skipped_csg.empty()) {
    std::string names;
    for (const std::string& s : skipped_csg) names += (names.empty() ? "" : ", ") + s;
    out.warnings.push_back(fmt::format("csg objects have no z-buffer form: skipped {} ({})",
                                       skipped_csg.size(), names));
  }
  if (options.mode == RenderMode::Full) {
    if (!scene.lights.empty())
      out.warnings.push_back("shadows not rendered by softraster (no shadow maps yet)");
    if (mirror) out.warnings.push_back("mirror reflection not rendered by softraster");
    if (transparency) out.warnings.push_back("transparency not rendered by softraster");
    if (scene.camera.aperture_radius > 0.0f)
      out.warnings.push_back("depth of field (aperture) not rendered by softraster: pinhole");
  }
  if (scene.image.samples_per_pixel > 1)
    out.warnings.push_back(
        fmt::format("softraster: {} samples per pixel requested; multisampling is not "
                    "implemented, rendered 1",
                    scene.image.samples_per_pixel));
  return out;
}

}  // namespace

Expected<RenderOutput> SoftRasterizer::render(const Scene& scene, const RenderOptions& options) {
  try {
    return render_impl(scene, options);
  } catch (const std::bad_alloc&) {
    return internal_error(fmt::format("out of memory rendering {}x{} with {} objects",
                                      scene.image.width, scene.image.height, scene.objects.size()));
  }
}

}  // namespace rvr
