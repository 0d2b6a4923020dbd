// Mismatch classes: edge ties, depth-precision ties, visibility errors and coverage errors.
#include "rvr/compare/mismatch_classes.h"

#include <algorithm>
#include <cmath>
#include <glm/glm.hpp>
#include <initializer_list>
#include <limits>
#include <memory>
#include <optional>
#include <utility>
#include <vector>

#include "dimmed_backdrop.h"
#include "rvr/core/camera.h"
#include "rvr/core/check.h"
#include "rvr/core/shapes.h"
#include "rvr/core/shapes/shape_geometry.h"
#include "rvr/core/shapes/triangle_mesh.h"

namespace rvr {

const char* to_string(DepthStore store) {
  switch (store) {
    case DepthStore::ViewFloat:
      return "float";
    case DepthStore::Window24:
      return "d24";
    case DepthStore::Window32F:
      return "d32f";
    case DepthStore::Window32FReversed:
      return "d32f_reversed";
  }
  return "float";
}

std::optional<DepthStore> parse_depth_store(const std::string& name) {
  if (name == "float") return DepthStore::ViewFloat;
  if (name == "d24") return DepthStore::Window24;
  if (name == "d32f") return DepthStore::Window32F;
  if (name == "d32f_reversed" || name == "d32f_rev") return DepthStore::Window32FReversed;
  return std::nullopt;
}

namespace {

// Relative resolution of a view depth computed in float: the ray parameter of a float
// ray-triangle test is a quotient of dot and cross products, each term rounded to 2^-24 of its
// size; with terms up to a few times the result (grazing rays), 16 ulps = 2^-20 of the depth
// bounds its error. The same bound serves softraster, which orders double view depths and
// stores them as float.
constexpr double kViewFloatRelative = 0x1p-20;

// The spacing of floats at w (0 <= w <= 1): 2^(floor(log2 w) - 23) in the normal range, the
// denormal spacing 2^-149 below it.
double float_spacing(double w) {
  if (!(w > 0.0)) return 0x1p-149;
  int e = 0;
  std::frexp(w, &e);  // w = m 2^e with m in [0.5, 1): floor(log2 w) = e - 1
  return std::ldexp(1.0, std::max(e - 1 - 23, -149));
}

}  // namespace

// GL's perspective projection with depth range [0, 1] maps view depth z (n <= z <= f) to window
// depth
//   w(z) = f (z - n) / ((f - n) z)            (near at 0)
//   1 - w(z) = n (f - z) / ((f - n) z)        (reversed Z: near at 1)
// whose slope is |dw/dz| = f n / ((f - n) z^2) either way. Two surfaces fall into one stored
// value, and the depth test cannot order them, when their window depths differ by less than
// the store's step s(w); in view depth that is
//   dz = s(w) / |dw/dz| = s(w) z^2 (f - n) / (f n).
// d24 stores w in 24-bit unsigned normalised fixed point: s = 1 / (2^24 - 1) everywhere, so
// dz ~ z^2 (f - n) / (f n) 2^-24. d32f stores w as a float: s is the float spacing at w, 2^-24
// for w in [0.5, 1), which holds every z beyond about 2n, so it is no finer than d24 there.
// Reversed Z stores n (f - z) / ((f - n) z), near n/z for f >> z: s ~ 2^-23 of it, which makes
// dz ~ 2^-23 z (f - z) / f, the constant relative resolution that makes reversed Z the fix.
double depth_resolution(DepthStore store, double z, double near, double far) {
  const double slope = far * near / ((far - near) * z * z);
  switch (store) {
    case DepthStore::ViewFloat:
      return z * kViewFloatRelative;
    case DepthStore::Window24:
      return (1.0 / 16777215.0) / slope;
    case DepthStore::Window32F:
      return float_spacing(far * (z - near) / ((far - near) * z)) / slope;
    case DepthStore::Window32FReversed:
      return float_spacing(near * (far - z) / ((far - near) * z)) / slope;
  }
  return z * kViewFloatRelative;
}

const char* to_string(MismatchClass c) {
  switch (c) {
    case MismatchClass::None:
      return "none";
    case MismatchClass::Edge:
      return "edge";
    case MismatchClass::DepthPrecision:
      return "depth_precision";
    case MismatchClass::Occlusion:
      return "occlusion";
    case MismatchClass::Coverage:
      return "coverage";
  }
  return "none";
}

std::optional<MismatchClass> parse_mismatch_class(const std::string& name) {
  for (MismatchClass c : {MismatchClass::Edge, MismatchClass::DepthPrecision,
                          MismatchClass::Occlusion, MismatchClass::Coverage})
    if (name == to_string(c)) return c;
  return std::nullopt;
}

size_t MismatchCounts::of(MismatchClass c) const {
  switch (c) {
    case MismatchClass::Edge:
      return edge;
    case MismatchClass::DepthPrecision:
      return depth_precision;
    case MismatchClass::Occlusion:
      return occlusion;
    case MismatchClass::Coverage:
      return coverage;
    case MismatchClass::None:
      break;
  }
  return 0;
}

MismatchCounts count_classes(const std::vector<MismatchClass>& classes) {
  MismatchCounts n;
  for (MismatchClass c : classes) {
    if (c == MismatchClass::Edge) ++n.edge;
    if (c == MismatchClass::DepthPrecision) ++n.depth_precision;
    if (c == MismatchClass::Occlusion) ++n.occlusion;
    if (c == MismatchClass::Coverage) ++n.coverage;
  }
  return n;
}

namespace {

// The (object, primitive) id of a pixel, background being one id whatever its primitive.
uint64_t id_key(const FrameBuffers& fb, size_t i) {
  const uint32_t obj = fb.object_id[i];
  const uint32_t prim = obj == kNoId ? kNoId : fb.primitive_id[i];
  return (uint64_t(obj) << 32) | prim;
}

bool comparable(const FrameBuffers& a, const FrameBuffers& b) {
  const size_t n = a.pixel_count();
  auto sized = [n](const FrameBuffers& fb) {
    return fb.object_id.size() == n && fb.primitive_id.size() == n && fb.depth.size() == n;
  };
  return a.width == b.width && a.height == b.height && a.width >= 0 && a.height >= 0 && sized(a) &&
         sized(b);
}

// The pinhole camera of the frame in double precision: the image-plane point of a pixel
// position at unit distance along the view axis, and the size of a pixel there.
struct PixelRays {
  glm::dvec3 eye, forward, right, up;
  double tan_half_fov_y = 1.0, aspect = 1.0, pixel_size = 1.0;
  int width = 1, height = 1;

