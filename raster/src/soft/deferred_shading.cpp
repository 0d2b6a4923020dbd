#include "soft/deferred_shading.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <cstdint>
#include <cstring>
#include <limits>
#include <memory>

#include "rvr/core/check.h"
#include "rvr/core/prefetch.h"
#include "rvr/core/shade_batch.h"
#include "rvr/core/shapes/triangle_mesh.h"
#include "rvr/core/stream_copy.h"
#include "rvr/core/surface_colour.h"

namespace rvr::soft {

namespace {

// What the kernel needs of an object, looked up once per frame instead of once per pixel.
struct ObjectShading {
  const TriangleMesh* mesh = nullptr;
  bool smooth = false;
  bool varies = false;  // textured or vertex-coloured: a material per pixel
  const Material* source = nullptr;
  ShadeMaterial material{};
};

// v in p[0, n). std::fill stores a glm::vec3 a float at a time; four of them are 48 bytes,
// three 16-byte stores of one repeating pattern.
void fill_vec3(glm::vec3* p, size_t n, const glm::vec3& v) {
  float pattern[12];
  for (int k = 0; k < 12; ++k) pattern[k] = v[k % 3];
  size_t i = 0;
  for (; i + 4 <= n; i += 4) std::memcpy(static_cast<void*>(p + i), pattern, sizeof pattern);
  for (; i < n; ++i) p[i] = v;
}

// Sizes fb to w x h; its pixels are left for the caller to write, every one of them.
void allocate_frame(int w, int h, FrameBuffers& fb) {
  fb.allocate(w, h);  // frame memory: asked for huge pages (pixel_memory.h)
}

// Calls f(x0, n, run) for the runs [x0, x0 + n) of a row `width` wide, with `run` room for n
// values: each run is computed into it (in cache) and then streamed to its frame buffer
// (stream_copy.h), as the tracer streams its tiles' rows.
template <class T, class F>
void for_each_run(int width, F&& f) {
  constexpr int kRun = 256;
  alignas(64) T run[kRun];
  for (int x0 = 0; x0 < width; x0 += kRun) f(x0, std::min(kRun, width - x0), run);
}

// What visibility leaves per pixel, a row at a time: depth, object and primitive id, cost.
// The one writer of those buffers for both passes (shading and visibility only).
class VisibilityRows {
 public:
  VisibilityRows(const DrawList& list, const DepthTarget& target, bool cost)
      : target_(target), cost_(cost), use_primitive_id_(list.objects.size()) {
    for (size_t i = 0; i < list.objects.size(); ++i) {
      use_primitive_id_[i] = list.objects[i].use_primitive_id;
      every_primitive_id_ = every_primitive_id_ && list.objects[i].use_primitive_id;
    }
  }

  // Row y of fb's depth, object id, primitive id and cost (0 without the cost AOV). The
  // target's "nothing covers it" id is the frame buffers' background id.
  void write(int y, FrameBuffers& fb) const {
    const int width = target_.width();  // a local: stores through float* could alias a member
    const size_t row = fb.index(0, y);
    if (cost_)
      target_.cost_row(y, fb.cost.data() + row);
    else
      std::fill_n(fb.cost.data() + row, size_t(width), 0.0f);
    // One buffer at a time.
    const uint32_t* __restrict row_object = target_.objects() + row;
    const double* __restrict row_depth = target_.depths() + row;
    for_each_run<float>(width, [&](int x0, int n, float* __restrict run) {
      // Loads before the selection, so that this loop vectorizes (branch-free).
      for (int k = 0; k < n; ++k) {
        const float depth = float(row_depth[x0 + k]);
        run[k] = row_object[x0 + k] == kNoId ? std::numeric_limits<float>::infinity() : depth;
      }
      stream_copy(fb.depth.data() + row + size_t(x0), run, size_t(n) * sizeof(float));
    });
    write_ids(y, fb);
  }

