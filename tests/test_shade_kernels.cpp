// The shading kernels (rvr/core/shade_kernel.h), each this CPU can run, against the scalar
// shading code they replace: softraster's surface_at glm formulas, the tracer's viewer and
// face_viewer, and rvr::shade_local. Bit for bit, on random pixels and on the equation's special
// cases, so an image cannot depend on the kernel, and softraster and the tracer compute the same
// colour for the same surface point.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <glm/glm.hpp>
#include <limits>
#include <memory>
#include <random>
#include <string>
#include <vector>

#include "rvr/core/expected.h"
#include "rvr/core/isa.h"
#include "rvr/core/scene.h"
#include "rvr/core/shade_batch.h"
#include "rvr/core/shade_kernel.h"
#include "rvr/core/shading.h"

using namespace rvr;

namespace {

// One pixel as the deferred pass sees it.
struct Pixel {
  glm::vec3 bary;
  glm::vec3 vertex[3], normal[3];
  bool smooth;
  Material material;
};

struct Shaded {
  glm::vec3 normal, colour;
};

// The scalar code: surface_at (soft_rasterizer.cpp, before the kernels) and shade_local.
Shaded scalar_shade(const Pixel& p, const glm::vec3& eye, const glm::vec3& ambient,
                    const std::vector<LightSample>& lights) {
  const glm::vec3 P = p.bary.x * p.vertex[0] + p.bary.y * p.vertex[1] + p.bary.z * p.vertex[2];
  const glm::vec3 geometric =
      glm::normalize(glm::cross(p.vertex[1] - p.vertex[0], p.vertex[2] - p.vertex[0]));
  const glm::vec3 shading =
      p.smooth
          ? glm::normalize(p.bary.x * p.normal[0] + p.bary.y * p.normal[1] + p.bary.z * p.normal[2])
          : geometric;
  const glm::vec3 V = glm::normalize(eye - P);
  const glm::vec3 N = face_viewer(shading, geometric, V);
  return {N, shade_local(p.material, P, N, V, ambient, lights)};
}

void put(float (&to)[3][kShadeBatch], int i, const glm::vec3& v) {
  for (int a = 0; a < 3; ++a) to[a][i] = v[a];
}

bool same_material(const Material& a, const Material& b) {
  return a.diffuse == b.diffuse && a.specular == b.specular && a.emission == b.emission &&
         a.shininess == b.shininess;
}

// Shades pixels [0, n) with one kernel, the batch padded as the deferred pass pads it. With
// `as_the_pass`, what the deferred pass leaves out is filled with NaN, so that reading it shows:
// a batch of one material passes it once (batch.material), not per slot, and flat pixels'
// vertex normals are not gathered.
std::vector<Shaded> kernel_shade(const ShadeKernels& kernels, const std::vector<Pixel>& px,
                                 const glm::vec3& eye, const glm::vec3& ambient,
                                 const std::vector<LightSample>& lights, bool as_the_pass) {
  const float nan = std::numeric_limits<float>::quiet_NaN();
  const glm::vec3 nan3(nan);
  std::vector<float> data[6];
  for (const LightSample& l : lights)
    for (int a = 0; a < 3; ++a) {
      data[a].push_back(l.position[a]);
      data[3 + a].push_back(l.intensity[a]);
    }
  const ShadeLights soa = {{data[0].data(), data[1].data(), data[2].data()},
                           {data[3].data(), data[4].data(), data[5].data()},
                           int(lights.size())};
  const float eye_xyz[3] = {eye.x, eye.y, eye.z};
  auto batch = std::make_unique<ShadeBatch>();
  std::vector<Shaded> out;
  for (size_t first = 0; first < px.size(); first += kShadeBatch) {
    const int n = int(std::min<size_t>(kShadeBatch, px.size() - first));
    const int padded = (n + kShadeMaxLanes - 1) / kShadeMaxLanes * kShadeMaxLanes;
    bool one_material = as_the_pass;
    for (int i = 1; i < n; ++i)
      one_material =
          one_material && same_material(px[first + size_t(i)].material, px[first].material);
    ShadeMaterial material;
    for (int a = 0; a < 3; ++a) {
      material.diffuse[a] = px[first].material.diffuse[a];
      material.specular[a] = px[first].material.specular[a];
      material.base[a] = shade_base(px[first].material, ambient)[a];
    }
    material.shininess = px[first].material.shininess;
    batch->material = one_material ? &material : nullptr;
    for (int i = 0; i < padded; ++i) {
      const Pixel& p = px[first + size_t(std::min(i, n - 1))];
      put(batch->bary, i, p.bary);
      const glm::vec3 flat_normal = as_the_pass ? nan3 : glm::vec3(0.0f);
      for (int c = 0; c < 3; ++c) {
        put(batch->vertex[c], i, p.vertex[c]);
        put(batch->normal[c], i, p.smooth ? p.normal[c] : flat_normal);
      }
      batch->smooth[i] = p.smooth ? ~0u : 0u;
      put(batch->diffuse, i, one_material ? nan3 : p.material.diffuse);
      put(batch->specular, i, one_material ? nan3 : p.material.specular);
      put(batch->base, i, one_material ? nan3 : shade_base(p.material, ambient));
      batch->shininess[i] = one_material ? nan : p.material.shininess;
    }
    batch->count = n;
    kernels.shade(*batch, eye_xyz, soa);
    for (int i = 0; i < n; ++i)
      out.push_back(
          {{batch->shading_normal[0][i], batch->shading_normal[1][i], batch->shading_normal[2][i]},
           {batch->colour[0][i], batch->colour[1][i], batch->colour[2][i]}});
  }
  return out;
}

bool same_bits(const glm::vec3& a, const glm::vec3& b) {
  return std::memcmp(&a, &b, sizeof a) == 0;
}

std::string show(const glm::vec3& v) {
  char s[128];
  std::snprintf(s, sizeof s, "(%.9g, %.9g, %.9g)", double(v.x), double(v.y), double(v.z));
  return s;
}

const glm::vec3 kEye(0.3f, 0.6f, 3.2f), kAmbient(0.05f, 0.07f, 0.02f);
// Three samples: in front of most surfaces, behind some, one exactly at a vertex.
const glm::vec3 kAtVertex(0.25f, -0.5f, 0.125f);
const std::vector<LightSample> kLights = {{{2.0f, 3.0f, 3.0f}, {20.0f, 18.0f, 15.0f}},
                                          {{-1.5f, 0.5f, -2.0f}, {3.0f, 4.0f, 5.0f}},
                                          {kAtVertex, {1.0f, 1.0f, 1.0f}}};

// Random pixels and the equation's special cases, each with its own material.
std::vector<Pixel> random_pixels() {
  std::mt19937 rng(7);
  std::uniform_real_distribution<float> unit(-1.0f, 1.0f), positive(0.0f, 1.0f);
  auto random_vec = [&](float scale) { return scale * glm::vec3(unit(rng), unit(rng), unit(rng)); };
  std::vector<Pixel> pixels;
  const float shininess[] = {48.0f, 1.0f, 0.0f, 7.5f, 200.0f};
  for (int k = 0; k < 3001; ++k) {  // not a multiple of any lane count or of the batch
    Pixel p;
    const float u = positive(rng), v = positive(rng) * (1.0f - u);
    p.bary = {1.0f - u - v, u, v};
    const glm::vec3 centre = random_vec(1.0f);
    for (int c = 0; c < 3; ++c) {
      p.vertex[c] = centre + random_vec(k % 7 == 0 ? 0.001f : 0.2f);  // some sub-pixel-sized
      p.normal[c] = random_vec(1.0f);
    }
    p.smooth = k % 3 != 0;
    p.material.diffuse = {positive(rng), positive(rng), positive(rng)};
    p.material.specular = {positive(rng), positive(rng), positive(rng)};
    p.material.emission = k % 5 == 0 ? glm::vec3(0.5f, 0.0f, 0.25f) : glm::vec3(0.0f);
    p.material.shininess = shininess[k % 5];
    if (k % 11 == 0) {  // no specular and no diffuse: brdf 0 skips every sample
      p.material.diffuse = glm::vec3(0.0f);
      p.material.specular = glm::vec3(0.0f);
    }
    if (k % 13 == 0) {  // P exactly at the third sample: |L - P| = 0 adds nothing
      p.bary = {1.0f, 0.0f, 0.0f};
      p.vertex[0] = kAtVertex;
    }
    pixels.push_back(p);
  }
  return pixels;
}

// Every kernel this CPU runs against scalar_shade, bit for bit.
void expect_kernels_shade_as_scalar(const std::vector<Pixel>& pixels, bool as_the_pass) {
  int tested = 0;
  for (Isa isa : kAllIsas) {
    if (!cpu_supports(isa)) continue;
    ++tested;
    const ShadeKernels& kernels = shade_kernels(isa);
    EXPECT_EQ(std::string(kernels.isa), to_string(isa));
    const std::vector<Shaded> got =
        kernel_shade(kernels, pixels, kEye, kAmbient, kLights, as_the_pass);
    ASSERT_EQ(got.size(), pixels.size());
    int failures = 0;
    for (size_t i = 0; i < pixels.size() && failures < 5; ++i) {
      const Shaded want = scalar_shade(pixels[i], kEye, kAmbient, kLights);
      if (same_bits(got[i].normal, want.normal) && same_bits(got[i].colour, want.colour)) continue;
      ++failures;
      ADD_FAILURE() << to_string(isa) << " pixel " << i << ": normal " << show(got[i].normal)
                    << " colour " << show(got[i].colour) << ", scalar " << show(want.normal) << " "
                    << show(want.colour);
    }
  }
  EXPECT_GE(tested, 1);
}

}  // namespace

