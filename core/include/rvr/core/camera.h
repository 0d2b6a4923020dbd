// The camera both renderers share: OpenGL look-at + perspective, pixel (0,0) at the top left.
#pragma once

#include <glm/glm.hpp>

#include "rvr/core/scene.h"

namespace rvr {

struct CameraFrame {
  glm::vec3 eye;
  glm::vec3 forward;  // unit, towards target (eye-space -z)
  glm::vec3 right;    // unit, eye-space +x
  glm::vec3 up;       // unit, eye-space +y
  float tan_half_fov_y;
  float aspect;  // width / height
  int width, height;
};

CameraFrame make_camera_frame(const Camera& camera, int width, int height);

// Direction (not normalised; its component along forward is 1) through the continuous image
// position (px, py), measured in pixels from the top-left corner. The pixel centre of (x, y)
// is (x + 0.5, y + 0.5). With forward component 1, t along this direction is the view depth.
inline glm::vec3 camera_ray_direction(const CameraFrame& f, float px, float py) {
  float ndc_x = 2.0f * px / float(f.width) - 1.0f;
  float ndc_y = 1.0f - 2.0f * py / float(f.height);
  return f.forward + f.right * (ndc_x * f.tan_half_fov_y * f.aspect) +
         f.up * (ndc_y * f.tan_half_fov_y);
}

// The OpenGL matrices equivalent to the frame (glm::lookAt, glm::perspective).
glm::mat4 view_matrix(const Camera& camera);
glm::mat4 projection_matrix(const Camera& camera, int width, int height);

}  // namespace rvr
