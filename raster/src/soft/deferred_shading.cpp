#include "soft/deferred_shading.h"

#include <sys/mman.h>
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <cstdint>
#include <cstring>
#include <limits>

#include "rvr/shared/check.h"
#include "rvr/shared/shade_batch.h"
#include "rvr/shared/shading.h"
#include "rvr/shared/surface_colour.h"

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

// Asks for transparent huge pages over a buffer not yet touched. The frame's buffers are fresh
// memory every frame (the caller takes them away), tens of MB first touched here: one page
// fault per 4 KiB, or, where the system grants huge pages on request, one per 2 MiB. Advice
// only: no byte written changes, and a refusal (an error return) leaves the small pages.
template <class T>
void ask_for_huge_pages(PixelVector<T>& v) {
  constexpr uintptr_t kHuge = uintptr_t(2) << 20;
  const uintptr_t begin = (reinterpret_cast<uintptr_t>(v.data()) + kHuge - 1) & ~(kHuge - 1);
  const uintptr_t end = reinterpret_cast<uintptr_t>(v.data() + v.size()) & ~(kHuge - 1);
  if (end > begin) madvise(reinterpret_cast<void*>(begin), end - begin, MADV_HUGEPAGE);
}

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
  fb.allocate(w, h);
  ask_for_huge_pages(fb.color);
  ask_for_huge_pages(fb.normal);
  ask_for_huge_pages(fb.depth);
  ask_for_huge_pages(fb.object_id);
  ask_for_huge_pages(fb.primitive_id);
  ask_for_huge_pages(fb.cost);
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
    static_assert(kNoId == 0xFFFFFFFFu);
    const int width = target_.width();  // a local: stores through uint32_t* could alias a member
    const size_t row = fb.index(0, y);
    if (cost_)
      target_.cost_row(y, fb.cost.data() + row);
    else
      std::fill_n(fb.cost.data() + row, size_t(width), 0.0f);
    // One buffer at a time.
    const uint32_t* __restrict row_object = target_.objects() + row;
    const uint32_t* __restrict row_primitive = target_.primitives() + row;
    const double* __restrict row_depth = target_.depths() + row;
    float* __restrict depth_out = fb.depth.data() + row;
    uint32_t* __restrict primitive_out = fb.primitive_id.data() + row;
    std::memcpy(fb.object_id.data() + row, row_object, size_t(width) * sizeof(uint32_t));
    // Loads before the selection, so that these loops vectorize (branch-free).
    for (int k = 0; k < width; ++k) {
      const float depth = float(row_depth[k]);
      depth_out[k] = row_object[k] == kNoId ? std::numeric_limits<float>::infinity() : depth;
    }
    if (every_primitive_id_) {
      for (int k = 0; k < width; ++k) {
        const uint32_t primitive = row_primitive[k];
        primitive_out[k] = row_object[k] == kNoId ? kNoId : primitive;
      }
    } else {
      const uint8_t* use = use_primitive_id_.data();
      for (int k = 0; k < width; ++k)
        primitive_out[k] = row_object[k] == kNoId    ? kNoId
                           : use[row_object[k]] != 0 ? row_primitive[k]
                                                     : 0u;
    }
  }

 private:
  const DepthTarget& target_;
  bool cost_;
  bool every_primitive_id_ = true;
  std::vector<uint8_t> use_primitive_id_;  // per object: its triangle index is the primitive id
};

}  // namespace

