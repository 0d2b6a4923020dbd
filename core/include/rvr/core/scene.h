// The scene model shared by every renderer: what rvr-scene/1 describes, fully resolved
// (materials by index, meshes in world space, defaults applied).
#pragma once

#include <stddef.h>

#include <cstdint>
#include <glm/glm.hpp>
#include <memory>
#include <string>
#include <vector>

#include "rvr/core/shapes/csg.h"
#include "rvr/core/shapes/shape_list.h"
#include "rvr/core/shapes/triangle_mesh.h"
#include "rvr/core/texture.h"

namespace rvr {

// A 2D affine map of texture coordinates, glTF's KHR_texture_transform, in glTF's texture space
// (v down, s = (u, 1 - v) of a mesh's uv): s' = translate(offset) * R * scale(scale) * s with
// R = [cos r, -sin r; sin r, cos r] (the extension's GLSL matrix, column-major), r = rotation in
// radians. apply() takes and returns a mesh's uv (v up).
struct UvTransform {
  glm::vec2 offset{0.0f};
  float rotation = 0.0f;
  glm::vec2 scale{1.0f};

  bool identity() const {
    return offset == glm::vec2(0.0f) && rotation == 0.0f && scale == glm::vec2(1.0f);
  }
  glm::vec2 apply(glm::vec2 uv) const;
};

struct Material {
  std::string name;
  // The base colour: diffuse times the texture (when `texture` >= 0 and the surface has texture
  // coordinates) times the interpolated vertex colour (when the mesh has them); it scales the
  // ambient and diffuse terms of the shading equation (docs/design.md).
  glm::vec3 diffuse{0.8f};
  glm::vec3 specular{0.0f};
  glm::vec3 emission{0.0f};
  float shininess = 32.0f;
  float mirror = 0.0f;
  float transparency = 0.0f;
  float ior = 1.0f;
  int32_t texture = -1;      // index into Scene::textures, or -1
  UvTransform uv_transform;  // applied to the mesh's uvs before the texture is sampled
};

enum class LightType { Point, Area };

struct Light {
  LightType type = LightType::Point;
  glm::vec3 position{0.0f};  // point
  glm::vec3 corner{0.0f};    // area: parallelogram corner + edge_u + edge_v
  glm::vec3 edge_u{0.0f};
  glm::vec3 edge_v{0.0f};
  glm::vec3 intensity{0.0f};  // total intensity (split over an area light's samples)
  int samples = 4;            // area: n per side, n x n stratified
};

struct Camera {
  glm::vec3 eye{0.0f, 0.0f, 1.0f};
  glm::vec3 target{0.0f};
  glm::vec3 up{0.0f, 1.0f, 0.0f};
  float fov_y_deg = 45.0f;
  float near = 0.01f;
  float far = 1000.0f;
  float aperture_radius = 0.0f;
  float focus_distance = 1.0f;
};

struct ImageSettings {
  int width = 640;
  int height = 480;
  glm::vec3 background{0.0f};
  int samples_per_pixel = 1;
  // Exposure in stops (EV): every renderer's linear colour is multiplied by 2^exposure after
  // shading, before it is written or compared (apply_exposure in framebuffers.h).
  float exposure = 0.0f;
};

// The kind of an object: which of its shape fields holds it. Triangle meshes and CSG trees, then
// one kind per analytic shape of shapes/shape_list.h; rvr/core/shapes.h visits them all.
#define RVR_OBJECT_TYPE(Type, Enumerator, member) , Enumerator
enum class ObjectType { Triangles, Csg RVR_ANALYTIC_SHAPES(RVR_OBJECT_TYPE) };
#undef RVR_OBJECT_TYPE

struct Object {
  std::string name;
  ObjectType type = ObjectType::Triangles;
  uint32_t material = 0;               // index into Scene::materials
  TriangleMesh mesh;                   // ObjectType::Triangles ("triangle" and "mesh" in the file)
  std::shared_ptr<const CsgNode> csg;  // ObjectType::Csg
  // One field per analytic shape, named as in shape_list.h: sphere, plane, disc...
#define RVR_OBJECT_SHAPE(Type, Enumerator, member) Type member;
  RVR_ANALYTIC_SHAPES(RVR_OBJECT_SHAPE)
#undef RVR_OBJECT_SHAPE
};

struct Scene {
  std::string source;  // file path or "builtin:NAME", used in messages and reports
  ImageSettings image;
  Camera camera;
  glm::vec3 ambient{0.0f};
  std::vector<Material> materials;  // index 0 is the built-in grey default
  std::vector<Texture> textures;    // base-colour textures, referred to by Material::texture
  std::vector<Light> lights;
  std::vector<Object> objects;
  std::vector<std::string> warnings;  // e.g. dropped degenerate triangles

  size_t triangle_count() const;
};

// The built-in grey material used when an object names none.
Material default_material();

// One point light sample: a point light is one; an area light is n x n, at the centres of
// its strata, each carrying intensity / (n*n).
struct LightSample {
  glm::vec3 position;
  glm::vec3 intensity;
};
std::vector<LightSample> light_samples(const std::vector<Light>& lights);

// The same, with each area-light sample placed at (i + jitter(), j + jitter()) / n inside its
// stratum; jitter() returns numbers in [0, 1) (0.5 gives the centres).
template <class Jitter>
std::vector<LightSample> light_samples(const std::vector<Light>& lights, Jitter&& jitter) {
  std::vector<LightSample> samples;
  for (const Light& light : lights) {
    if (light.type == LightType::Point) {
      samples.push_back({light.position, light.intensity});
      continue;
    }
    int n = light.samples;
    glm::vec3 share = light.intensity / float(n * n);
    for (int j = 0; j < n; ++j) {
      for (int i = 0; i < n; ++i) {
        float u = (float(i) + jitter()) / float(n);
        float v = (float(j) + jitter()) / float(n);
        samples.push_back({light.corner + u * light.edge_u + v * light.edge_v, share});
      }
    }
  }
  return samples;
}

}  // namespace rvr