  // Row y of fb's object and primitive ids.
  void write_ids(int y, FrameBuffers& fb) const {
    static_assert(kNoId == 0xFFFFFFFFu);
    const int width = target_.width();  // a local: stores through uint32_t* could alias a member
    const size_t row = fb.index(0, y);
    const uint32_t* __restrict row_object = target_.objects() + row;
    const uint32_t* __restrict row_primitive = target_.primitives() + row;
    stream_copy(fb.object_id.data() + row, row_object, size_t(width) * sizeof(uint32_t));
    const uint8_t* use = use_primitive_id_.data();
    const bool every = every_primitive_id_;
    for_each_run<uint32_t>(width, [&](int x0, int n, uint32_t* __restrict run) {
      const uint32_t* __restrict object = row_object + x0;
      const uint32_t* __restrict primitive = row_primitive + x0;
      if (every) {
        for (int k = 0; k < n; ++k) {
          const uint32_t p = primitive[k];
          run[k] = object[k] == kNoId ? kNoId : p;
        }
      } else {
        for (int k = 0; k < n; ++k)
          run[k] = object[k] == kNoId ? kNoId : use[object[k]] != 0 ? primitive[k] : 0u;
      }
      stream_copy(fb.primitive_id.data() + row + size_t(x0), run, size_t(n) * sizeof(uint32_t));
    });
  }

 private:
  const DepthTarget& target_;
  bool cost_;
  bool every_primitive_id_ = true;
  std::vector<uint8_t> use_primitive_id_;  // per object: its triangle index is the primitive id
};

// The per-object table the kernel reads, built once per frame.
std::vector<ObjectShading> object_shading(const DrawList& list, const DeferredShading& settings) {
  std::vector<ObjectShading> objects(list.objects.size());
  for (size_t i = 0; i < objects.size(); ++i) {
    const DrawObject& d = list.objects[i];
    ObjectShading& s = objects[i];
    s.mesh = d.mesh;
    s.smooth = d.smooth;
    s.source = d.material;
    s.varies = settings.surfaces && d.material && settings.surfaces->varies(uint32_t(i));
    if (d.material) s.material = shade_material(*d.material, settings.ambient);
  }
  return objects;
}

// What every row's shading shares in one frame.
struct FrameShading {
  const DepthTarget& target;
  const DeferredShading& settings;
  const ShadeKernels& kernels;
  const VisibilityRows& visibility;
  const std::vector<ObjectShading>& objects;
  const ShadeLights& lights;
  glm::vec3 eye;
  FrameBuffers& fb;
  bool fetch_ahead;  // enough triangles that their data lies beyond the caches (prefetch.h)
};

// Shades rows of one range: each covered pixel gathered into a batch of kShadeBatch slots
// (barycentrics, material, triangle), shaded by the kernel when full; uncovered runs get the
// background. The target marks a pixel nothing covers with the id the frame buffers give the
// background.
class RowShader {
 public:
  explicit RowShader(const FrameShading& frame) : frame_(frame) {
    // Flat pixels leave their slots' vertex normals as they were: defined values, not read.
    std::fill(&batch_.normal[0][0][0], &batch_.normal[0][0][0] + 9 * kShadeBatch, 0.0f);
  }

  // Row y: its depth, ids and cost, then its runs of background and its covered pixels.
  void shade_row(int y) {
    static_assert(kNoId == 0xFFFFFFFFu);
    const int w = frame_.target.width();
    const uint32_t* object_of = frame_.target.objects();
    const size_t row = frame_.fb.index(0, y);
    frame_.visibility.write(y, frame_.fb);
    const bool ahead = frame_.fetch_ahead;
    if (ahead)
      for (int x = 0; x < std::min(w, kVerticesAhead); ++x) fetch_triangle(row + size_t(x));
    int x = 0;
    while (x < w) {
      if (object_of[row + size_t(x)] == kNoId) {
        int end = x + 1;
        while (end < w && object_of[row + size_t(end)] == kNoId) ++end;
        fill_background(row + size_t(x), size_t(end - x));
        x = end;
        continue;
      }
      if (ahead && x + kTriangleAhead < w) fetch_triangle(row + size_t(x + kTriangleAhead));
      if (ahead && x + kVerticesAhead < w) fetch_vertices(row + size_t(x + kVerticesAhead));
      add_pixel(row + size_t(x), x, y);
      ++x;
    }
  }