void shade_pixels(const DrawList& list, const DepthTarget& target, const DeferredShading& settings,
                  const ShadeKernels& kernels, tbb::task_arena& arena, ProgressSink* progress,
                  FrameBuffers& fb) {
  const int w = target.width(), h = target.height();
  allocate_frame(w, h, fb);  // every pixel is written below
  const VisibilityRows visibility(list, target, settings.cost);
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
  const SurfaceColours* surfaces = settings.surfaces;
  if (surfaces && surfaces->textured())
    fb.lod.assign(fb.pixel_count(), std::numeric_limits<float>::quiet_NaN());
  // The light samples as the kernel reads them (none: the colour is the base).
  const bool lit = settings.colour == ShadedColour::Local && settings.samples;
  const ShadeLightArrays light_arrays(lit ? *settings.samples : std::vector<LightSample>{});
  const ShadeLights& lights = light_arrays.lights();
  const float eye[3] = {settings.eye.x, settings.eye.y, settings.eye.z};
  // The target marks a pixel nothing covers with the id the frame buffers give the background.
  static_assert(kNoId == 0xFFFFFFFFu);
  const uint32_t* object_of = target.objects();
  const uint32_t* primitive_of = target.primitives();
  const float* barycentrics = target.barycentrics();

  arena.execute([&] {
    tbb::parallel_for(tbb::blocked_range<int>(0, h), [&](const tbb::blocked_range<int>& r) {
      if (is_cancelled(progress)) return;  // the rows left are skipped
      ShadeBatch batch;
      PlanesCache planes;
      // Flat pixels leave their slots' vertex normals as they were: defined values, not read.
      std::fill(&batch.normal[0][0][0], &batch.normal[0][0][0] + 9 * kShadeBatch, 0.0f);
      size_t pixel[kShadeBatch];  // frame-buffer index of each slot
      // The object of every slot so far, while the batch holds one (then batch.material is
      // set at the flush and the per-slot material arrays are not filled).
      uint32_t batch_object = 0;
      bool mixed = false;
      auto flush = [&] {
        if (batch.count == 0) return;
        RVR_DCHECK(batch.count <= kShadeBatch, "flushed when full: ", batch.count);
        const int n = batch.count;
        pad_batch(batch, mixed);
        batch.material = mixed ? nullptr : &objects[batch_object].material;
        kernels.shade(batch, eye, lights);
        for (int i = 0; i < n; ++i) {
          const size_t o = pixel[i];
          fb.normal[o] = {batch.shading_normal[0][i], batch.shading_normal[1][i],
                          batch.shading_normal[2][i]};
          fb.color[o] = {batch.colour[0][i], batch.colour[1][i], batch.colour[2][i]};
        }
        batch.count = 0;
        mixed = false;
      };
      // The last triangle gathered: consecutive pixels mostly show the same one.
      uint32_t last_object = kNoId, last_primitive = kNoId;
      glm::vec3 last_vertex[3] = {glm::vec3(0.0f), glm::vec3(0.0f), glm::vec3(0.0f)};
      glm::vec3 last_normal[3] = {glm::vec3(0.0f), glm::vec3(0.0f), glm::vec3(0.0f)};
      for (int y = r.begin(); y != r.end(); ++y) {
        const size_t row = fb.index(0, y);
        visibility.write(y, fb);  // depth, ids and cost of the whole row
        int x = 0;
        while (x < w) {
          if (object_of[row + size_t(x)] == kNoId) {
            int end = x + 1;
            while (end < w && object_of[row + size_t(end)] == kNoId) ++end;
            fill_vec3(fb.color.data() + row + size_t(x), size_t(end - x), settings.background);
            std::memset(static_cast<void*>(fb.normal.data() + row + size_t(x)), 0,
                        size_t(end - x) * sizeof(glm::vec3));  // +0.0f is all zero bits
            x = end;
            continue;
          }
          const size_t o = row + size_t(x);
          ++x;
          const uint32_t id = object_of[o];
          const ObjectShading& s = objects[id];
          const uint32_t primitive = primitive_of[o];
          RVR_DCHECK(id < objects.size() && primitive < objects[id].mesh->triangles.size(),
                     "the z-buffer stores ids of drawn triangles: object ", id, ", primitive ",
                     primitive);

          const int i = batch.count++;
          pixel[i] = o;
          if (i == 0)
            batch_object = id;
          else if (!mixed && id != batch_object) {
            mixed = true;  // from now on each slot carries its material
            for (int k = 0; k < i; ++k) put_material(batch, k, objects[batch_object].material);
          }
          for (int a = 0; a < 3; ++a) batch.bary[a][i] = barycentrics[3 * o + size_t(a)];
          if (s.varies) {
            if (!mixed) {
              mixed = true;
              for (int k = 0; k < i; ++k) put_material(batch, k, objects[batch_object].material);
            }
            const glm::vec3 b(batch.bary[0][i], batch.bary[1][i], batch.bary[2][i]);
            const SurfaceSample here = surfaces->at(id, *s.source, primitive, b, x - 1, y, planes);
            put_material(batch, i,
                         shade_material(with_diffuse(*s.source, here.base), settings.ambient));
            if (!fb.lod.empty()) fb.lod[o] = here.lod;
          } else if (mixed) {
            put_material(batch, i, s.material);
          }
          if (id != last_object || primitive != last_primitive) {
            last_object = id;
            last_primitive = primitive;
            const TriangleMesh& mesh = *s.mesh;
            const glm::uvec3& tri = mesh.triangles[primitive];
            for (int c = 0; c < 3; ++c) last_vertex[c] = mesh.positions[tri[c]];
            if (s.smooth)
              for (int c = 0; c < 3; ++c) last_normal[c] = mesh.normals[tri[c]];
          }
          for (int c = 0; c < 3; ++c) put_vec3(batch.vertex[c], i, last_vertex[c]);
          batch.smooth[i] = s.smooth ? ~0u : 0u;
          if (s.smooth)
            for (int c = 0; c < 3; ++c) put_vec3(batch.normal[c], i, last_normal[c]);
          if (batch.count == kShadeBatch) flush();
        }
      }
      flush();
      if (progress) progress->advance(uint64_t(r.size()) * uint64_t(w));
    });
  });
}

void write_visibility(const DrawList& list, const DepthTarget& target, const glm::vec3& background,
                      bool cost, const SurfaceColours* surfaces, tbb::task_arena& arena,
                      ProgressSink* progress, FrameBuffers& fb) {
  const int w = target.width(), h = target.height();
  allocate_frame(w, h, fb);  // every pixel is written below
  const VisibilityRows visibility(list, target, cost);
  if (surfaces && surfaces->textured())
    fb.lod.assign(fb.pixel_count(), std::numeric_limits<float>::quiet_NaN());
  arena.execute([&] {
    tbb::parallel_for(tbb::blocked_range<int>(0, h), [&](const tbb::blocked_range<int>& r) {
      for (int y = r.begin(); y != r.end(); ++y) {
        const size_t row = fb.index(0, y);
        visibility.write(y, fb);
        fill_vec3(fb.color.data() + row, size_t(w), background);
        std::memset(static_cast<void*>(fb.normal.data() + row), 0,
                    size_t(w) * sizeof(glm::vec3));  // +0.0f is all zero bits
        if (fb.lod.empty()) continue;
        PlanesCache planes;
        for (int x = 0; x < w; ++x) {
          const uint32_t id = fb.object_id[row + size_t(x)];
          if (id == kNoId || !list.objects[id].material) continue;
          fb.lod[row + size_t(x)] = surfaces->lod(id, *list.objects[id].material,
                                                  fb.primitive_id[row + size_t(x)], x, y, planes);
        }
      }
      if (progress) progress->advance(uint64_t(r.size()) * uint64_t(w));
    });
  });
}

}  // namespace rvr::soft
