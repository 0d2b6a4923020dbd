// The structural similarity of two luminance images (Wang et al. 2004), per pixel: compare's
// whole-image SSIM is its mean, and each effect's its mean over the effect's mask.
#pragma once

#include <glm/glm.hpp>
#include <vector>

namespace rvr {

// The luminance SSIM is computed on: Rec. 709 weights of the colour clamped to [0, 1] (NaN as 0).
float luminance(const glm::vec3& c);

// SSIM at every pixel of two w x h luminance images, row-major: an 11x11 Gaussian window (sigma
// 1.5), C1 = 0.01^2, C2 = 0.03^2. Near the borders (and in images smaller than the window) the
// window is cut to the image and renormalised, so every pixel has a value. Empty for an empty
// image.
std::vector<double> ssim_map(const std::vector<float>& ya, const std::vector<float>& yb, int w,
                             int h);

// The mean of a w-wide ssim_map (1 for an empty one).
double mean_ssim(const std::vector<double>& map, int w);

}  // namespace rvr
