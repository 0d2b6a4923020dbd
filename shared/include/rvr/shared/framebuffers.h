// What every renderer produces: colour plus the AOVs, row-major with y = 0 the TOP row.
#pragma once

#include <cstdint>
#include <limits>
#include <map>
#include <string>
#include <vector>

#include <glm/glm.hpp>

namespace rvr {

constexpr uint32_t kNoId = 0xFFFFFFFFu;  // object/primitive id of the background

struct FrameBuffers {
  int width = 0;
  int height = 0;
  std::vector<glm::vec3> color;          // linear RGB
  std::vector<float> depth;              // view-axis depth, +inf on background
  std::vector<uint32_t> object_id;       // index in Scene::objects, kNoId on background
  std::vector<uint32_t> primitive_id;    // triangle index in the object (0 for analytic)
  std::vector<glm::vec3> normal;         // world-space shading normal facing the viewer, 0 on bg
  std::vector<float> cost;               // work per pixel (nodes + tests, or fragments)

  // Sizes every buffer and fills it with the background values.
  void reset(int w, int h, const glm::vec3& background);
  size_t index(int x, int y) const { return size_t(y) * size_t(width) + size_t(x); }
  size_t pixel_count() const { return size_t(width) * size_t(height); }
};

inline void FrameBuffers::reset(int w, int h, const glm::vec3& background) {
  width = w;
  height = h;
  size_t n = pixel_count();
  color.assign(n, background);
  depth.assign(n, std::numeric_limits<float>::infinity());
  object_id.assign(n, kNoId);
  primitive_id.assign(n, kNoId);
  normal.assign(n, glm::vec3(0.0f));
  cost.assign(n, 0.0f);
}

}  // namespace rvr
