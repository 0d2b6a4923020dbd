#include "environment_maps.h"

#include <fmt/format.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstddef>
#include <glm/gtc/matrix_transform.hpp>
#include <map>
#include <memory>
#include <optional>
#include <utility>

#include "pass_camera.h"
#include "rvr/core/check.h"
#include "rvr/core/effect_answer.h"
#include "rvr/core/shapes/sphere.h"
#include "rvr/core/shapes/triangle_mesh.h"
#include "screen_space_reflections.h"

namespace rvr {

namespace {

std::string object_label(const Scene& scene, size_t index) {
  const std::string& name = scene.objects[index].name;
  return name.empty() ? fmt::format("object#{}", index) : name;
}

// "a, b, c", the first eight names and how many more.
std::string joined(const std::vector<std::string>& names) {
  constexpr size_t kNamed = 8;
  std::string text;
  for (size_t i = 0; i < names.size() && i < kNamed; ++i) text += (i ? ", " : "") + names[i];
  if (names.size() > kNamed) text += fmt::format(" and {} more", names.size() - kNamed);
  return text;
}

// A mesh's bounds.
struct Bounds {
  glm::vec3 lo, hi;
};

Bounds bounds(const TriangleMesh& mesh) {
  Bounds b{mesh.positions.front(), mesh.positions.front()};
  for (const glm::vec3& p : mesh.positions) {
    b.lo = glm::min(b.lo, p);
    b.hi = glm::max(b.hi, p);
  }
  return b;
}

// A cube face's axis and the up its view is turned to; face f looks along forward[f].
struct FaceBasis {
  glm::dvec3 forward, right, up;
};

const std::array<FaceBasis, 6>& face_bases() {
  static const std::array<FaceBasis, 6> bases = [] {
    const glm::dvec3 axes[6] = {{1, 0, 0},  {-1, 0, 0}, {0, 1, 0},
                                {0, -1, 0}, {0, 0, 1},  {0, 0, -1}};
    const glm::dvec3 ups[6] = {{0, 1, 0}, {0, 1, 0}, {0, 0, -1}, {0, 0, 1}, {0, 1, 0}, {0, 1, 0}};
    std::array<FaceBasis, 6> b;
    for (int f = 0; f < 6; ++f) {
      // glm::lookAt's camera frame: right = forward × up, up = right × forward.
      b[f].forward = axes[f];
      b[f].right = glm::normalize(glm::cross(axes[f], ups[f]));
      b[f].up = glm::cross(b[f].right, axes[f]);
    }
    return b;
  }();
  return bases;
}

CubeFace cube_face(int f, const EnvironmentMapped& m, int size, const Camera& camera) {
  const FaceBasis& b = face_bases()[f];
  const glm::dvec3 eye(m.centre);
  CubeFace face;
  face.face = f;
  face.near = m.radius > 0.0f ? std::min(0.01f * m.radius, camera.near) : camera.near;
  face.far = std::max(2.0f * m.reach, face.near * 16.0f);
  face.view = glm::lookAt(eye, eye + b.forward, b.up);
  face.projection = glm::perspective(glm::radians(90.0), 1.0, double(face.near), double(face.far));
  face.eye = m.centre;
  face.size = size;
  face.hidden = m.object;
  return face;
}

// The six faces' colours of one object's map.
struct CubeMap {
  int size = 0;
  std::array<std::vector<glm::vec3>, 6> faces;

