// GLSL of the raster renderer. The fragment shader's shade_local mirrors
// core/include/rvr/core/shading.h operation for operation; change both together.
#pragma once

namespace rvr::shaders {

// Vertex attributes shared by both passes (one interleaved, non-indexed buffer).
constexpr unsigned kAttribPosition = 0;
constexpr unsigned kAttribNormal = 1;           // shading normal (smooth meshes)
constexpr unsigned kAttribGeometricNormal = 2;  // cross(v1 - v0, v2 - v0), same on all 3 corners
// Textured or vertex-coloured objects only (a second buffer, filled when some object varies in
// colour); elsewhere the attributes are disabled and read their constant values: uv 0, colour 1.
constexpr unsigned kAttribUv = 3;      // the mesh's uv after the material's uv_transform
constexpr unsigned kAttribColour = 4;  // linear RGB vertex colour

// Fragment outputs of the scene pass, in FBO attachment order.
constexpr unsigned kOutColour = 0;
constexpr unsigned kOutObjectId = 1;
constexpr unsigned kOutPrimitiveId = 2;
constexpr unsigned kOutViewDepth = 3;
constexpr unsigned kOutNormal = 4;
constexpr unsigned kOutLod = 5;  // drawn only when some object is textured

inline constexpr const char* kSceneVertex = R"glsl(#version 330 core
layout(location = 0) in vec3 a_position;
layout(location = 1) in vec3 a_normal;
layout(location = 2) in vec3 a_geometric_normal;
layout(location = 3) in vec2 a_uv;
layout(location = 4) in vec3 a_colour;

uniform mat4 u_view;
uniform mat4 u_projection;
// A planar mirror's view draws only what lies beyond the mirror: the world plane u_keep, as
// gl_ClipDistance[0] (enabled for those views only; (0, 0, 0, 1) keeps everything).
uniform vec4 u_keep;

out vec3 v_world;
out float v_view_depth;
out vec3 v_normal;
// flat: taken from one corner unchanged, so the facing decision is exactly the CPU's.
flat out vec3 v_geometric_normal;
out vec2 v_uv;
out vec3 v_colour;

void main() {
  vec4 eye = u_view * vec4(a_position, 1.0);
  v_world = a_position;
  v_view_depth = -eye.z;
  v_normal = a_normal;
  v_geometric_normal = a_geometric_normal;
  v_uv = a_uv;
  v_colour = a_colour;
  gl_ClipDistance[0] = dot(u_keep, vec4(a_position, 1.0));
  gl_Position = u_projection * eye;
}
)glsl";

inline constexpr const char* kSceneFragment = R"glsl(#version 330 core
#extension GL_ARB_texture_query_lod : enable
in vec3 v_world;
in float v_view_depth;
in vec3 v_normal;
flat in vec3 v_geometric_normal;
in vec2 v_uv;
in vec3 v_colour;

uniform vec3 u_eye;
uniform vec3 u_ambient;
uniform vec3 u_background;
uniform bool u_shade;            // false in visibility mode
uniform bool u_smooth;           // interpolate vertex normals, else the face normal
uniform bool u_use_primitive_id; // triangle meshes: gl_PrimitiveID; tessellated shapes: 0
uniform uint u_object_id;

uniform vec3 u_diffuse;
uniform vec3 u_specular;
uniform vec3 u_emission;
uniform float u_shininess;

// The base colour (rvr/core/surface_colour.h): u_diffuse times the texture (trilinear, the
// object's mip chain as every renderer builds it) times the interpolated vertex colour.
uniform bool u_textured;
uniform bool u_coloured;
uniform sampler2D u_texture;
vec3 g_diffuse;

// Light sample i: texel 2i = position, texel 2i+1 = intensity. A buffer texture holds
// millions of texels, where a uniform array would stop at a few hundred samples.
uniform samplerBuffer u_lights;
// This pass shades light samples [u_light_first, u_light_end) and adds emission + ambient only
// when u_base is set: full mode renders the shadow maps in batches and adds one lighting pass
// per batch (gl_rasterizer.cpp).
uniform int u_light_first;
uniform int u_light_end;
uniform bool u_base;

// Shadow maps (full mode): sample i of this batch owns layers 6(i - u_light_first) + face of
// u_shadow_maps, each holding |P - L| of the nearest surface (+huge where none) seen through
// the face's 90 degree frustum; u_face_rotation[face] turns P - L into that face's eye space.
uniform bool u_shadows;
uniform sampler2DArray u_shadow_maps;
uniform mat3 u_face_rotation[6];
uniform float u_shadow_bias;       // constant part, world units
uniform float u_shadow_texel;      // 2 / map size: a texel's largest extent in tan units
uniform bool u_shadow_pcf;