TEST(ShadeKernels, EveryKernelShadesAsTheScalarShadeLocalBitForBit) {
  expect_kernels_shade_as_scalar(random_pixels(), false);
}

// The deferred pass's batches: objects in runs (one material per batch, or two when a run ends
// inside one), groups of lanes all flat, all smooth or mixed; what it does not gather is NaN.
TEST(ShadeKernels, BatchesOfOneMaterialAndFlatGroupsShadeAsTheScalarCode) {
  std::vector<Pixel> pixels = random_pixels();
  for (size_t k = 0; k < pixels.size(); ++k) {
    const size_t run = k < 1000 ? 128 : 200;  // then runs that end inside batches
    pixels[k].material = pixels[k / run * run].material;
    const size_t group = k / 16 % 3;  // 0: flat, 1: smooth, 2: alternating
    pixels[k].smooth = group == 1 || (group == 2 && k % 2 == 0);
  }
  expect_kernels_shade_as_scalar(pixels, true);
}

namespace {

// A tracer's hit: the ray (from the batch's origin), t and (u, v) on a triangle, or an analytic
// shape's normals.
struct SurfacePixel {
  float t, u, v;
  glm::vec3 direction;
  glm::vec3 e1, e2, normal[3];
  bool smooth, given;
  glm::vec3 geometric, shading;  // given
  Material material;
};

const glm::vec3 kOrigin(0.25f, 0.5f, 2.75f);

// The tracer's scalar code (TraceGeometry::surface and ray_tracer.cpp before the kernels):
// P = o + t d, normalize(cross(e1, e2)), smooth normals interpolated and divided by their
// length when it is above 0, V = -normalize(d), face_viewer, shade_local.
// With `visibility` (full mode), vis_l is visibility[l], and the samples shade_local asks it
// for are the bits of `asked`, the surface point is `position`.
Shaded scalar_shade_surface(const SurfacePixel& p, const glm::vec3& ambient,
                            const std::vector<LightSample>& lights,
                            const float* visibility = nullptr, uint32_t* asked = nullptr,
                            glm::vec3* position = nullptr) {
  const glm::vec3 P = kOrigin + p.t * p.direction;
  glm::vec3 geometric = p.geometric, shading = p.shading;
  if (!p.given) {
    geometric = glm::normalize(glm::cross(p.e1, p.e2));
    shading = geometric;
    if (p.smooth) {
      const glm::vec3 n = (1.0f - p.u - p.v) * p.normal[0] + p.u * p.normal[1] + p.v * p.normal[2];
      const float length = glm::length(n);
      if (length > 0.0f) shading = n / length;
    }
  }
  const glm::vec3 V = -glm::normalize(p.direction);
  const glm::vec3 N = face_viewer(shading, geometric, V);
  if (!visibility) return {N, shade_local(p.material, P, N, V, ambient, lights)};
  *asked = 0;
  *position = P;
  return {N, shade_local(p.material, P, N, V, ambient, lights,
                         [&](size_t l, const glm::vec3&, const glm::vec3&) {
                           *asked |= 1u << l;
                           return visibility[l];
                         })};
}

// What the kernels' full-mode path gives besides the colour: each pixel's point and the light
// samples light_needs says need a shadow ray (bit l).
struct NeedsOut {
  std::vector<glm::vec3> position;
  std::vector<uint32_t> needs;
};

// The deferred pass's pixels as hits: the same triangles and materials seen along rays from
// kOrigin; every 9th an analytic shape (given normals), every 29th a smooth triangle whose
// vertex normals cancel at the hit (length 0: the geometric normal stays).
std::vector<SurfacePixel> random_surface_pixels() {
  std::mt19937 rng(11);
  std::uniform_real_distribution<float> unit(-1.0f, 1.0f);
  std::vector<SurfacePixel> out;
  int k = 0;
  for (const Pixel& p : random_pixels()) {
    SurfacePixel s;
    const glm::vec3 P = p.bary.x * p.vertex[0] + p.bary.y * p.vertex[1] + p.bary.z * p.vertex[2];
    s.t = 0.5f + 2.0f * std::abs(unit(rng));
    s.direction = (P - kOrigin) / s.t;
    s.u = p.bary.y;
    s.v = p.bary.z;
    s.e1 = p.vertex[1] - p.vertex[0];
    s.e2 = p.vertex[2] - p.vertex[0];
    for (int c = 0; c < 3; ++c) s.normal[c] = p.normal[c];
    s.smooth = p.smooth;
    s.given = k % 9 == 0;
    s.geometric = glm::normalize(glm::vec3(unit(rng), unit(rng), unit(rng)));
    s.shading = k % 2 ? s.geometric : glm::normalize(glm::vec3(unit(rng), unit(rng), unit(rng)));
    if (k % 29 == 0) {
      s.smooth = true;
      s.u = 0.5f;
      s.v = 0.0f;
      s.normal[0] = glm::vec3(1.0f, 0.0f, 0.0f);
      s.normal[1] = glm::vec3(-1.0f, 0.0f, 0.0f);
    }
    s.material = p.material;
    out.push_back(s);
    ++k;
  }
  return out;
}

// Shades the pixels with one kernel as the tracer fills its batches: runs of one material pass
// it once (the per-slot arrays then NaN), other batches carry it per slot; what the tracer does
// not fill for a lane (vertex normals of flat triangles, triangle data of given lanes, given
// normals of triangles) is NaN.
// With `visibility` (vis of sample l at pixel p: visibility[p * lights.size() + l]), as the
// tracer's full mode: light_needs (its points and needs into `needs_out`), then shade_surfaces
// with the visibility.
std::vector<Shaded> kernel_shade_surfaces(const ShadeKernels& kernels,
                                          const std::vector<SurfacePixel>& px,
                                          const glm::vec3& ambient,
                                          const std::vector<LightSample>& lights,
                                          const std::vector<float>* visibility = nullptr,
                                          NeedsOut* needs_out = nullptr) {
  const ShadeLightArrays soa(lights);
  auto batch = std::make_unique<SurfaceBatch>();
  std::vector<Shaded> out;
  const float nan = std::numeric_limits<float>::quiet_NaN();
  const glm::vec3 nan3(nan);
  for (int a = 0; a < 3; ++a) batch->origin[a] = kOrigin[a];
  for (size_t first = 0; first < px.size(); first += kShadeBatch) {
    const int n = int(std::min<size_t>(kShadeBatch, px.size() - first));
    bool one_material = true;
    for (int i = 1; i < n; ++i)
      one_material =
          one_material && same_material(px[first + size_t(i)].material, px[first].material);
    const ShadeMaterial material = shade_material(px[first].material, ambient);
    batch->count = n;
    for (int i = 0; i < n; ++i) {
      const SurfacePixel& p = px[first + size_t(i)];
      batch->t[i] = p.t;
      put_vec3(batch->direction, i, p.direction);
      batch->u[i] = p.given ? nan : p.u;
      batch->v[i] = p.given ? nan : p.v;
      put_vec3(batch->edge1, i, p.given ? nan3 : p.e1);
      put_vec3(batch->edge2, i, p.given ? nan3 : p.e2);
      for (int c = 0; c < 3; ++c)
        put_vec3(batch->vertex_normal[c], i, p.smooth && !p.given ? p.normal[c] : nan3);
      batch->smooth[i] = p.smooth && !p.given ? ~0u : 0u;
      batch->given[i] = p.given ? ~0u : 0u;
      put_vec3(batch->geometric, i, p.given ? p.geometric : nan3);
      put_vec3(batch->shading, i, p.given ? p.shading : nan3);
      put_material(*batch, i,
                   one_material
                       ? ShadeMaterial{{nan, nan, nan}, {nan, nan, nan}, {nan, nan, nan}, nan}
                       : shade_material(p.material, ambient));
    }
    pad_batch(*batch, !one_material);
    batch->material = one_material ? &material : nullptr;
    if (!visibility) {
      kernels.shade_surfaces(*batch, soa.lights(), nullptr);
    } else {
      LightNeeds needs;
      kernels.light_needs(*batch, soa.lights(), needs);
      auto vis = std::make_unique<LightVisibility>();
      for (int i = 0; i < kShadeBatch; ++i)
        for (size_t l = 0; l < lights.size(); ++l)
          vis->vis[l][i] =
              (*visibility)[std::min(first + size_t(i), px.size() - 1) * lights.size() + l];
      for (int i = 0; i < n; ++i) {
        needs_out->position.push_back(
            {batch->position[0][i], batch->position[1][i], batch->position[2][i]});
        uint32_t bits = 0;
        for (size_t l = 0; l < lights.size(); ++l) bits |= uint32_t(needs.at(int(l), i)) << l;
        needs_out->needs.push_back(bits);
      }
      kernels.shade_surfaces(*batch, soa.lights(), vis.get());
    }
    for (int i = 0; i < n; ++i)
      out.push_back(
          {{batch->shading_normal[0][i], batch->shading_normal[1][i], batch->shading_normal[2][i]},
           {batch->colour[0][i], batch->colour[1][i], batch->colour[2][i]}});
  }
  return out;
}

void expect_surface_kernels_shade_as_scalar(const std::vector<SurfacePixel>& pixels) {
  int tested = 0;
  for (Isa isa : kAllIsas) {
    if (!cpu_supports(isa)) continue;
    ++tested;
    const std::vector<Shaded> got =
        kernel_shade_surfaces(shade_kernels(isa), pixels, kAmbient, kLights);
    ASSERT_EQ(got.size(), pixels.size());
    int failures = 0;
    for (size_t i = 0; i < pixels.size() && failures < 5; ++i) {
      const Shaded want = scalar_shade_surface(pixels[i], kAmbient, kLights);
      if (same_bits(got[i].normal, want.normal) && same_bits(got[i].colour, want.colour)) continue;
      ++failures;
      ADD_FAILURE() << to_string(isa) << " hit " << i << ": normal " << show(got[i].normal)
                    << " colour " << show(got[i].colour) << ", scalar " << show(want.normal) << " "
                    << show(want.colour);
    }
  }
  EXPECT_GE(tested, 1);
}

}  // namespace