  // Shades the batch gathered so far and writes its pixels' colours and normals.
  void flush() {
    if (batch_.count == 0) return;
    RVR_DCHECK(batch_.count <= kShadeBatch, "flushed when full: ", batch_.count);
    const int n = batch_.count;
    pad_batch(batch_, mixed_);
    batch_.material = mixed_ ? nullptr : &frame_.objects[batch_object_].material;
    const float eye[3] = {frame_.eye.x, frame_.eye.y, frame_.eye.z};
    frame_.kernels.shade(batch_, eye, frame_.lights);
    FrameBuffers& fb = frame_.fb;
    for (int i = 0; i < n; ++i) {
      const size_t o = pixel_[i];
      fb.normal[o] = {batch_.shading_normal[0][i], batch_.shading_normal[1][i],
                      batch_.shading_normal[2][i]};
      fb.colour[o] = {batch_.colour[0][i], batch_.colour[1][i], batch_.colour[2][i]};
    }
    batch_.count = 0;
    mixed_ = false;
  }

 private:
  // Pixels [o, o + n): the background colour and a zero normal.
  void fill_background(size_t o, size_t n) {
    fill_vec3(frame_.fb.colour.data() + o, n, frame_.settings.background);
    std::memset(static_cast<void*>(frame_.fb.normal.data() + o), 0,
                n * sizeof(glm::vec3));  // +0.0f is all zero bits
  }

  // Shading a pixel reads its triangle's vertex indices, then its vertices (and vertex
  // normals): two dependent loads, both misses where neighbouring pixels show unrelated
  // triangles of a large mesh (a soup). They are fetched ahead along the row, so that the
  // misses of several pixels overlap instead of stalling one by one: pixel x + kTriangleAhead's
  // vertex indices, and pixel x + kVerticesAhead's vertices (its indices have arrived by then).
  // A pixel showing its left neighbour's triangle is skipped (put_triangle keeps that one).
  static constexpr int kTriangleAhead = 16, kVerticesAhead = 8;
  bool shows_new_triangle(size_t o) const {
    const uint32_t* object = frame_.target.objects();
    const uint32_t* primitive = frame_.target.primitives();
    return object[o] != kNoId && (o % size_t(frame_.target.width()) == 0 ||
                                  object[o] != object[o - 1] || primitive[o] != primitive[o - 1]);
  }
  void fetch_triangle(size_t o) const {
    if (!shows_new_triangle(o)) return;
    const TriangleMesh& mesh = *frame_.objects[frame_.target.objects()[o]].mesh;
    prefetch(&mesh.triangles[frame_.target.primitives()[o]]);
  }
  void fetch_vertices(size_t o) const {
    if (!shows_new_triangle(o)) return;
    const ObjectShading& s = frame_.objects[frame_.target.objects()[o]];
    const glm::uvec3& tri = s.mesh->triangles[frame_.target.primitives()[o]];
    for (int c = 0; c < 3; ++c) {
      prefetch(&s.mesh->positions[tri[c]]);
      if (s.smooth) prefetch(&s.mesh->normals[tri[c]]);
    }
  }

  // The covered pixel o (at x, y) into the next slot: barycentrics, material, triangle.
  void add_pixel(size_t o, int x, int y) {
    const uint32_t id = frame_.target.objects()[o];
    const ObjectShading& s = frame_.objects[id];
    const uint32_t primitive = frame_.target.primitives()[o];
    RVR_DCHECK(id < frame_.objects.size() && primitive < frame_.objects[id].mesh->triangles.size(),
               "the z-buffer stores ids of drawn triangles: object ", id, ", primitive ",
               primitive);
    const int i = batch_.count++;
    pixel_[i] = o;
    if (i == 0)
      batch_object_ = id;
    else if (!mixed_ && id != batch_object_)
      carry_materials(i);
    const float* barycentric = frame_.target.barycentrics() + 3 * o;
    for (int a = 0; a < 3; ++a) batch_.bary[a][i] = barycentric[a];
    if (s.varies) {
      if (!mixed_) carry_materials(i);
      put_surface_material(i, o, id, primitive, s, x, y);
    } else if (mixed_) {
      put_material(batch_, i, s.material);
    }
    put_triangle(i, id, primitive, s);
    if (batch_.count == kShadeBatch) flush();
  }

