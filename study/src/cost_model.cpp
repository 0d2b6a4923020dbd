// The cost models' features (see cost_model.h).
#include "rvr/study/cost_model.h"

#include <cmath>

namespace rvr::study {

const char* to_string(ModelForm form) {
  switch (form) {
    case ModelForm::ZBuffer:
      return "zbuffer";
    case ModelForm::Tracer:
      return "tracer";
    case ModelForm::Hybrid:
      return "hybrid";
  }
  return "?";
}

std::string formula(ModelForm form) {
  switch (form) {
    case ModelForm::ZBuffer:
      return "t = a + b·P + c·N";
    case ModelForm::Tracer:
      return "t = a + P·(b + c·log2 N)";
    case ModelForm::Hybrid:
      return "t = a + b·P + c·N + d·P·log2 N";
  }
  return "?";
}

std::vector<std::string> coefficient_names(ModelForm form) {
  if (form == ModelForm::Hybrid) return {"a", "b", "c", "d"};
  return {"a", "b", "c"};
}

std::vector<double> features(ModelForm form, double pixels, double n) {
  const double tree_levels = std::log2(std::max(n, 1.0));
  switch (form) {
    case ModelForm::ZBuffer:
      return {1.0, pixels, n};
    case ModelForm::Tracer:
      return {1.0, pixels, pixels * tree_levels};
    case ModelForm::Hybrid:
      return {1.0, pixels, n, pixels * tree_levels};
  }
  return {};
}

double predict(ModelForm form, const std::vector<double>& coefficients, double pixels, double n) {
  std::vector<double> x = features(form, pixels, n);
  double t = 0;
  for (size_t i = 0; i < x.size() && i < coefficients.size(); ++i) t += x[i] * coefficients[i];
  return t;
}

}  // namespace rvr::study