  PixelRays(const Camera& camera, int w, int h) {
    const CameraFrame f = make_camera_frame(camera, w, h);
    eye = f.eye;
    forward = f.forward;
    right = f.right;
    up = f.up;
    tan_half_fov_y = f.tan_half_fov_y;
    aspect = f.aspect;
    width = w;
    height = h;
    pixel_size = 2.0 * tan_half_fov_y / double(h);  // square pixels: aspect = w / h
  }
  // As camera_ray_direction: the component along forward is 1.
  glm::dvec3 direction(double px, double py) const {
    const double ndc_x = 2.0 * px / double(width) - 1.0;
    const double ndc_y = 1.0 - 2.0 * py / double(height);
    return forward + right * (ndc_x * tan_half_fov_y * aspect) + up * (ndc_y * tan_half_fov_y);
  }
};

// Distance in pixels from the pixel centre (x + 0.5, y + 0.5) to the nearest line through a
// projected edge of the triangle. Each edge and the eye span a plane (normal n); it meets the
// image plane (unit distance along the view axis) in the projected edge's line, and a point d
// of the image plane lies n.d / |n without its view-axis component| from that line. For a
// centre inside the triangle, or just outside it, the nearest line is the nearest edge.
double edge_distance_pixels(const PixelRays& rays, const std::array<glm::dvec3, 3>& v, int x,
                            int y) {
  const glm::dvec3 d = rays.direction(x + 0.5, y + 0.5);
  double best = std::numeric_limits<double>::infinity();
  for (int k = 0; k < 3; ++k) {
    const glm::dvec3 n = glm::cross(v[k] - rays.eye, v[(k + 1) % 3] - rays.eye);
    const glm::dvec3 in_plane = n - glm::dot(n, rays.forward) * rays.forward;
    const double len = glm::length(in_plane);
    if (!(len > 0.0)) continue;  // an edge seen end-on from the eye: no line
    best = std::min(best, std::fabs(glm::dot(n, d)) / len / rays.pixel_size);
  }
  return best;
}

// Marks every pixel whose 3x3 neighbourhood (itself included) holds a marked pixel.
std::vector<bool> dilate3x3(const std::vector<bool>& mask, int w, int h) {
  RVR_CHECK(w >= 0 && h >= 0 && mask.size() == size_t(w) * size_t(h),
            "one mask entry per pixel of the ", w, "x", h, " frame: ", mask.size());
  std::vector<bool> out(mask.size(), false);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      bool any = false;
      for (int dy = -1; dy <= 1 && !any; ++dy)
        for (int dx = -1; dx <= 1 && !any; ++dx) {
          const int xx = x + dx, yy = y + dy;
          any = xx >= 0 && yy >= 0 && xx < w && yy < h && mask[size_t(yy) * w + xx];
        }
      out[size_t(y) * w + x] = any;
    }
  return out;
}

// Without geometry: a pixel within one pixel of an object or primitive boundary of either
// image.
std::vector<bool> near_any_boundary(const FrameBuffers& a, const FrameBuffers& b) {
  const int w = a.width, h = a.height;
  std::vector<bool> boundary(a.pixel_count(), false);
  for (const FrameBuffers* fb : {&a, &b})
    for (int y = 0; y < h; ++y)
      for (int x = 0; x < w; ++x) {
        const size_t i = fb->index(x, y);
        const uint64_t k = id_key(*fb, i);
        if (x + 1 < w && id_key(*fb, i + 1) != k) boundary[i] = boundary[i + 1] = true;
        if (y + 1 < h && id_key(*fb, i + w) != k) boundary[i] = boundary[i + w] = true;
      }
  return dilate3x3(boundary, w, h);
}

// Whether the pixel lies on the outline of the object `fb` shows there: its 3x3 neighbourhood
// in `fb` holds another object or the background.
bool on_own_outline(const FrameBuffers& fb, int x, int y) {
  const uint32_t object = fb.object_id[fb.index(x, y)];
  for (int dy = -1; dy <= 1; ++dy)
    for (int dx = -1; dx <= 1; ++dx) {
      const int xx = x + dx, yy = y + dy;
      if (xx < 0 || yy < 0 || xx >= fb.width || yy >= fb.height) continue;
      if (fb.object_id[fb.index(xx, yy)] != object) return true;
    }
  return false;
}

// The triangles an object's primitive ids index: a mesh's own, a round shape's facets (sphere,
// disc) when the renderers drew and traced its triangle form (made once, on first use); null for
// an object drawn as one primitive.
class NamedTriangles {
 public:
  NamedTriangles(const Scene& scene, int sphere_segments)
      : scene_(scene), sphere_segments_(sphere_segments), made_(scene.objects.size()) {}