  // From slot i on, each slot carries its material: slots before it get the one they shared.
  void carry_materials(int i) {
    mixed_ = true;
    for (int k = 0; k < i; ++k) put_material(batch_, k, frame_.objects[batch_object_].material);
  }

  // A textured or vertex-coloured pixel's own material (its base colour at the slot's
  // barycentrics) and the level of detail it was sampled at.
  void put_surface_material(int i, size_t o, uint32_t id, uint32_t primitive,
                            const ObjectShading& s, int x, int y) {
    const glm::vec3 b(batch_.bary[0][i], batch_.bary[1][i], batch_.bary[2][i]);
    const SurfaceSample here =
        frame_.settings.surfaces->at(id, *s.source, primitive, b, x, y, planes_);
    put_material(batch_, i,
                 shade_material(with_diffuse(*s.source, here.base), frame_.settings.ambient));
    if (!frame_.fb.lod.empty()) frame_.fb.lod[o] = here.lod;
  }

  // The triangle's vertices (and vertex normals if smooth) into slot i; consecutive pixels
  // mostly show the same triangle, so the last one gathered is kept.
  void put_triangle(int i, uint32_t id, uint32_t primitive, const ObjectShading& s) {
    if (id != last_object_ || primitive != last_primitive_) {
      last_object_ = id;
      last_primitive_ = primitive;
      const TriangleMesh& mesh = *s.mesh;
      const glm::uvec3& tri = mesh.triangles[primitive];
      for (int c = 0; c < 3; ++c) last_vertex_[c] = mesh.positions[tri[c]];
      if (s.smooth)
        for (int c = 0; c < 3; ++c) last_normal_[c] = mesh.normals[tri[c]];
    }
    for (int c = 0; c < 3; ++c) put_vec3(batch_.vertex[c], i, last_vertex_[c]);
    batch_.smooth[i] = s.smooth ? ~0u : 0u;
    if (s.smooth)
      for (int c = 0; c < 3; ++c) put_vec3(batch_.normal[c], i, last_normal_[c]);
  }

