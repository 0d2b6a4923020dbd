#include "soft/triangle_setup.h"

#include <algorithm>
#include <cmath>
#include <iterator>
#include <limits>
#include <memory>
#include <utility>

#include "rvr/core/check.h"
#include "soft/setup_kernel.h"

namespace rvr::soft {

namespace {

// std::llround (halves away from zero) without the library call, which baseline x86-64 cannot
// inline: x minus its truncation is exact for |x| < 2^52 (screen positions in sub-pixels inside
// the guard band are far smaller), so the comparisons decide exactly as llround does.
inline int64_t round_half_away(double x) {
  int64_t i = int64_t(x);
  const double fraction = x - double(i);
  if (fraction >= 0.5) ++i;
  if (fraction <= -0.5) --i;
  return i;
}

// A vertex the rasterizer can place: finite clip coordinates and, where it is not clipped, a
// finite screen position. Others (coordinates overflowing the projection) have no position, and
// a triangle with one is dropped.
bool placeable(const ProjectedVertex& v) {
  const glm::dvec4& c = v.clip;
  if (!(std::isfinite(c.x) && std::isfinite(c.y) && std::isfinite(c.z) && std::isfinite(c.w)))
    return false;
  return v.clip_planes != 0 || (std::isfinite(v.sx) && std::isfinite(v.sy));
}

}  // namespace

TriangleSetup::TriangleSetup(int width, int height, const glm::dmat4& view_projection,
                             const std::optional<glm::dvec4>& keep)
    : width_(width), height_(height), view_projection_(view_projection), keep_(keep) {
  RVR_CHECK(width > 0 && height > 0 && width <= kMaxImageSide && height <= kMaxImageSide,
            "the renderer refuses frames outside 1..kMaxImageSide: ", width, "x", height);
  const double gx = kGuardPixels / width, gy = kGuardPixels / height;
  const glm::dvec4 frustum[6] = {{1, 0, 0, 1},  {-1, 0, 0, 1}, {0, 1, 0, 1},
                                 {0, -1, 0, 1}, {0, 0, 1, 1},  {0, 0, -1, 1}};
  // Near first: afterwards w >= near > 0, so the guard planes (scaled by w) are well defined.
  const glm::dvec4 clip[5] = {
      {0, 0, 1, 1}, {1, 0, 0, gx}, {-1, 0, 0, gx}, {0, 1, 0, gy}, {0, -1, 0, gy}};
  std::copy(frustum, frustum + 6, frustum_);
  std::copy(clip, clip + 5, clip_planes_);
  // A plane's coefficients map to clip space by the inverse transpose: keep · P =
  // keep · (VP^-1 c) = (VP^-T keep) · c.
  if (keep) keep_clip_ = glm::transpose(glm::inverse(view_projection)) * *keep;
  poly_.reserve(16);
  scratch_.reserve(16);
}

ProjectedVertex TriangleSetup::project(const glm::vec3& p) const {
  ProjectedVertex v;
  v.clip = view_projection_ * glm::dvec4(glm::dvec3(p), 1.0);
  // The planes' dot products with their zero terms left out: adding a zero product changes no
  // bit, so these are exactly glm::dot(plane, clip) (clip_polygon still uses glm::dot).
  const glm::dvec4& c = v.clip;
  const double gx = clip_planes_[1].w, gy = clip_planes_[3].w;
  v.reject = uint32_t(c.x + c.w < 0) | uint32_t(-c.x + c.w < 0) << 1 |
             uint32_t(c.y + c.w < 0) << 2 | uint32_t(-c.y + c.w < 0) << 3 |
             uint32_t(c.z + c.w < 0) << 4 | uint32_t(-c.z + c.w < 0) << 5;
  v.clip_planes = uint32_t(c.z + c.w < 0) | uint32_t(c.x + gx * c.w < 0) << 1 |
                  uint32_t(-c.x + gx * c.w < 0) << 2 | uint32_t(c.y + gy * c.w < 0) << 3 |
                  uint32_t(-c.y + gy * c.w < 0) << 4;
  if (keep_ && discarded_by(*keep_, p)) {
    v.reject |= kUserPlaneReject;
    v.clip_planes |= kUserPlaneClip;
  }
  if (v.clip_planes == 0) {  // in front of the near plane and inside the guard band
    const glm::dvec4& k = v.clip;
    // Viewport with y flipped: row 0 is the top.
    v.sx = (k.x / k.w * 0.5 + 0.5) * width_;
    v.sy = (0.5 - k.y / k.w * 0.5) * height_;
    if (!std::isfinite(v.sx) || !std::isfinite(v.sy)) {
      // Not placeable: a fixed point outside every range, so that the batch path hands the
      // triangle to add(), which drops it.
      v.fx = v.fy = std::numeric_limits<int64_t>::min();
      return v;
    }
    v.fx = round_half_away(v.sx * double(kSub));
    v.fy = round_half_away(v.sy * double(kSub));
    RVR_DCHECK(std::abs(v.fx) < (int64_t(1) << 28) && std::abs(v.fy) < (int64_t(1) << 28),
               "inside the guard band fixed point is below 2^28: ", v.fx, ", ", v.fy);
    v.inv_w = 1.0 / k.w;
  }
  return v;
}

void TriangleSetup::add(const ProjectedVertex& a, const ProjectedVertex& b,
                        const ProjectedVertex& c, uint32_t object, uint32_t primitive,
                        SetupTriangles& out, size_t& clipped) {
  // Trivial reject against the view frustum; then clip only where a plane is crossed.
  if ((a.reject & b.reject & c.reject) || !placeable(a) || !placeable(b) || !placeable(c)) {
    ++clipped;
    return;
  }
  const ProjectedVertex* v[3] = {&a, &b, &c};
  if (a.clip_planes | b.clip_planes | c.clip_planes) {
    ++clipped;
    clip_and_emit(v, object, primitive, out);
    return;
  }
  // The common case: the triangle as it is. Its barycentrics are the unit vectors, so
  // f_j = b_j / w is 1/w at vertex j and 0 elsewhere.
  double sx[3], sy[3], f[3][3], w[3];
  int64_t fx[3], fy[3];
  for (int i = 0; i < 3; ++i) {
    sx[i] = v[i]->sx;
    sy[i] = v[i]->sy;
    fx[i] = v[i]->fx;
    fy[i] = v[i]->fy;
    w[i] = v[i]->clip.w;
    // 0 / w is +0 for w > 0 (in front of the near plane): no division needed.
    for (int j = 0; j < 3; ++j) f[i][j] = i == j ? v[i]->inv_w : 0.0;
  }
  emit(sx, sy, fx, fy, f, w, object, primitive, out);
}

void TriangleSetup::clip_polygon(const Polygon& in, const glm::dvec4& plane, Polygon& out) {
  out.clear();
  for (size_t i = 0; i < in.size(); ++i) {
    const ClipVertex& a = in[i];
    const ClipVertex& b = in[(i + 1) % in.size()];
    double da = glm::dot(plane, a.c), db = glm::dot(plane, b.c);
    if (da >= 0) out.push_back(a);
    if ((da >= 0) != (db >= 0)) {
      double t = da / (da - db);
      out.push_back({a.c + t * (b.c - a.c), a.b + t * (b.b - a.b)});
    }
  }
}

void TriangleSetup::clip_and_emit(const ProjectedVertex* pv[3], uint32_t object, uint32_t primitive,
                                  SetupTriangles& out) {
  Polygon& v = poly_;
  v.resize(3);
  for (int i = 0; i < 3; ++i) {
    v[i].c = pv[i]->clip;
    v[i].b = glm::dvec3(0.0);
    v[i].b[i] = 1.0;
  }
  auto clip_by = [&](const glm::dvec4& plane) {
    bool outside = false;
    for (const ClipVertex& c : v) outside |= glm::dot(plane, c.c) < 0;
    if (!outside) return;
    clip_polygon(v, plane, scratch_);
    std::swap(v, scratch_);
  };
  for (const glm::dvec4& plane : clip_planes_) {
    clip_by(plane);
    if (v.size() < 3) break;
  }
  if (keep_clip_ && v.size() >= 3) clip_by(*keep_clip_);
  RVR_DCHECK(v.size() <= 4 + std::size(clip_planes_),
             "each clip plane adds at most one vertex to a convex polygon: ", v.size());
  // A convex polygon as a fan: the inner diagonals are shared edges, drawn once by the rule.
  for (size_t i = 1; i + 1 < v.size(); ++i) {
    const ClipVertex* cv[3] = {&v[0], &v[i], &v[i + 1]};
    double sx[3], sy[3], f[3][3], w[3];
    int64_t fx[3], fy[3];
    for (int k = 0; k < 3; ++k) {
      const glm::dvec4& c = cv[k]->c;
      sx[k] = (c.x / c.w * 0.5 + 0.5) * width_;
      sy[k] = (0.5 - c.y / c.w * 0.5) * height_;
      fx[k] = round_half_away(sx[k] * double(kSub));
      fy[k] = round_half_away(sy[k] * double(kSub));
      w[k] = c.w;
      for (int j = 0; j < 3; ++j) f[k][j] = cv[k]->b[j] / c.w;
    }
    emit(sx, sy, fx, fy, f, w, object, primitive, out);
  }
}

void TriangleSetup::emit(const double sx_in[3], const double sy_in[3], const int64_t fx[3],
                         const int64_t fy[3], const double f_in[3][3], const double w[3],
                         uint32_t object, uint32_t primitive, SetupTriangles& out) const {
  int order[3] = {0, 1, 2};
  int64_t area = (fx[1] - fx[0]) * (fy[2] - fy[0]) - (fy[1] - fy[0]) * (fx[2] - fx[0]);
  if (area == 0) return;                        // covers no pixel centre
  if (area < 0) std::swap(order[1], order[2]);  // two-sided: either winding, oriented here
  SetupTriangle t;
  double sx[3], sy[3];
  for (int i = 0; i < 3; ++i) {
    RVR_DCHECK(std::abs(fx[i]) < (int64_t(1) << 28) && std::abs(fy[i]) < (int64_t(1) << 28),
               "guard-band fixed point must fit SetupTriangle's int32_t: ", fx[i], ", ", fy[i]);
    t.x[i] = int32_t(fx[order[i]]);
    t.y[i] = int32_t(fy[order[i]]);
    sx[i] = sx_in[order[i]];
    sy[i] = sy_in[order[i]];
  }
  const int64_t min_x = std::min({t.x[0], t.x[1], t.x[2]});
  const int64_t max_x = std::max({t.x[0], t.x[1], t.x[2]});
  const int64_t min_y = std::min({t.y[0], t.y[1], t.y[2]});
  const int64_t max_y = std::max({t.y[0], t.y[1], t.y[2]});
  // The pixels whose centres ((x + 1/2) kSub) lie in the bounding box: only they can be
  // covered. Most triangles of a dense mesh hold none, and stop here.
  auto first_centre = [](int64_t lo) { return int((lo - kSub / 2 + kSub - 1) >> kSubBits); };
  auto last_centre = [](int64_t hi) { return int((hi - kSub / 2) >> kSubBits); };
  t.x0 = int16_t(std::max(0, first_centre(min_x)));
  t.y0 = int16_t(std::max(0, first_centre(min_y)));
  t.x1 = int16_t(std::min(width_ - 1, last_centre(max_x)));
  t.y1 = int16_t(std::min(height_ - 1, last_centre(max_y)));
  if (t.x0 > t.x1 || t.y0 > t.y1) return;
  RVR_DCHECK(t.x0 >= 0 && t.y0 >= 0 && t.x1 < width_ && t.y1 < height_,
             "a set-up triangle's pixel box lies on screen");
  int64_t edge_dx[3], edge_dy[3];
  for (int i = 0; i < 3; ++i) {
    const int64_t dx = int64_t(t.x[(i + 1) % 3]) - t.x[i], dy = int64_t(t.y[(i + 1) % 3]) - t.y[i];
    edge_dx[i] = dx;
    edge_dy[i] = dy;
    // y points down: with positive area, top edges run right and left edges run up.
    t.top_left[i] = (dy == 0 && dx > 0) || dy < 0;
  }
  // A small triangle's few candidate centres, tested here with the rasterizer's own edge
  // functions: one that covers none of them draws nothing, so it needs no perspective setup,
  // no bin and no raster work (at 10^6 triangles on a 1024x768 frame most are such).
  if ((t.x1 - t.x0 + 1) * (t.y1 - t.y0 + 1) <= 4) {
    bool covers = false;
    for (int y = t.y0; y <= t.y1 && !covers; ++y) {
      for (int x = t.x0; x <= t.x1 && !covers; ++x) {
        const int64_t px = int64_t(x) * kSub + kSub / 2, py = int64_t(y) * kSub + kSub / 2;
        bool inside = true;
        for (int i = 0; i < 3; ++i)
          inside &=
              edge_dx[i] * (py - t.y[i]) - edge_dy[i] * (px - t.x[i]) - (t.top_left[i] ? 0 : 1) >=
              0;
        covers = inside;
      }
    }
    if (!covers) return;
  }
  double dx1 = sx[1] - sx[0], dy1 = sy[1] - sy[0], dx2 = sx[2] - sx[0], dy2 = sy[2] - sy[0];
  double det = dx1 * dy2 - dx2 * dy1;
  if (!(std::abs(det) > 0.0) || !std::isfinite(det)) return;
  for (int j = 0; j < 3; ++j) {
    double f0 = f_in[order[0]][j], f1 = f_in[order[1]][j], f2 = f_in[order[2]][j];
    t.qa[j] = ((f1 - f0) * dy2 - (f2 - f0) * dy1) / det;
    t.qb[j] = ((f2 - f0) * dx1 - (f1 - f0) * dx2) / det;
    // The planes go through (sx[0], sy[0]) with value f0; stored at the snapped vertex 0.
    t.q0[j] = plane_at_snapped_origin(f0, t.qa[j], t.qb[j], sx[0], sy[0], t.x[0], t.y[0]);
  }
  // Inside the unsnapped triangle depth is at least the nearest vertex's. A covered centre may
  // lie up to kSnapDistance outside it, where the clamped q_j sum to at most
  // (1 + 2 d / altitude) / w_min; so no fragment is nearer than w_min / (1 + 2 d / altitude).
  // Slivers (altitude -> 0) get 0: hi-z never rejects them.
  double longest2 = 0;
  for (int i = 0; i < 3; ++i) {
    int n = (i + 1) % 3;
    longest2 =
        std::max(longest2, (sx[n] - sx[i]) * (sx[n] - sx[i]) + (sy[n] - sy[i]) * (sy[n] - sy[i]));
  }
  const double altitude = std::abs(det) / std::sqrt(longest2);
  const double w_min = std::min({w[0], w[1], w[2]});
  // Twice the bound's slack, for the rounding in computing it.
  t.min_depth = altitude > 0 ? w_min / (1.0 + 4.0 * kSnapDistance / altitude) : 0.0;
  t.object = object;
  t.primitive = primitive;
  out.push_back(t);
}

}  // namespace rvr::soft