  const TriangleMesh* of(uint32_t object) {
    const Object& o = scene_.objects[object];
    if (o.type == ObjectType::Triangles) return &o.mesh;
    if (sphere_segments_ <= 0) return nullptr;
    if (!made_[object]) {
      const TessellationOptions traced_as_mesh{sphere_segments_, true};
      TriangleForm form =
          visit_shape(o, [&](const auto& shape) { return shape.triangle_form(traced_as_mesh); });
      made_[object] = form.names_triangles && form.made ? std::move(form.made) : nullptr;
      if (!made_[object]) made_[object] = std::make_unique<const TriangleMesh>();
    }
    return made_[object]->triangles.empty() ? nullptr : made_[object].get();
  }

 private:
  const Scene& scene_;
  int sphere_segments_;
  std::vector<std::unique_ptr<const TriangleMesh>> made_;  // empty: drawn as one primitive
};

// Whether the hit `fb` shows at (x, y) is within the tolerance of an edge of its primitive: a
// named triangle's projected edges, or the outline of an object drawn as one primitive.
bool at_hit_edge(const FrameBuffers& fb, int x, int y, NamedTriangles& named, const Scene& scene,
                 const PixelRays& rays, double tolerance) {
  const size_t i = fb.index(x, y);
  const uint32_t object = fb.object_id[i];
  if (object == kNoId) return false;
  if (object >= scene.objects.size()) return on_own_outline(fb, x, y);
  const TriangleMesh* mesh = named.of(object);
  const uint32_t prim = fb.primitive_id[i];
  if (!mesh || prim >= mesh->triangles.size()) return on_own_outline(fb, x, y);
  const glm::uvec3 t = mesh->triangles[prim];
  const std::array<glm::dvec3, 3> v = {glm::dvec3(mesh->positions[t.x]),
                                       glm::dvec3(mesh->positions[t.y]),
                                       glm::dvec3(mesh->positions[t.z])};
  return edge_distance_pixels(rays, v, x, y) <= tolerance;
}

// The class of a mismatch that is not an edge tie: coverage when one side is background, else
// a depth-precision tie or an occlusion error by the two surfaces' separation.
MismatchClass classify_off_edge(float depth_a, float depth_b, bool hit_a, bool hit_b,
                                const MismatchContext& context, double near, double far) {
  if (!hit_a || !hit_b) return MismatchClass::Coverage;
  const double da = depth_a, db = depth_b;
  if (!std::isfinite(da) || !std::isfinite(db)) return MismatchClass::Occlusion;
  // Resolution grows with depth: the farther surface's depth gives the wider tie.
  const double z = std::max({da, db, near});
  const double tie = depth_resolution(context.store_a, z, near, far) +
                     depth_resolution(context.store_b, z, near, far);
  return std::fabs(da - db) <= tie ? MismatchClass::DepthPrecision : MismatchClass::Occlusion;
}

}  // namespace