  // The map's colour in direction d (not zero): the face of d's largest component (x before y
  // before z on ties), bilinear between that face's pixel centres, clamped at its edges.
  glm::vec3 lookup(const glm::dvec3& d) const {
    const glm::dvec3 a = glm::abs(d);
    const int axis = a.x >= a.y && a.x >= a.z ? 0 : a.y >= a.z ? 1 : 2;
    const int f = 2 * axis + (d[axis] < 0.0 ? 1 : 0);
    const FaceBasis& b = face_bases()[f];
    const double along = glm::dot(d, b.forward);
    const double u = glm::dot(d, b.right) / along, v = glm::dot(d, b.up) / along;
    const double s = double(size);
    const double x = std::clamp((u + 1.0) * 0.5 * s - 0.5, 0.0, s - 1.0);
    const double y = std::clamp((1.0 - v) * 0.5 * s - 0.5, 0.0, s - 1.0);
    const int x0 = int(x), y0 = int(y);
    const int x1 = std::min(x0 + 1, size - 1), y1 = std::min(y0 + 1, size - 1);
    const float fx = float(x - x0), fy = float(y - y0);
    const std::vector<glm::vec3>& c = faces[f];
    const auto at = [&](int px, int py) { return c[size_t(py) * size_t(size) + size_t(px)]; };
    return (1.0f - fy) * ((1.0f - fx) * at(x0, y0) + fx * at(x1, y0)) +
           fy * ((1.0f - fx) * at(x0, y1) + fx * at(x1, y1));
  }
};

Expected<CubeMap> draw_cube_map(const EnvironmentMapped& m, int size, const Camera& camera,
                                const CubeFacePass& pass, EnvironmentStats& stats) {
  CubeMap map;
  map.size = size;
  for (int f = 0; f < 6; ++f) {
    Expected<FrameBuffers> frame = pass(cube_face(f, m, size, camera));
    if (!frame) return frame.error();
    RVR_CHECK(frame->width == size && frame->height == size &&
                  frame->colour.size() == frame->pixel_count(),
              "a cube face is a square frame of the map's size with colour at every pixel");
    map.faces[size_t(f)].assign(frame->colour.begin(), frame->colour.end());
    ++stats.faces;
  }
  return map;
}

glm::dvec3 reflected(const glm::dvec3& d, const glm::dvec3& n) {
  return d - 2.0 * glm::dot(d, n) * n;
}

// The tracer's transmitted direction through an interface whose normal n faces the incoming
// ray d, with η the ratio of the indices (1/ior entering, ior leaving); nothing when the ray is
// totally internally reflected.
std::optional<glm::dvec3> transmitted(const glm::dvec3& d, const glm::dvec3& n, double eta) {
  const double cos_i = -glm::dot(d, n);
  const double k = 1.0 - eta * eta * (1.0 - cos_i * cos_i);
  if (k < 0.0) return std::nullopt;
  return glm::normalize(eta * d + (eta * cos_i - std::sqrt(k)) * n);
}

// Where a ray from p (on or just inside the sphere) in direction t (unit) leaves the sphere: the
// farther root of |p + s t - c| = r.
glm::dvec3 sphere_exit(const glm::dvec3& p, const glm::dvec3& t, const glm::dvec3& c, double r) {
  const glm::dvec3 o = p - c;
  const double b = glm::dot(o, t), q = glm::dot(o, o) - r * r;
  return p + (-b + std::sqrt(std::max(0.0, b * b - q))) * t;
}

// For each mapped object, the pixels of `fb` that see it.
std::vector<std::vector<size_t>> pixels_per_object(const std::vector<EnvironmentMapped>& mapped,
                                                   const FrameBuffers& fb) {
  uint32_t last = 0;
  for (const EnvironmentMapped& m : mapped) last = std::max(last, m.object);
  std::vector<int> index_of(size_t(last) + 1, -1);
  for (size_t i = 0; i < mapped.size(); ++i) index_of[mapped[i].object] = int(i);
  std::vector<std::vector<size_t>> seen(mapped.size());
  for (size_t p = 0; p < fb.pixel_count(); ++p) {
    const uint32_t id = fb.object_id[p];
    if (id <= last && index_of[id] >= 0) seen[size_t(index_of[id])].push_back(p);
  }
  return seen;
}

// The answer a screen-space reflection's outcome gives its pixel.
EffectAnswer ssr_answer(SsrOutcome outcome) {
  switch (outcome) {
    case SsrOutcome::Hit:
      return EffectAnswer::SsrHit;
    case SsrOutcome::Background:
      return EffectAnswer::SsrBackground;
    case SsrOutcome::OffScreen:
      return EffectAnswer::SsrOffScreen;
    case SsrOutcome::Hidden:
      return EffectAnswer::SsrHidden;
  }
  return EffectAnswer::None;
}

}  // namespace

std::vector<EnvironmentMapped> environment_mapped(const Scene& scene, const PreparedScene& prepared,
                                                  const std::vector<PlanarMirror>& planar,
                                                  std::vector<std::string>& left_out) {
  std::vector<EnvironmentMapped> mapped;
  std::vector<Bounds> drawn;  // every drawn object's bounds, for the faces' far planes
  for (const PreparedObject& p : prepared.objects)
    if (p.mesh && !p.mesh->positions.empty()) drawn.push_back(bounds(*p.mesh));
  for (size_t i = 0; i < prepared.objects.size(); ++i) {
    const PreparedObject& p = prepared.objects[i];
    if (!p.mesh || p.mesh->positions.empty()) continue;
    const Material& material = *p.material;
    const bool is_planar = std::any_of(planar.begin(), planar.end(),
                                       [&](const PlanarMirror& m) { return m.object == i; });
    // A planar object's mirror and ior-1 layer have views of their own (planar_mirrors.h); a
    // planar mirror's transparency with another ior is left out.
    if (is_planar) {
      if (material.transparency > 0.0f && !transmits_straight(material))
        left_out.push_back(object_label(scene, i));
      continue;
    }
    const float mirror = material.mirror;
    if (!(mirror > 0.0f) && !(material.transparency > 0.0f)) continue;
    const Bounds b = bounds(*p.mesh);
    const glm::vec3 centre = 0.5f * (b.lo + b.hi);
    const Object& object = scene.objects[i];
    float reach = 0.0f;
    for (const Bounds& o : drawn) {
      const glm::vec3 far_corner = glm::max(glm::abs(o.lo - centre), glm::abs(o.hi - centre));
      reach = std::max(reach, glm::length(far_corner));
    }
    const bool sphere = object.type == ObjectType::Sphere;
    mapped.push_back({uint32_t(i), centre, 0.5f * glm::length(b.hi - b.lo), reach, mirror,
                      material.transparency, material.ior, sphere,
                      sphere ? object.sphere.center : glm::vec3(0.0f),
                      sphere ? object.sphere.radius : 0.0f});
  }
  return mapped;
}

Status add_environment_maps(const Scene& scene, const RenderOptions& options,
                            const std::vector<EnvironmentMapped>& mapped, const CubeFacePass& pass,
                            FrameBuffers& fb, EnvironmentStats& stats) {
  const std::vector<std::vector<size_t>> seen = pixels_per_object(mapped, fb);
  const PassCamera camera = pass_camera(scene, options);
  // Screen-space reflections march over the frame as the camera drew it, before any reflection.
  const bool ssr = options.zbuffer_reflection == ZBufferReflection::Ssr;
  FrameBuffers drawn;
  if (ssr) {
    drawn.width = fb.width;
    drawn.height = fb.height;
    drawn.colour = fb.colour;
    drawn.depth = fb.depth;
    drawn.object_id = fb.object_id;
  }
  for (size_t i = 0; i < mapped.size(); ++i) {
    const EnvironmentMapped& m = mapped[i];
    if (seen[i].empty()) continue;
    const float kept = 1.0f - m.mirror - m.transparency;  // the local share
    if (options.max_depth < 1) {  // the tracer's recursion limit: the shares dropped
      for (size_t p : seen[i]) {
        fb.colour[p] = kept * fb.colour[p];
        set_answer(fb, p, EffectAnswer::AtLimit);
      }
      stats.dropped += seen[i].size();
      continue;
    }
    // The map: for the transmitted share, and for the mirrored one unless the frame answers it.
    std::optional<CubeMap> map;
    if (m.transparency > 0.0f || !ssr) {
      RVR_TRY_ASSIGN(drawn_map, draw_cube_map(m, options.cube_map_size, scene.camera, pass, stats));
      map = std::move(*drawn_map);
    }
    const ScreenSpaceReflections screen(drawn, camera, double(scene.camera.near),
                                        2.0 * double(m.reach));
    for (size_t p : seen[i]) {
      const PixelRay ray =
          camera.ray(int(p % size_t(fb.width)), int(p / size_t(fb.width)), double(fb.depth[p]));
      const glm::dvec3& d = ray.direction;
      const glm::dvec3 n = glm::normalize(glm::dvec3(fb.normal[p]));
      const glm::dvec3 r = reflected(d, n);
      const glm::vec3 local = fb.colour[p];
      glm::vec3 c = kept * local;
      if (m.mirror > 0.0f && ssr) {
        glm::vec3 shown = scene.image.background;  // what a miss shows: nothing met
        const SsrOutcome outcome = screen.trace(ray.at_depth, r, m.object, shown);
        if (outcome == SsrOutcome::OffScreen || outcome == SsrOutcome::Hidden)
          shown = scene.image.background;
        ++stats.ssr[size_t(outcome)];
        c += m.mirror * shown;
        set_answer(fb, p, ssr_answer(outcome));
      } else if (m.mirror > 0.0f) {
        c += m.mirror * map->lookup(r);
        ++stats.reflected;
        set_answer(fb, p, EffectAnswer::CubeMapReflection);
      }
      // A pixel with both shares is classed by its transmitted one.
      if (m.transparency > 0.0f)
        set_answer(fb, p,
                   m.sphere ? EffectAnswer::CubeMapRefraction : EffectAnswer::FirstInterfaceOnly);
      if (m.transparency > 0.0f) {
        ++stats.refracted;
        const std::optional<glm::dvec3> t = transmitted(d, n, 1.0 / double(m.ior));
        if (!t) {
          ++stats.total_internal;
          c += m.transparency * map->lookup(r);
        } else if (!m.sphere) {
          c += m.transparency * map->lookup(*t);
        } else {
          // The second interface: leaving the sphere, the normal facing the ray (inwards).
          const glm::dvec3 centre(m.sphere_centre);
          const glm::dvec3 x = sphere_exit(ray.at_depth, *t, centre, double(m.sphere_radius));
          const glm::dvec3 inward = glm::normalize(centre - x);
          const glm::dvec3 inner = reflected(*t, inward);
          const std::optional<glm::dvec3> out = transmitted(*t, inward, double(m.ior));
          glm::vec3 exit = kept * local + m.mirror * map->lookup(inner);
          exit += m.transparency * map->lookup(out ? *out : inner);
          if (!out) ++stats.total_internal;
          c += m.transparency * exit;
        }
      }
      fb.colour[p] = c;
    }
  }
  return ok_status();
}

void mark_left_out(const std::vector<EnvironmentMapped>& mapped, FrameBuffers& fb) {
  for (const std::vector<size_t>& pixels : pixels_per_object(mapped, fb))
    for (size_t p : pixels) set_answer(fb, p, EffectAnswer::LeftOut);
}

int cube_face_shadow_map_size(const RenderOptions& options) {
  return std::max(16, std::min(options.shadow_map_size, options.cube_map_size));
}

void record_environment_stats(const EnvironmentStats& stats, double seconds, RenderOutput& out) {
  out.stats["cube_map.faces"] = double(stats.faces);
  out.stats["cube_map.reflected_pixels"] = double(stats.reflected);
  out.stats["cube_map.refracted_pixels"] = double(stats.refracted);
  out.stats["cube_map.total_internal"] = double(stats.total_internal);
  out.stats["time.cube_maps"] = seconds;
  const uint64_t marched = stats.ssr[0] + stats.ssr[1] + stats.ssr[2] + stats.ssr[3];
  if (marched == 0) return;
  out.stats["ssr.hits"] = double(stats.ssr[size_t(SsrOutcome::Hit)]);
  out.stats["ssr.background"] = double(stats.ssr[size_t(SsrOutcome::Background)]);
  out.stats["ssr.off_screen"] = double(stats.ssr[size_t(SsrOutcome::OffScreen)]);
  out.stats["ssr.hidden"] = double(stats.ssr[size_t(SsrOutcome::Hidden)]);
  const auto share = [&](SsrOutcome o) {
    return 100.0 * double(stats.ssr[size_t(o)]) / double(marched);
  };
  out.warnings.push_back(fmt::format(
      "screen-space reflections: {:.1f}% of curved-mirror pixels reflect points outside the view "
      "and {:.1f}% points hidden behind other surfaces (both shown as the background)",
      share(SsrOutcome::OffScreen), share(SsrOutcome::Hidden)));
}

void note_environment_maps(const Scene& scene, const RenderOptions& options,
                           const std::vector<EnvironmentMapped>& mapped,
                           const std::vector<std::string>& left_out,
                           std::vector<std::string>& warnings) {
  const bool drawn = options.cube_map_size > 0;
  const bool ssr = options.zbuffer_reflection == ZBufferReflection::Ssr;
  if (!left_out.empty())
    warnings.push_back(fmt::format("transparency not rendered on {} planar mirror{} ({})",
                                   left_out.size(), left_out.size() == 1 ? "" : "s",
                                   joined(left_out)));
  std::vector<std::string> mirrors, clear, flat_glass;  // flat: bent at one interface only
  std::vector<std::string> screen;                      // curved mirrors reflected in screen space
  bool clear_spheres = false;
  for (const EnvironmentMapped& m : mapped) {
    if (m.mirror > 0.0f && ssr) screen.push_back(object_label(scene, m.object));
    if (m.mirror > 0.0f && !ssr) mirrors.push_back(object_label(scene, m.object));
    if (m.transparency > 0.0f) {
      clear.push_back(object_label(scene, m.object));
      if (m.sphere)
        clear_spheres = true;
      else
        flat_glass.push_back(object_label(scene, m.object));
    }
  }
  if (!screen.empty() && drawn)
    warnings.push_back(fmt::format(
        "reflection on {} curved mirror{} ({}) by screen-space reflections: only what the camera "
        "sees, one bounce",
        screen.size(), screen.size() == 1 ? "" : "s", joined(screen)));
  if (mirrors.empty() && clear.empty()) return;
  std::string what;
  if (!mirrors.empty())
    what = fmt::format("reflection on {} curved mirror{} ({})", mirrors.size(),
                       mirrors.size() == 1 ? "" : "s", joined(mirrors));
  if (!clear.empty())
    what += fmt::format("{}refraction on {} transparent object{} ({})", what.empty() ? "" : " and ",
                        clear.size(), clear.size() == 1 ? "" : "s", joined(clear));
  if (!drawn) {
    warnings.push_back(what + " not rendered (--cube-map-size 0): local colour only");
    return;
  }
  what +=
      " from cube maps drawn at each object's centre: no parallax (the map is seen from the "
      "centre, not the surface point), no self-reflection, ";
  if (!flat_glass.empty())
    what += fmt::format("refraction at the first interface only ({}), ", joined(flat_glass));
  if (clear_spheres) what += "a sphere's back surface shaded as its front, ";
  warnings.push_back(what +
                     "and one bounce (what a map shows keeps its own mirrors' and glass's local "
                     "colour)");
}

}  // namespace rvr
