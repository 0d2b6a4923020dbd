#include "planar_mirrors.h"

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <map>
#include <memory>
#include <string>
#include <utility>

#include "rvr/core/check.h"
#include "rvr/core/effect_answer.h"
#include "rvr/core/scene.h"
#include "rvr/core/shapes/triangle_mesh.h"

namespace rvr {

namespace {

// The plane of a flat mesh, or nothing: every vertex within a millionth of the mesh's extent of
// the plane through its largest triangle, and every vertex normal (a smooth mesh's) that plane's
// normal to 1e-5, so that the tracer's reflection, about the shading normal, is the plane's.
std::optional<glm::dvec4> flat_plane(const TriangleMesh& mesh) {
  if (mesh.triangles.empty()) return std::nullopt;
  glm::dvec3 n(0.0);
  double largest = 0.0;
  glm::dvec3 lo(mesh.positions.front()), hi(mesh.positions.front());
  for (const glm::vec3& p : mesh.positions) {
    lo = glm::min(lo, glm::dvec3(p));
    hi = glm::max(hi, glm::dvec3(p));
  }
  for (const glm::uvec3& t : mesh.triangles) {
    const glm::dvec3 a(mesh.positions[t.x]), b(mesh.positions[t.y]), c(mesh.positions[t.z]);
    const glm::dvec3 cross = glm::cross(b - a, c - a);
    const double area = glm::length(cross);
    if (area > largest) {
      largest = area;
      n = cross / area;
    }
  }
  if (!(largest > 0.0)) return std::nullopt;
  const glm::dvec3 on(mesh.positions[mesh.triangles.front().x]);
  // The point of the largest triangle would do as well; any vertex is on a flat mesh's plane.
  const double d = -glm::dot(n, on);
  const double tolerance = 1e-6 * std::max(1.0, glm::length(hi - lo));
  for (const glm::vec3& p : mesh.positions)
    if (std::abs(glm::dot(n, glm::dvec3(p)) + d) > tolerance) return std::nullopt;
  for (const glm::vec3& v : mesh.normals)
    if (std::abs(std::abs(glm::dot(n, glm::normalize(glm::dvec3(v)))) - 1.0) > 1e-5)
      return std::nullopt;
  return glm::dvec4(n, d);
}

}  // namespace

bool transmits_straight(const Material& material) {
  return material.transparency > 0.0f && material.ior == 1.0f;
}

std::vector<PlanarMirror> planar_mirrors(const PreparedScene& prepared) {
  std::vector<PlanarMirror> mirrors;
  for (size_t i = 0; i < prepared.objects.size(); ++i) {
    const PreparedObject& p = prepared.objects[i];
    if (!p.mesh) continue;
    const Material& material = *p.material;
    const float layer = transmits_straight(material) ? material.transparency : 0.0f;
    if (!(material.mirror > 0.0f) && !(layer > 0.0f)) continue;
    if (const std::optional<glm::dvec4> plane = flat_plane(*p.mesh))
      mirrors.push_back({uint32_t(i), *plane, material.mirror, layer});
  }
  return mirrors;
}

glm::dmat4 reflection_matrix(const glm::dvec4& plane) {
  const glm::dvec3 n(plane);
  glm::dmat4 r(1.0);
  for (int c = 0; c < 3; ++c)
    for (int row = 0; row < 3; ++row) r[c][row] -= 2.0 * n[row] * n[c];
  for (int row = 0; row < 3; ++row) r[3][row] = -2.0 * plane.w * n[row];
  return r;
}

namespace {

// The view `parent` sees reflected in mirror m: its reflections then m's (a point P beyond the
// mirror is drawn where the parent would draw its mirror image), the parent's eye reflected,
// and only what lies on the parent eye's side of the mirror drawn (what a ray leaving the mirror
// towards that side can meet).
MirrorView reflected_view(const MirrorView& parent, const PlanarMirror& m) {
  MirrorView child;
  const glm::dmat4 r = reflection_matrix(m.plane);
  child.reflection = parent.reflection * r;
  child.eye = glm::vec3(r * glm::dvec4(glm::dvec3(parent.eye), 1.0));
  const double side = glm::dot(m.plane, glm::dvec4(glm::dvec3(parent.eye), 1.0));
  child.keep = side >= 0.0 ? m.plane : -m.plane;
  child.hidden = {m.object};
  child.depth = parent.depth + 1;
  return child;
}

// The view `parent` sees through layer m: the same view without m (what the transmitted ray,
// going straight on, meets beyond it). Everything the parent sees at m's pixels lies beyond m,
// so nothing needs clipping.
MirrorView view_behind(const MirrorView& parent, const PlanarMirror& m) {
  MirrorView child = parent;
  child.hidden.push_back(m.object);
  child.depth = parent.depth + 1;
  return child;
}

}  // namespace

namespace {

// The pixels of a view that matter (all of the camera's; of a reflected view, those where the
// view above it sees its mirror), with the view's colour and object id at each.
struct ViewPixels {
  std::vector<size_t> pixel;
  std::vector<glm::vec3> colour;
  std::vector<uint32_t> id;
};

// For each mirror, the indices into `px` of the pixels that see it.
std::vector<std::vector<size_t>> pixels_per_mirror(const std::vector<PlanarMirror>& mirrors,
                                                   const ViewPixels& px) {
  uint32_t last_object = 0;
  for (const PlanarMirror& m : mirrors) last_object = std::max(last_object, m.object);
  std::vector<int> mirror_of(size_t(last_object) + 1, -1);
  for (size_t i = 0; i < mirrors.size(); ++i) mirror_of[mirrors[i].object] = int(i);
  std::vector<std::vector<size_t>> seen_by(mirrors.size());
  for (size_t k = 0; k < px.id.size(); ++k) {
    const uint32_t id = px.id[k];
    if (id <= last_object && mirror_of[id] >= 0) seen_by[size_t(mirror_of[id])].push_back(k);
  }
  return seen_by;
}

// The frame of `child` at the pixels `seen` (indices into `px`), drawn by `pass`.
Expected<ViewPixels> child_pixels(const MirrorView& child, const MirrorViewPass& pass,
                                  const ViewPixels& px, const std::vector<size_t>& seen) {
  Expected<FrameBuffers> frame = pass(child);
  if (!frame) return frame.error();
  RVR_CHECK(frame->colour.size() == frame->pixel_count() &&
                frame->object_id.size() == frame->pixel_count(),
            "a child view has colour and ids at every pixel");
  ViewPixels out;
  for (size_t k : seen) {
    const size_t p = px.pixel[k];
    RVR_CHECK(p < frame->pixel_count(), "a child view has the frame's size");
    out.pixel.push_back(p);
    out.colour.push_back(frame->colour[p]);
    out.id.push_back(frame->object_id[p]);
  }
  return out;
}

// The recursion of add_planar_reflections over the pixels `px` of `view`. A child view's frame is
// kept only at the pixels that see its object (what the view above needs), so a chain of
// reflections holds one frame at a time however deep it goes.
Status reflect(const std::vector<PlanarMirror>& mirrors, int max_depth, const MirrorView& view,
               const MirrorViewPass& pass, ViewPixels& px, MirrorStats& stats) {
  const std::vector<std::vector<size_t>> seen_by = pixels_per_mirror(mirrors, px);
  for (size_t i = 0; i < mirrors.size(); ++i) {
    const PlanarMirror& m = mirrors[i];
    const std::vector<size_t>& seen = seen_by[i];
    if (seen.empty()) continue;
    const float kept = 1.0f - m.mirror - m.transparency;  // the local share
    if (view.depth >= max_depth) {  // the tracer's recursion limit: the shares dropped
      for (size_t k : seen) px.colour[k] = kept * px.colour[k];
      stats.dropped += seen.size();
      continue;
    }
    // A child view at the pixels `seen`, drawn, with its own mirrors and layers composited.
    const auto drawn_child = [&](const MirrorView& child, ViewPixels& into) -> Status {
      RVR_TRY_ASSIGN(drawn, child_pixels(child, pass, px, seen));
      into = std::move(*drawn);
      stats.deepest = std::max(stats.deepest, child.depth);
      return reflect(mirrors, max_depth, child, pass, into, stats);
    };
    ViewPixels reflected, behind;
    if (m.mirror > 0.0f) {
      RVR_TRY(drawn_child(reflected_view(view, m), reflected));
      ++stats.passes;
      stats.pixels += seen.size();
    }
    if (m.transparency > 0.0f) {
      RVR_TRY(drawn_child(view_behind(view, m), behind));
      ++stats.layer_passes;
      stats.layer_pixels += seen.size();
    }
    // The tracer's sum: (1 - mirror - transparency) · local, plus mirror · reflected, plus
    // transparency · what the straight transmitted ray meets. A planar mirror with another ior
    // is not a layer: its transparency share stays local (the z-buffers leave it out).
    for (size_t j = 0; j < seen.size(); ++j) {
      glm::vec3& c = px.colour[seen[j]];
      glm::vec3 sum = kept * c;
      if (m.mirror > 0.0f) sum += m.mirror * reflected.colour[j];
      if (m.transparency > 0.0f) sum += m.transparency * behind.colour[j];
      c = sum;
    }
  }
  return ok_status();
}

}  // namespace

Status add_planar_reflections(const std::vector<PlanarMirror>& mirrors, int max_depth,
                              const MirrorView& view, const MirrorViewPass& pass, FrameBuffers& fb,
                              MirrorStats& stats) {
  ViewPixels px;
  px.pixel.resize(fb.pixel_count());
  for (size_t p = 0; p < px.pixel.size(); ++p) px.pixel[p] = p;
  px.colour.assign(fb.colour.begin(), fb.colour.end());
  px.id.assign(fb.object_id.begin(), fb.object_id.end());
  // What answers each pixel that sees a planar mirror or layer (its shares drop at the limit).
  const std::vector<std::vector<size_t>> seen_by = pixels_per_mirror(mirrors, px);
  for (size_t i = 0; i < mirrors.size(); ++i) {
    const EffectAnswer answer = view.depth >= max_depth          ? EffectAnswer::AtLimit
                                : mirrors[i].transparency > 0.0f ? EffectAnswer::LayerView
                                                                 : EffectAnswer::ReflectedView;
    for (size_t k : seen_by[i]) set_answer(fb, px.pixel[k], answer);
  }
  RVR_TRY(reflect(mirrors, max_depth, view, pass, px, stats));
  std::copy(px.colour.begin(), px.colour.end(), fb.colour.begin());
  return ok_status();
}

void record_mirror_stats(const MirrorStats& stats, double seconds, RenderOutput& out) {
  out.stats["mirror.views"] = double(stats.passes);
  out.stats["mirror.depth"] = double(stats.deepest);
  out.stats["mirror.pixels"] = double(stats.pixels);
  out.stats["mirror.pixels_at_limit"] = double(stats.dropped);
  out.stats["time.mirrors"] = seconds;
  if (stats.layer_passes == 0) return;
  out.stats["layer.views"] = double(stats.layer_passes);
  out.stats["layer.pixels"] = double(stats.layer_pixels);
}

}  // namespace rvr