std::vector<MismatchClass> classify_mismatches(const FrameBuffers& a, const FrameBuffers& b,
                                               const MismatchContext& context) {
  const size_t n = a.pixel_count();
  if (!comparable(a, b)) return std::vector<MismatchClass>(n, MismatchClass::Coverage);
  std::vector<MismatchClass> classes(n, MismatchClass::None);
  const Scene* scene = context.scene;
  const Camera camera = scene ? scene->camera : Camera{};
  const double near = camera.near, far = camera.far > camera.near ? camera.far : camera.near * 2;
  const PixelRays rays(camera, std::max(a.width, 1), std::max(a.height, 1));
  std::vector<bool> near_boundary;
  if (!scene) near_boundary = near_any_boundary(a, b);
  std::optional<NamedTriangles> named;
  if (scene) named.emplace(*scene, context.sphere_segments);

  for (int y = 0; y < a.height; ++y)
    for (int x = 0; x < a.width; ++x) {
      const size_t i = a.index(x, y);
      if (id_key(a, i) == id_key(b, i)) continue;
      const double tolerance = context.edge_tolerance_pixels;
      const bool edge = scene ? at_hit_edge(a, x, y, *named, *scene, rays, tolerance) ||
                                    at_hit_edge(b, x, y, *named, *scene, rays, tolerance)
                              : bool(near_boundary[i]);
      classes[i] = edge ? MismatchClass::Edge
                        : classify_off_edge(a.depth[i], b.depth[i], a.object_id[i] != kNoId,
                                            b.object_id[i] != kNoId, context, near, far);
    }
  return classes;
}

Image mismatch_class_image(const FrameBuffers& a, const std::vector<MismatchClass>& classes) {
  return overlay_on_dimmed(a, [&](size_t i) -> const float* {
    const MismatchClass c = i < classes.size() ? classes[i] : MismatchClass::Coverage;
    return c != MismatchClass::None ? kMismatchClassColours[size_t(c)].data() : nullptr;
  });
}

}  // namespace rvr
