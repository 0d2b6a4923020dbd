// The textbook cost of each loop order as a linear model in its coefficients:
//   z-buffer  t = a + b·P + c·N            (setup, per pixel, per triangle)
//   tracer    t = a + P·(b + c·log2 N)     (setup, per ray, per ray and level of the tree)
//   hybrid    t = a + b·P + c·N + d·P·log2 N   (the sum of both; the two per-pixel terms are one)
// P is the pixel count (primary rays), N the swept axis (triangles).
#pragma once

#include <string>
#include <vector>

namespace rvr::study {

enum class ModelForm { ZBuffer, Tracer, Hybrid };

const char* to_string(ModelForm form);  // "zbuffer", "tracer", "hybrid"
std::string formula(ModelForm form);    // "t = a + b·P + c·N"

// The coefficients' names, in the order of features().
std::vector<std::string> coefficient_names(ModelForm form);

// What each coefficient multiplies at (P, N): the model is the dot product with them.
std::vector<double> features(ModelForm form, double pixels, double n);

// The coefficient multiplying P alone: it cannot be told from `a` when every point has the same
// P. Its index in coefficient_names().
constexpr size_t kPixelCoefficient = 1;

double predict(ModelForm form, const std::vector<double>& coefficients, double pixels, double n);

}  // namespace rvr::study
