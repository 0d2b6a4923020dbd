#include "rvr/core/camera.h"

#include <cmath>
#include <glm/gtc/matrix_transform.hpp>

namespace rvr {

CameraFrame make_camera_frame(const Camera& camera, int width, int height) {
  CameraFrame f;
  f.eye = camera.eye;
  f.forward = glm::normalize(camera.target - camera.eye);
  f.right = glm::normalize(glm::cross(f.forward, camera.up));
  f.up = glm::cross(f.right, f.forward);
  f.tan_half_fov_y = std::tan(glm::radians(camera.fov_y_deg) * 0.5f);
  f.aspect = float(width) / float(height);
  f.width = width;
  f.height = height;
  return f;
}

glm::mat4 view_matrix(const Camera& camera) {
  return glm::lookAt(camera.eye, camera.target, camera.up);
}

glm::mat4 projection_matrix(const Camera& camera, int width, int height) {
  return glm::perspective(glm::radians(camera.fov_y_deg), float(width) / float(height), camera.near,
                          camera.far);
}

}  // namespace rvr
