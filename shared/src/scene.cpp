#include "rvr/shared/scene.h"

namespace rvr {

size_t Scene::triangle_count() const {
  size_t n = 0;
  for (const Object& o : objects) n += o.mesh.triangle_count();
  return n;
}

Material default_material() {
  Material m;
  m.name = "default";
  return m;
}

std::vector<LightSample> light_samples(const std::vector<Light>& lights) {
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
        float u = (float(i) + 0.5f) / float(n);
        float v = (float(j) + 0.5f) / float(n);
        samples.push_back({light.corner + u * light.edge_u + v * light.edge_v, share});
      }
    }
  }
  return samples;
}

}  // namespace rvr
