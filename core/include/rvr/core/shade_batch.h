// Filling the shading kernels' batches (rvr/core/shade_kernel.h) from baseline code: the
// materials and light samples in the kernels' form, pixels put into slots, and the padding of a
// batch to the widest kernel's lanes. Kept apart from shade_kernel.h, which the kernel
// translation units include: inline code there could be instantiated with wide instructions.
#pragma once

#include <glm/glm.hpp>
#include <vector>

#include "rvr/core/scene.h"
#include "rvr/core/shade_kernel.h"

namespace rvr {

// A material's terms as the kernels read them (base = shade_base(m, ambient)).
ShadeMaterial shade_material(const Material& m, const glm::vec3& ambient);

// Light samples in structure-of-arrays form, in summation order; lights() points into this
// object, which must outlive its use.
class ShadeLightArrays {
 public:
  explicit ShadeLightArrays(const std::vector<LightSample>& samples);
  ShadeLightArrays(const ShadeLightArrays&) = delete;
  ShadeLightArrays& operator=(const ShadeLightArrays&) = delete;
  const ShadeLights& lights() const { return lights_; }

 private:
  std::vector<float> data_[6];  // position x, y, z, intensity r, g, b
  ShadeLights lights_;
};

inline void put_vec3(float (&to)[3][kShadeBatch], int i, const glm::vec3& v) {
  to[0][i] = v.x;
  to[1][i] = v.y;
  to[2][i] = v.z;
}

// Slot i's own material (for batches whose material is null).
void put_material(ShadeLanes& b, int i, const ShadeMaterial& m);

// Pads pixels [count, next multiple of kShadeMaxLanes) with copies of the last one (every input
// the kernel reads; the per-slot materials too when `materials`).
void pad_batch(ShadeBatch& b, bool materials);
void pad_batch(SurfaceBatch& b, bool materials);

}  // namespace rvr
