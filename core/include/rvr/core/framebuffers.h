// What every renderer produces: colour plus the AOVs, row-major with y = 0 the TOP row.
#pragma once

#include <cmath>
#include <cstdint>
#include <glm/glm.hpp>
#include <limits>
#include <map>
#include <memory>
#include <new>
#include <string>
#include <utility>
#include <vector>

#include "rvr/core/check.h"
#include "rvr/core/pixel_memory.h"

namespace rvr {

constexpr uint32_t kNoId = 0xFFFFFFFFu;  // object/primitive id of the background

// An allocator whose resize() leaves new elements uninitialised (default-initialised), so a
// renderer that writes every pixel can size its buffers without a serial pass over them: the
// pages are then first touched by the threads that render them. Its memory is recycled
// between frames (pixel_memory.h).
template <class T>
struct PixelAllocator : DefaultInitConstruct {
  using value_type = T;
  PixelAllocator() = default;
  template <class U>
  PixelAllocator(const PixelAllocator<U>&) {}
  T* allocate(size_t n) {
    static_assert(alignof(T) <= 64, "pixel memory is 64-byte aligned");
    if (n > size_t(-1) / sizeof(T)) throw std::bad_array_new_length();
    return static_cast<T*>(acquire_pixel_memory(n * sizeof(T)));
  }
  void deallocate(T* p, size_t n) noexcept { release_pixel_memory(p, n * sizeof(T)); }
  template <class U>
  bool operator==(const PixelAllocator<U>&) const {
    return true;
  }
  template <class U>
  bool operator!=(const PixelAllocator<U>&) const {
    return false;
  }
};

template <class T>
using PixelVector = std::vector<T, PixelAllocator<T>>;

struct FrameBuffers {
  int width = 0;
  int height = 0;
  PixelVector<glm::vec3> colour;       // linear RGB
  PixelVector<float> depth;            // view-axis depth, +inf on background
  PixelVector<uint32_t> object_id;     // index in Scene::objects, kNoId on background
  PixelVector<uint32_t> primitive_id;  // triangle index in the object (0 for analytic)
  PixelVector<glm::vec3> normal;       // world-space shading normal facing the viewer, 0 on bg
  PixelVector<float> cost;             // work per pixel (nodes + tests, or fragments)
  // The texture level of detail the renderer sampled at the visible surface, NaN where that is
  // not textured; empty (reset and allocate empty it) unless the scene has a textured object.
  PixelVector<float> lod;
  // How a z-buffer answered the effect at each pixel (EffectAnswer, rvr/core/effect_answer.h);
  // empty unless a z-buffer answered some effect (full mode). The tracers leave it empty.
  PixelVector<uint8_t> answer;

  // Sizes every buffer and fills it with the background values.
  void reset(int w, int h, const glm::vec3& background);
  // Sizes every buffer and leaves the contents undefined: the caller writes every pixel of
  // every buffer (set_background for the pixels nothing covers).
  void allocate(int w, int h);
  void set_background(size_t i, const glm::vec3& background) {
    colour[i] = background;
    depth[i] = std::numeric_limits<float>::infinity();
    object_id[i] = kNoId;
    primitive_id[i] = kNoId;
    normal[i] = glm::vec3(0.0f);
    cost[i] = 0.0f;
  }
  size_t index(int x, int y) const {
    RVR_DCHECK(x >= 0 && x < width && y >= 0 && y < height, "pixel (", x, ", ", y, ") of a ", width,
               "x", height, " frame");
    return size_t(y) * size_t(width) + size_t(x);
  }
  size_t pixel_count() const { return size_t(width) * size_t(height); }
};

inline void FrameBuffers::reset(int w, int h, const glm::vec3& background) {
  RVR_CHECK(w >= 0 && h >= 0, "frame size ", w, "x", h);
  width = w;
  height = h;
  size_t n = pixel_count();
  colour.assign(n, background);
  depth.assign(n, std::numeric_limits<float>::infinity());
  object_id.assign(n, kNoId);
  primitive_id.assign(n, kNoId);
  normal.assign(n, glm::vec3(0.0f));
  cost.assign(n, 0.0f);
  lod.clear();
  answer.clear();
}

inline void FrameBuffers::allocate(int w, int h) {
  RVR_CHECK(w >= 0 && h >= 0, "frame size ", w, "x", h);
  width = w;
  height = h;
  size_t n = pixel_count();
  for (auto* v : {&depth, &cost}) {
    v->clear();
    v->resize(n);
  }
  for (auto* v : {&colour, &normal}) {
    v->clear();
    v->resize(n);
  }
  for (auto* v : {&object_id, &primitive_id}) {
    v->clear();
    v->resize(n);
  }
  lod.clear();
  answer.clear();
}

// The one colour transform after shading, the same for every renderer: linear colour times
// 2^ev (ImageSettings::exposure). Nothing changes at ev = 0.
inline void apply_exposure(FrameBuffers& buffers, float ev) {
  if (ev == 0.0f) return;
  const float scale = std::exp2(ev);
  for (glm::vec3& c : buffers.colour) c *= scale;
}

}  // namespace rvr
