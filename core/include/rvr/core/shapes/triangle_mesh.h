// A triangle mesh: the scene format's "triangle" and "mesh" objects, and the triangle form of
// every other shape.
#pragma once

#include <stddef.h>

#include <cstdint>
#include <glm/glm.hpp>
#include <vector>

#include "rvr/core/shapes/shape_geometry.h"

namespace rvr {

// Triangles in world space. normals is empty (flat shading: geometric normal) or holds one
// unit normal per position (smooth shading: interpolated). uvs and colours are empty or hold
// one value per position, interpolated like the normals: texture coordinates (OpenGL's
// convention: v = 0 is the image's bottom row) and linear RGB vertex colours.
struct TriangleMesh {
  std::vector<glm::vec3> positions;
  std::vector<glm::vec3> normals;
  std::vector<glm::uvec3> triangles;
  std::vector<glm::vec2> uvs;
  std::vector<glm::vec3> colours;

  bool operator==(const TriangleMesh&) const = default;

  size_t triangle_count() const { return triangles.size(); }
  bool smooth() const { return !normals.empty(); }
  bool textured() const { return !uvs.empty(); }
  bool coloured() const { return !colours.empty(); }

  // As a shape (shape_geometry.h): its vertices bound it; it is its own triangle form, which
  // every renderer traces or draws as it is.
  void bounding_balls(std::vector<BoundingBall>& out) const;
  uint64_t triangle_count(const TessellationOptions&) const { return triangles.size(); }
  TriangleForm triangle_form(const TessellationOptions& options) const;
  bool traced_analytically(const TessellationOptions&) const { return false; }
};

}  // namespace rvr
