#include "rvr/core/shade_batch.h"

#include <stddef.h>
#include <stdint.h>

#include <limits>

#include "rvr/core/check.h"
#include "rvr/core/shading.h"

namespace rvr {

namespace {

void copy3(float (&p)[3][kShadeBatch], int from, int to) {
  for (int a = 0; a < 3; ++a) p[a][to] = p[a][from];
}

void copy_material(ShadeLanes& b, int from, int to) {
  copy3(b.diffuse, from, to);
  copy3(b.specular, from, to);
  copy3(b.base, from, to);
  b.shininess[to] = b.shininess[from];
}

int padded(int count) {
  return (count + kShadeMaxLanes - 1) / kShadeMaxLanes * kShadeMaxLanes;
}

}  // namespace

ShadeMaterial shade_material(const Material& m, const glm::vec3& ambient) {
  ShadeMaterial s;
  const glm::vec3 base = shade_base(m, ambient);
  for (int a = 0; a < 3; ++a) {
    s.diffuse[a] = m.diffuse[a];
    s.specular[a] = m.specular[a];
    s.base[a] = base[a];
  }
  s.shininess = m.shininess;
  return s;
}

ShadeLightArrays::ShadeLightArrays(const std::vector<LightSample>& samples) {
  RVR_CHECK(samples.size() <= size_t(std::numeric_limits<int>::max()),
            "the kernels count light samples in an int: ", samples.size());
  for (const LightSample& l : samples)
    for (int a = 0; a < 3; ++a) {
      data_[a].push_back(l.position[a]);
      data_[3 + a].push_back(l.intensity[a]);
    }
  lights_ = {{data_[0].data(), data_[1].data(), data_[2].data()},
             {data_[3].data(), data_[4].data(), data_[5].data()},
             int(samples.size())};
}

void put_material(ShadeLanes& b, int i, const ShadeMaterial& m) {
  RVR_DCHECK(i >= 0 && i < kShadeBatch, "slot ", i, " of a batch of ", kShadeBatch);
  for (int a = 0; a < 3; ++a) {
    b.diffuse[a][i] = m.diffuse[a];
    b.specular[a][i] = m.specular[a];
    b.base[a][i] = m.base[a];
  }
  b.shininess[i] = m.shininess;
}

void pad_batch(ShadeBatch& b, bool materials) {
  RVR_CHECK(b.count >= 0 && padded(b.count) <= kShadeBatch,
            "a shade batch holds 0..kShadeBatch pixels, padded to the widest kernel: ", b.count);
  const int last = b.count - 1;
  for (int i = b.count; i < padded(b.count); ++i) {
    copy3(b.bary, last, i);
    for (int c = 0; c < 3; ++c) {
      copy3(b.vertex[c], last, i);
      copy3(b.normal[c], last, i);
    }
    b.smooth[i] = b.smooth[last];
    if (materials) copy_material(b, last, i);
  }
}

void pad_batch(SurfaceBatch& b, bool materials) {
  RVR_CHECK(b.count >= 0 && padded(b.count) <= kShadeBatch,
            "a surface batch holds 0..kShadeBatch pixels, padded to the widest kernel: ", b.count);
  const int last = b.count - 1;
  for (int i = b.count; i < padded(b.count); ++i) {
    b.t[i] = b.t[last];
    copy3(b.direction, last, i);
    b.u[i] = b.u[last];
    b.v[i] = b.v[last];
    copy3(b.edge1, last, i);
    copy3(b.edge2, last, i);
    for (int c = 0; c < 3; ++c) copy3(b.vertex_normal[c], last, i);
    b.smooth[i] = b.smooth[last];
    b.given[i] = b.given[last];
    copy3(b.geometric, last, i);
    copy3(b.shading, last, i);
    if (materials) copy_material(b, last, i);
  }
}

}  // namespace rvr
