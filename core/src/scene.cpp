#include "rvr/core/scene.h"

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
  return light_samples(lights, [] { return 0.5f; });
}

}  // namespace rvr