// The tracer's primary hits: every kernel gives the bits of its scalar shading, with a material
// per pixel (mixed batches) and with runs of one material.
TEST(ShadeKernels, EveryKernelShadesTheTracersHitsAsTheScalarCodeBitForBit) {
  std::vector<SurfacePixel> pixels = random_surface_pixels();
  expect_surface_kernels_shade_as_scalar(pixels);
  for (size_t k = 0; k < pixels.size(); ++k) pixels[k].material = pixels[k / 150 * 150].material;
  expect_surface_kernels_shade_as_scalar(pixels);
}

// Full mode: every kernel asks for the visibility of the samples shade_local asks for, leaves
// from the same point, and with the same answers (0, 1 and a fraction) gives the same bits.
TEST(ShadeKernels, EveryKernelShadesTheTracersHitsWithTheirVisibilityAsTheScalarCode) {
  const std::vector<SurfacePixel> pixels = random_surface_pixels();
  std::mt19937 rng(5);
  const float answers[] = {0.0f, 1.0f, 0.25f};
  std::vector<float> visibility(pixels.size() * kLights.size());
  for (float& v : visibility) v = answers[rng() % 3];
  int tested = 0, asked_total = 0;
  for (Isa isa : kAllIsas) {
    if (!cpu_supports(isa)) continue;
    ++tested;
    NeedsOut needs;
    const std::vector<Shaded> got =
        kernel_shade_surfaces(shade_kernels(isa), pixels, kAmbient, kLights, &visibility, &needs);
    ASSERT_EQ(got.size(), pixels.size());
    int failures = 0;
    for (size_t i = 0; i < pixels.size() && failures < 5; ++i) {
      uint32_t asked = 0;
      glm::vec3 P;
      const Shaded want = scalar_shade_surface(pixels[i], kAmbient, kLights,
                                               &visibility[i * kLights.size()], &asked, &P);
      asked_total += __builtin_popcount(asked);
      if (same_bits(got[i].normal, want.normal) && same_bits(got[i].colour, want.colour) &&
          same_bits(needs.position[i], P) && needs.needs[i] == asked)
        continue;
      ++failures;
      ADD_FAILURE() << to_string(isa) << " hit " << i << ": colour " << show(got[i].colour)
                    << " point " << show(needs.position[i]) << " needs " << needs.needs[i]
                    << ", scalar " << show(want.colour) << " " << show(P) << " " << asked;
    }
  }
  EXPECT_GE(tested, 1);
  // Both kinds of sample occur: asked for (in front) and skipped (behind, at the vertex).
  EXPECT_GT(asked_total, 0);
  EXPECT_LT(asked_total, tested * int(pixels.size() * kLights.size()));
}
