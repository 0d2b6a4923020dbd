#include "soft/deferred_shading.h"

#include <sys/mman.h>
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <cstdint>
#include <limits>

#include "rvr/shared/shading.h"

namespace rvr::soft {

namespace {

// What the kernel needs of an object, looked up once per frame instead of once per pixel.
struct ObjectShading {
  const TriangleMesh* mesh = nullptr;
  bool smooth = false;
  bool use_primitive_id = false;
  glm::vec3 diffuse{0.0f}, specular{0.0f}, base{0.0f};
  float shininess = 0.0f;
};

void put(float (&to)[3][kShadeBatch], int i, const glm::vec3& v) {
  to[0][i] = v.x;
  to[1][i] = v.y;
  to[2][i] = v.z;
}

// Asks for transparent huge pages over a buffer not yet touched. The frame's buffers are fresh
// memory every frame (the caller takes them away): 31 MB at 1024x768, first touched here, one
// page fault per 4 KiB (page faults were a fifth of the samples of a tessphere:100000 frame).
// Where the system grants huge pages on request, that is one fault per 2 MiB (measured: 4,600
// faults a frame before, 2,000 after). Advice only: no byte written changes, and a refusal (an
// error return) leaves the small pages.
template <class T>
void ask_for_huge_pages(PixelVector<T>& v) {
  constexpr uintptr_t kHuge = uintptr_t(2) << 20;
  const uintptr_t begin = (reinterpret_cast<uintptr_t>(v.data()) + kHuge - 1) & ~(kHuge - 1);
  const uintptr_t end = reinterpret_cast<uintptr_t>(v.data() + v.size()) & ~(kHuge - 1);
  if (end > begin) madvise(reinterpret_cast<void*>(begin), end - begin, MADV_HUGEPAGE);
}

// Repeats slot `from` in slot `to` (every input of the kernel).
void copy_slot(ShadeBatch& b, int from, int to) {
  for (int a = 0; a < 3; ++a) {
    b.bary[a][to] = b.bary[a][from];
    for (int c = 0; c < 3; ++c) {
      b.vertex[c][a][to] = b.vertex[c][a][from];
      b.normal[c][a][to] = b.normal[c][a][from];
    }
    b.diffuse[a][to] = b.diffuse[a][from];
    b.specular[a][to] = b.specular[a][from];
    b.base[a][to] = b.base[a][from];
  }
  b.smooth[to] = b.smooth[from];
  b.shininess[to] = b.shininess[from];
}

}  // namespace

void shade_pixels(const DrawList& list, const DepthTarget& target, const DeferredShading& settings,
                  const ShadeKernels& kernels, tbb::task_arena& arena, ProgressSink* progress,
                  FrameBuffers& fb) {
  const int w = target.width(), h = target.height();
  fb.allocate(w, h);  // every pixel is written below
  ask_for_huge_pages(fb.color);
  ask_for_huge_pages(fb.normal);
  ask_for_huge_pages(fb.depth);
  ask_for_huge_pages(fb.object_id);
  ask_for_huge_pages(fb.primitive_id);
  ask_for_huge_pages(fb.cost);
  std::vector<ObjectShading> objects(list.objects.size());
  for (size_t i = 0; i < objects.size(); ++i) {
    const DrawObject& d = list.objects[i];
    ObjectShading& s = objects[i];
    s.mesh = d.mesh;
    s.smooth = d.smooth;
    s.use_primitive_id = d.use_primitive_id;
    if (!d.material) continue;
    s.diffuse = d.material->diffuse;
    s.specular = d.material->specular;
    s.shininess = d.material->shininess;
    s.base = shade_base(*d.material, settings.ambient);
  }
  // The light samples as the kernel reads them (none: the colour is the base).
  std::vector<float> light_data[6];
  if (settings.colour == ShadedColour::Local && settings.samples)
    for (const LightSample& l : *settings.samples)
      for (int a = 0; a < 3; ++a) {
        light_data[a].push_back(l.position[a]);
        light_data[3 + a].push_back(l.intensity[a]);
      }
  const ShadeLights lights = {{light_data[0].data(), light_data[1].data(), light_data[2].data()},
                              {light_data[3].data(), light_data[4].data(), light_data[5].data()},
                              int(light_data[0].size())};
  const float eye[3] = {settings.eye.x, settings.eye.y, settings.eye.z};
  const bool write_colour = settings.colour != ShadedColour::Background;

  arena.execute([&] {
    tbb::parallel_for(tbb::blocked_range<int>(0, h), [&](const tbb::blocked_range<int>& r) {
      ShadeBatch batch;
      size_t pixel[kShadeBatch];  // frame-buffer index of each slot
      auto flush = [&] {
        if (batch.count == 0) return;
        const int n = batch.count;
        const int padded = (n + kShadeMaxLanes - 1) / kShadeMaxLanes * kShadeMaxLanes;
        for (int i = n; i < padded; ++i) copy_slot(batch, n - 1, i);
        kernels.shade(batch, eye, lights);
        for (int i = 0; i < n; ++i) {
          const size_t o = pixel[i];
          fb.normal[o] = {batch.shading_normal[0][i], batch.shading_normal[1][i],
                          batch.shading_normal[2][i]};
          if (write_colour)
            fb.color[o] = {batch.colour[0][i], batch.colour[1][i], batch.colour[2][i]};
        }
        batch.count = 0;
      };
      for (int y = r.begin(); y != r.end(); ++y) {
        for (int x = 0; x < w; ++x) {
          const size_t o = fb.index(x, y);
          if (!target.covered(o)) {
            fb.set_background(o, settings.background);
            fb.cost[o] = target.cost(x, y);
            continue;
          }
          const uint32_t id = target.object(o);
          const ObjectShading& s = objects[id];
          const uint32_t primitive = target.primitive(o);
          fb.cost[o] = target.cost(x, y);
          fb.depth[o] = float(target.depth(o));
          fb.object_id[o] = id;
          fb.primitive_id[o] = s.use_primitive_id ? primitive : 0u;
          if (!write_colour) fb.color[o] = settings.background;

          const int i = batch.count++;
          pixel[i] = o;
          put(batch.bary, i, target.barycentric(o));
          const TriangleMesh& mesh = *s.mesh;
          const glm::uvec3& tri = mesh.triangles[primitive];
          for (int c = 0; c < 3; ++c) put(batch.vertex[c], i, mesh.positions[tri[c]]);
          batch.smooth[i] = s.smooth ? ~0u : 0u;
          for (int c = 0; c < 3; ++c)
            put(batch.normal[c], i, s.smooth ? mesh.normals[tri[c]] : glm::vec3(0.0f));
          put(batch.diffuse, i, s.diffuse);
          put(batch.specular, i, s.specular);
          put(batch.base, i, s.base);
          batch.shininess[i] = s.shininess;
          if (batch.count == kShadeBatch) flush();
        }
      }
      flush();
      if (progress) progress->advance(uint64_t(r.size()) * uint64_t(w));
    });
  });
}

}  // namespace rvr::soft
