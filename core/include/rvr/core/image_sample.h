// The samples of a pixel when a scene takes several (image.samples_per_pixel > 1): sample k
// sits at the same place in every pixel and looks through the same lens point, as the passes of
// an accumulation buffer do (Haeberli & Akeley 1990). The tracer takes its samples from here, and
// a z-buffer can draw sample k of every pixel as one pass (the hybrid renderer), so both see the
// same rays sample for sample.
#pragma once

#include <cstdint>
#include <glm/glm.hpp>

#include "rvr/core/scene.h"

namespace rvr {

struct ImageSample {
  // Where in the pixel, in pixels from its top-left corner: (0.5, 0.5) is the centre.
  float jx = 0.5f, jy = 0.5f;
  // The lens point, in world units along the camera's right and up axes from the eye (0, 0 for
  // a pinhole). Rays through it aim at the point the pinhole ray meets at the focus distance.
  float lens_x = 0.0f, lens_y = 0.0f;
};

// What every renderer says of a lens with one sample per pixel: a single lens point is a
// pinhole, so depth of field needs several samples (the tracer's and the accumulation buffer's).
inline constexpr const char* kDepthOfFieldNeedsSamples =
    "depth of field needs samples_per_pixel > 1: one sample is a pinhole";

// Sample k of spp for every pixel of a frame rendered with `seed`: the pixel split into an
// m x m grid (m = floor(sqrt(spp))), samples k < m*m jittered inside cell k, the rest uniform.
// With a lens (`thin_lens`: full mode and aperture_radius > 0), a point on the aperture disk:
// angle stratified by k, radius by the square root of a uniform number (uniform over the disk).
ImageSample image_sample(const Camera& camera, uint64_t seed, int k, int spp, bool thin_lens);

// Where `sample`'s rays start: the eye moved to its lens point (the eye itself for a pinhole), as
// the tracer's sample rays do; the point a z-buffer pass shades the direction to the eye from.
glm::vec3 sample_eye(const Camera& camera, const ImageSample& sample);

// The OpenGL matrices (view_matrix, projection_matrix of camera.h) that draw what `sample` sees:
// the eye moved to the lens point and the image sheared so that the focus plane stays put, then
// shifted so each pixel's centre lands where the sample is. A z-buffer drawn with them holds, at
// each pixel centre, what the sample's ray through that pixel meets.
glm::mat4 sample_view_matrix(const Camera& camera, const ImageSample& sample);
glm::mat4 sample_projection_matrix(const Camera& camera, int width, int height,
                                   const ImageSample& sample);

}  // namespace rvr
