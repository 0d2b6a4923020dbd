// GLSL of the raster renderer. The fragment shader's shade_local mirrors
// shared/include/rvr/shared/shading.h operation for operation; change both together.
#pragma once

namespace rvr::shaders {

// Vertex attributes shared by both passes (one interleaved, non-indexed buffer).
constexpr unsigned kAttribPosition = 0;
constexpr unsigned kAttribNormal = 1;           // shading normal (smooth meshes)
constexpr unsigned kAttribGeometricNormal = 2;  // cross(v1 - v0, v2 - v0), same on all 3 corners

// Fragment outputs of the scene pass, in FBO attachment order.
constexpr unsigned kOutColour = 0;
constexpr unsigned kOutObjectId = 1;
constexpr unsigned kOutPrimitiveId = 2;
constexpr unsigned kOutViewDepth = 3;
constexpr unsigned kOutNormal = 4;

inline constexpr const char* kSceneVertex = R"glsl(#version 330 core
layout(location = 0) in vec3 a_position;
layout(location = 1) in vec3 a_normal;
layout(location = 2) in vec3 a_geometric_normal;

uniform mat4 u_view;
uniform mat4 u_projection;

out vec3 v_world;
out float v_view_depth;
out vec3 v_normal;
// flat: taken from one corner unchanged, so the facing decision is exactly the CPU's.
flat out vec3 v_geometric_normal;

void main() {
  vec4 eye = u_view * vec4(a_position, 1.0);
  v_world = a_position;
  v_view_depth = -eye.z;
  v_normal = a_normal;
  v_geometric_normal = a_geometric_normal;
  gl_Position = u_projection * eye;
}
)glsl";

inline constexpr const char* kSceneFragment = R"glsl(#version 330 core
in vec3 v_world;
in float v_view_depth;
in vec3 v_normal;
flat in vec3 v_geometric_normal;

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

// Light sample i: texel 2i = position, texel 2i+1 = intensity. A buffer texture holds
// millions of texels, where a uniform array would stop at a few hundred samples.
uniform samplerBuffer u_lights;
uniform int u_light_count;

layout(location = 0) out vec4 o_colour;
layout(location = 1) out uint o_object_id;
layout(location = 2) out uint o_primitive_id;
layout(location = 3) out float o_view_depth;
layout(location = 4) out vec4 o_normal;

vec3 face_viewer(vec3 shading_normal, vec3 geometric_normal, vec3 to_viewer) {
  return dot(geometric_normal, to_viewer) < 0.0 ? -shading_normal : shading_normal;
}

// x^s with 0^0 = 1: GLSL leaves pow(0, 0) undefined.
float specular_power(float x, float s) {
  if (x <= 0.0) return s == 0.0 ? 1.0 : 0.0;
  return pow(x, s);
}

vec3 shade_local(vec3 P, vec3 N, vec3 V) {
  vec3 colour = u_emission + u_ambient * u_diffuse;
  for (int i = 0; i < u_light_count; ++i) {
    vec3 light_position = texelFetch(u_lights, 2 * i).xyz;
    vec3 light_intensity = texelFetch(u_lights, 2 * i + 1).xyz;
    vec3 to_light = light_position - P;
    float dist2 = dot(to_light, to_light);
    if (!(dist2 > 0.0)) continue;
    vec3 Ld = to_light / sqrt(dist2);
    float n_dot_l = max(0.0, dot(N, Ld));
    vec3 H = normalize(Ld + V);
    float n_dot_h = max(0.0, dot(N, H));
    vec3 brdf = u_diffuse * n_dot_l + u_specular * specular_power(n_dot_h, u_shininess);
    if (brdf == vec3(0.0)) continue;
    float vis = 1.0;  // shadow maps come later
    colour += vis * brdf * light_intensity / dist2;
  }
  return colour;
}

void main() {
  vec3 P = v_world;
  vec3 V = normalize(u_eye - P);
  vec3 shading_normal = u_smooth ? normalize(v_normal) : normalize(v_geometric_normal);
  vec3 N = face_viewer(shading_normal, v_geometric_normal, V);

  o_colour = vec4(u_shade ? shade_local(P, N, V) : u_background, 1.0);
  o_object_id = u_object_id;
  o_primitive_id = u_use_primitive_id ? uint(gl_PrimitiveID) : 0u;
  o_view_depth = v_view_depth;
  o_normal = vec4(N, 0.0);
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