  const FrameShading& frame_;
  ShadeBatch batch_;
  PlanesCache planes_;
  size_t pixel_[kShadeBatch];  // frame-buffer index of each slot
  // The object of every slot so far, while the batch holds one (then batch.material is set at
  // the flush and the per-slot material arrays are not filled).
  uint32_t batch_object_ = 0;
  bool mixed_ = false;
  uint32_t last_object_ = kNoId, last_primitive_ = kNoId;
  glm::vec3 last_vertex_[3] = {glm::vec3(0.0f), glm::vec3(0.0f), glm::vec3(0.0f)};
  glm::vec3 last_normal_[3] = {glm::vec3(0.0f), glm::vec3(0.0f), glm::vec3(0.0f)};
};

}  // namespace

void shade_pixels(const DrawList& list, const DepthTarget& target, const DeferredShading& settings,
                  const ShadeKernels& kernels, tbb::task_arena& arena, ProgressSink* progress,
                  FrameBuffers& fb) {
  allocate_frame(target.width(), target.height(), fb);  // every pixel is written below
  const VisibilityRows visibility(list, target, settings.cost);
  const std::vector<ObjectShading> objects = object_shading(list, settings);
  if (settings.surfaces && settings.surfaces->textured())
    fb.lod.assign(fb.pixel_count(), std::numeric_limits<float>::quiet_NaN());
  // The light samples as the kernel reads them (none: the colour is the base).
  const bool lit = settings.colour == ShadedColour::Local && settings.samples;
  const ShadeLightArrays light_arrays(lit ? *settings.samples : std::vector<LightSample>{});
  const FrameShading frame{target,       settings, kernels,
                           visibility,   objects,  light_arrays.lights(),
                           settings.eye, fb,       list.triangles() >= kFetchAheadTriangles};
  arena.execute([&] {
    tbb::parallel_for(tbb::blocked_range<int>(0, target.height()),
                      [&](const tbb::blocked_range<int>& r) {
                        if (is_cancelled(progress)) return;  // the rows left are skipped
                        RowShader shader(frame);
                        for (int y = r.begin(); y != r.end(); ++y) shader.shade_row(y);
                        shader.flush();
                        stream_fence();  // the rows' streamed stores, before another thread reads
                        if (progress)
                          progress->advance(uint64_t(r.size()) * uint64_t(target.width()));
                      });
  });
}

// Each textured pixel's level of detail into fb.lod (NaN elsewhere), from fb's ids; primitive
// ids read only where the object names its triangles (`use_primitive_id`), 0 elsewhere, as the
// visibility buffer reports them.
void write_lod(const DrawList& list, const SurfaceColours& surfaces, tbb::task_arena& arena,
               FrameBuffers& fb) {
  const int w = fb.width, h = fb.height;
  fb.lod.assign(fb.pixel_count(), std::numeric_limits<float>::quiet_NaN());
  arena.execute([&] {
    tbb::parallel_for(tbb::blocked_range<int>(0, h), [&](const tbb::blocked_range<int>& r) {
      for (int y = r.begin(); y != r.end(); ++y) {
        const size_t row = fb.index(0, y);
        PlanesCache planes;
        for (int x = 0; x < w; ++x) {
          const uint32_t id = fb.object_id[row + size_t(x)];
          if (id == kNoId || !list.objects[id].material) continue;
          const uint32_t primitive =
              list.objects[id].use_primitive_id ? fb.primitive_id[row + size_t(x)] : 0u;
          fb.lod[row + size_t(x)] =
              surfaces.lod(id, *list.objects[id].material, primitive, x, y, planes);
        }
      }
    });
  });
}

void write_visibility(const DrawList& list, const DepthTarget& target, const glm::vec3& background,
                      bool cost, const SurfaceColours* surfaces, tbb::task_arena& arena,
                      ProgressSink* progress, FrameBuffers& fb) {
  const int w = target.width(), h = target.height();
  allocate_frame(w, h, fb);  // every pixel is written below
  const VisibilityRows visibility(list, target, cost);
  arena.execute([&] {
    tbb::parallel_for(tbb::blocked_range<int>(0, h), [&](const tbb::blocked_range<int>& r) {
      for (int y = r.begin(); y != r.end(); ++y) {
        const size_t row = fb.index(0, y);
        visibility.write(y, fb);
        fill_vec3(fb.colour.data() + row, size_t(w), background);
        std::memset(static_cast<void*>(fb.normal.data() + row), 0,
                    size_t(w) * sizeof(glm::vec3));  // +0.0f is all zero bits
      }
      stream_fence();  // the rows' streamed stores, before another thread reads
      if (progress) progress->advance(uint64_t(r.size()) * uint64_t(w));
    });
  });
  if (surfaces && surfaces->textured()) write_lod(list, *surfaces, arena, fb);
}

void give_visibility_ids(const DrawList& list, DepthTarget& target, const SurfaceColours* surfaces,
                         tbb::task_arena& arena, ProgressSink* progress, FrameBuffers& fb) {
  fb.allocate(0, 0);
  fb.width = target.width();
  fb.height = target.height();
  target.give_ids(fb.object_id, fb.primitive_id);
  if (surfaces && surfaces->textured()) write_lod(list, *surfaces, arena, fb);
  if (progress) progress->advance(uint64_t(fb.pixel_count()));
}

}  // namespace rvr::soft
