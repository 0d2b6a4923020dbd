#include "csg_leaves.h"

#include <algorithm>
#include <cmath>
#include <limits>

namespace rvr {

CsgLeafFaces split_by_facing(const TriangleMesh& mesh, uint32_t first, uint32_t count,
                             const glm::vec3& centre, const glm::vec3& eye) {
  CsgLeafFaces faces;
  // Both halves keep the whole vertex list, which the triangles index.
  faces.front.positions = mesh.positions;
  faces.back.positions = mesh.positions;
  for (uint32_t k = 0; k < count; ++k) {
    const glm::uvec3& t = mesh.triangles[first + k];
    const glm::dvec3 p0(mesh.positions[t.x]), p1(mesh.positions[t.y]), p2(mesh.positions[t.z]);
    glm::dvec3 n = glm::cross(p1 - p0, p2 - p0);
    // Outward, whatever the winding: the centre lies inside the convex mesh.
    if (glm::dot(n, (p0 + p1 + p2) / 3.0 - glm::dvec3(centre)) < 0.0) n = -n;
    const bool faces_eye = glm::dot(n, glm::dvec3(eye) - p0) > 0.0;
    (faces_eye ? faces.front : faces.back).triangles.push_back(t);
    (faces_eye ? faces.front_triangle : faces.back_triangle).push_back(k);
  }
  return faces;
}

PixelBox leaf_box(const Sphere& leaf, const glm::dmat4& view_projection, int width, int height) {
  const double infinity = std::numeric_limits<double>::infinity();
  double lo_x = infinity, lo_y = infinity, hi_x = -infinity, hi_y = -infinity;
  for (int corner = 0; corner < 8; ++corner) {
    const glm::dvec3 offset(corner & 1 ? 1.0 : -1.0, corner & 2 ? 1.0 : -1.0,
                            corner & 4 ? 1.0 : -1.0);
    const glm::dvec4 clip =
        view_projection * glm::dvec4(glm::dvec3(leaf.center) + double(leaf.radius) * offset, 1.0);
    if (!(clip.w > 0.0)) return {0, 0, width, height};
    const double px = (clip.x / clip.w + 1.0) * 0.5 * width;
    const double py = (1.0 - clip.y / clip.w) * 0.5 * height;
    lo_x = std::min(lo_x, px);
    hi_x = std::max(hi_x, px);
    lo_y = std::min(lo_y, py);
    hi_y = std::max(hi_y, py);
  }
  auto clamp_to = [](double v, int n) { return int(std::clamp(v, 0.0, double(n))); };
  return {clamp_to(std::floor(lo_x) - 1.0, width), clamp_to(std::floor(lo_y) - 1.0, height),
          clamp_to(std::ceil(hi_x) + 1.0, width), clamp_to(std::ceil(hi_y) + 1.0, height)};
}

CsgInterval pixel_interval(double enter, double leave, uint32_t enter_facet, uint32_t leave_facet) {
  const double infinity = std::numeric_limits<double>::infinity();
  CsgInterval interval;
  const bool entered = enter < infinity, left = leave < infinity;
  interval.hit = entered || left;
  interval.enter = entered ? enter : -infinity;
  interval.leave = leave;
  interval.enter_facet = enter_facet;
  interval.leave_facet = leave_facet;
  return interval;
}

}  // namespace rvr