// CSG solids (csg_leaves.h). A leaf's depth pass keeps the fragments of its triangles that face
// the eye (u_csg_half 1) or of those that face away (2), outward taken from the leaf's centre:
// the centre lies inside every face's plane of the convex tessellation, so the test's sign is
// the triangle's at each of its fragments. The passes that draw the frame keep a solid's
// fragment only on the triangle where the tree puts the solid's first boundary at that pixel
// (u_csg_winners: that triangle's index in the solid's draw + 1, 0: no boundary).
uniform int u_csg_half;
uniform vec3 u_csg_centre;
uniform bool u_csg_masked;
uniform usampler2D u_csg_winners;

layout(location = 0) out vec4 o_colour;
layout(location = 1) out uint o_object_id;
layout(location = 2) out uint o_primitive_id;
layout(location = 3) out float o_view_depth;
layout(location = 4) out vec4 o_normal;
layout(location = 5) out float o_lod;

vec3 face_viewer(vec3 shading_normal, vec3 geometric_normal, vec3 to_viewer) {
  return dot(geometric_normal, to_viewer) < 0.0 ? -shading_normal : shading_normal;
}

// x^s with 0^0 = 1: GLSL leaves pow(0, 0) undefined.
float specular_power(float x, float s) {
  if (x <= 0.0) return s == 0.0 ? 1.0 : 0.0;
  return pow(x, s);
}

// Cube face of direction d (0 +x, 1 -x, 2 +y, 3 -y, 4 +z, 5 -z): the major axis; ties go to
// the first, which is fine because the faces' frusta overlap on their shared edges.
int cube_face(vec3 d) {
  vec3 a = abs(d);
  if (a.x >= a.y && a.x >= a.z) return d.x >= 0.0 ? 0 : 1;
  if (a.y >= a.z) return d.y >= 0.0 ? 2 : 3;
  return d.z >= 0.0 ? 4 : 5;
}

// vis_l of docs/design.md from sample i's shadow cube: 1 when |P - L| - bias <= the stored distance
// of P's texel, else 0; with PCF the mean of that test over the 3x3 texels around it (clamped
// to the face: no filtering across cube edges).
float shadow_visibility(int i, vec3 P, vec3 L, vec3 geometric_normal) {
  vec3 n = normalize(geometric_normal);
  float true_dist = length(P - L);
  if (dot(n, L - P) < 0.0) n = -n;  // the side of the surface the light is on
  // Normal offset: look up from P moved off its own surface, towards the light, by one texel's
  // footprint at this distance (a texel spans at most u_shadow_texel = 2/size in tan units),
  // so grazing surfaces stop reading their own neighbouring texels (acne).
  vec3 d = P + n * (u_shadow_texel * true_dist) - L;
  float dist = length(d);
  int face = cube_face(d);
  vec3 e = u_face_rotation[face] * d;  // eye space of the face, looking down -z
  vec2 uv = e.xy / max(-e.z, 1e-30) * 0.5 + 0.5;
  int size = textureSize(u_shadow_maps, 0).x;
  ivec2 texel = clamp(ivec2(floor(uv * float(size))), ivec2(0), ivec2(size - 1));
  int layer = 6 * (i - u_light_first) + face;
  // Slope-scaled term: the map holds the distance at its texel centre, up to ~0.7 texel away
  // from the lookup direction; on a surface at angle theta to the light ray that changes the
  // distance by about dist * 0.7 * texel * tan(theta). Capped so grazing surfaces keep shadows.
  float cos_theta = abs(dot(n, d / max(dist, 1e-30)));
  float tan_theta = min(sqrt(max(0.0, 1.0 - cos_theta * cos_theta)) / max(cos_theta, 1e-6), 8.0);
  float bias = u_shadow_bias + 0.75 * u_shadow_texel * dist * tan_theta;
  if (!u_shadow_pcf) {
    float stored = texelFetch(u_shadow_maps, ivec3(texel, layer), 0).r;
    return dist - bias <= stored ? 1.0 : 0.0;
  }
  float lit = 0.0;
  for (int dy = -1; dy <= 1; ++dy)
    for (int dx = -1; dx <= 1; ++dx) {
      ivec2 t = clamp(texel + ivec2(dx, dy), ivec2(0), ivec2(size - 1));
      float stored = texelFetch(u_shadow_maps, ivec3(t, layer), 0).r;
      lit += dist - bias <= stored ? 1.0 : 0.0;
    }
  return lit / 9.0;
}

vec3 shade_local(vec3 P, vec3 N, vec3 V, vec3 geometric_normal) {
  vec3 colour = u_base ? u_emission + u_ambient * g_diffuse : vec3(0.0);
  for (int i = u_light_first; i < u_light_end; ++i) {
    vec3 light_position = texelFetch(u_lights, 2 * i).xyz;
    vec3 light_intensity = texelFetch(u_lights, 2 * i + 1).xyz;
    vec3 to_light = light_position - P;
    float dist2 = dot(to_light, to_light);
    if (!(dist2 > 0.0)) continue;
    vec3 Ld = to_light / sqrt(dist2);
    float n_dot_l = max(0.0, dot(N, Ld));
    vec3 H = normalize(Ld + V);
    float n_dot_h = max(0.0, dot(N, H));
    vec3 brdf = g_diffuse * n_dot_l + u_specular * specular_power(n_dot_h, u_shininess);
    if (brdf == vec3(0.0)) continue;
    float vis = u_shadows ? shadow_visibility(i, P, light_position, geometric_normal) : 1.0;
    colour += vis * brdf * light_intensity / dist2;
  }
  return colour;
}

