// The cost models' features (see cost_model.h).
#include "rvr/study/cost_model.h"

#include <algorithm>
#include <cmath>

#include "rvr/study/study_markdown.h"

namespace rvr::study {
namespace {

const char* textbook_formula(ModelForm form) {
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

}  // namespace

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

std::string formula(const CostModel& model) {
  std::string text = textbook_formula(model.form);
  if (model.depth && model.form == ModelForm::ZBuffer) text += " + d·P·D";
  if (model.depth && model.form == ModelForm::Hybrid) text += " + g·P·D";
  if (model.edges) text += " + e·√(P·N)";
  if (model.knee > 0) {
    std::string knee = format_number(model.knee);
    if (model.flatter)
      text += model.form == ModelForm::Tracer ? " + f·P·min(log2 N, log2 " + knee + ")"
                                              : " + f·min(N, " + knee + ")";
    else
      text += model.form == ModelForm::Tracer ? " + f·P·max(0, log2(N / " + knee + "))"
                                              : " + f·max(0, N − " + knee + ")";
  }
  return text;
}

std::vector<std::string> coefficient_names(const CostModel& model) {
  std::vector<std::string> names = {"a", "b", "c"};
  if (model.form == ModelForm::Hybrid) names.push_back("d");
  if (model.depth && model.form != ModelForm::Tracer)
    names.push_back(model.form == ModelForm::ZBuffer ? "d" : "g");
  if (model.edges) names.push_back("e");
  if (model.knee > 0) names.push_back("f");
  return names;
}

std::vector<double> features(const CostModel& model, double pixels, double n) {
  const double tree_levels = std::log2(std::max(n, 1.0));
  std::vector<double> x;
  switch (model.form) {
    case ModelForm::ZBuffer:
      x = {1.0, pixels, n};
      break;
    case ModelForm::Tracer:
      x = {1.0, pixels, pixels * tree_levels};
      break;
    case ModelForm::Hybrid:
      x = {1.0, pixels, n, pixels * tree_levels};
      break;
  }
  if (model.depth && model.form != ModelForm::Tracer) x.push_back(pixels * n);
  if (model.edges) x.push_back(std::sqrt(pixels * n));
  if (model.knee > 0 && model.flatter) {
    x.push_back(model.form == ModelForm::Tracer
                    ? pixels * std::min(tree_levels, std::log2(model.knee))
                    : std::min(n, model.knee));
  } else if (model.knee > 0) {
    x.push_back(model.form == ModelForm::Tracer
                    ? pixels * std::max(0.0, std::log2(std::max(n, 1.0) / model.knee))
                    : std::max(0.0, n - model.knee));
  }
  return x;
}

double predict(const CostModel& model, const std::vector<double>& coefficients, double pixels,
               double n) {
  std::vector<double> x = features(model, pixels, n);
  double t = 0;
  for (size_t i = 0; i < x.size() && i < coefficients.size(); ++i) t += x[i] * coefficients[i];
  return t;
}

}  // namespace rvr::study