// The level of detail GL samples the texture at: the driver's own (textureQueryLOD) where it
// offers it, else the specification's formula on the fragment's derivatives.
float texture_lod() {
#ifdef GL_ARB_texture_query_lod
  return textureQueryLOD(u_texture, v_uv).y;
#else
  vec2 size = vec2(textureSize(u_texture, 0));
  return log2(max(length(dFdx(v_uv) * size), length(dFdy(v_uv) * size)));
#endif
}

// Whether this fragment of a CSG leaf belongs to the pass (see u_csg_half, u_csg_masked).
bool csg_keeps() {
  if (u_csg_half != 0) {
    vec3 outward = v_geometric_normal;
    if (dot(outward, v_world - u_csg_centre) < 0.0) outward = -outward;
    bool faces_eye = dot(outward, u_eye - v_world) > 0.0;
    if (faces_eye != (u_csg_half == 1)) return false;
  }
  if (u_csg_masked)
    return texelFetch(u_csg_winners, ivec2(gl_FragCoord.xy), 0).r == uint(gl_PrimitiveID) + 1u;
  return true;
}

void main() {
  if (!csg_keeps()) discard;
  // u_textured is uniform: its branch is uniform control flow, where derivatives are defined.
  float lod = uintBitsToFloat(0x7fc00000u);  // NaN: not textured
  g_diffuse = u_diffuse;
  if (u_textured) {
    lod = texture_lod();
    g_diffuse = g_diffuse * texture(u_texture, v_uv).rgb;
  }
  if (u_coloured) g_diffuse = g_diffuse * v_colour;
  o_lod = lod;
  vec3 P = v_world;
  vec3 V = normalize(u_eye - P);
  vec3 shading_normal = u_smooth ? normalize(v_normal) : normalize(v_geometric_normal);
  vec3 N = face_viewer(shading_normal, v_geometric_normal, V);

  // Alpha 1 in the base pass, 0 in additive passes (blended ONE, ONE).
  o_colour = vec4(u_shade ? shade_local(P, N, V, v_geometric_normal) : u_background,
                  u_base ? 1.0 : 0.0);
  o_object_id = u_object_id;
  o_primitive_id = u_use_primitive_id ? uint(gl_PrimitiveID) : 0u;
  o_view_depth = v_view_depth;
  o_normal = vec4(N, 0.0);
}
)glsl";

// Shadow maps: one cube face of one light sample. Positions are taken relative to the light
// and turned into the face's eye space; the fragment stores |P - L| (linear distance, exact in
// float whatever the near plane) and the target keeps the minimum (GL_MIN blending), so no
// depth buffer and no depth-precision trade-off is needed.
// A CSG leaf's pass keeps the fragments of its triangles that face the light (u_csg_half 1) or
// of those that face away (2), outward taken from the leaf's centre, as the scene program's
// leaf passes do for the eye.
inline constexpr const char* kShadowVertex = R"glsl(#version 330 core
layout(location = 0) in vec3 a_position;
layout(location = 2) in vec3 a_geometric_normal;
uniform vec3 u_light;
uniform mat3 u_rotation;
uniform mat4 u_projection;
out vec3 v_offset;
flat out vec3 v_geometric_normal;
void main() {
  v_offset = a_position - u_light;
  v_geometric_normal = a_geometric_normal;
  gl_Position = u_projection * vec4(u_rotation * v_offset, 1.0);
}
)glsl";

inline constexpr const char* kShadowFragment = R"glsl(#version 330 core
in vec3 v_offset;
flat in vec3 v_geometric_normal;
uniform vec3 u_light;
uniform int u_csg_half;
uniform vec3 u_csg_centre;
layout(location = 0) out float o_distance;
void main() {
  if (u_csg_half != 0) {
    vec3 outward = v_geometric_normal;
    if (dot(outward, u_light + v_offset - u_csg_centre) < 0.0) outward = -outward;
    bool faces_light = dot(outward, -v_offset) > 0.0;
    if (faces_light != (u_csg_half == 1)) discard;
  }
  o_distance = length(v_offset);
}
)glsl";

// The overdraw pass: every generated fragment adds 1 to its pixel (additive blending, no depth
// test), which is the rasterizer's work per pixel.
inline constexpr const char* kCostVertex = R"glsl(#version 330 core
layout(location = 0) in vec3 a_position;
uniform mat4 u_view;
uniform mat4 u_projection;
void main() { gl_Position = u_projection * (u_view * vec4(a_position, 1.0)); }
)glsl";

inline constexpr const char* kCostFragment = R"glsl(#version 330 core
layout(location = 0) out float o_cost;
void main() { o_cost = 1.0; }
)glsl";

}  // namespace rvr::shaders
