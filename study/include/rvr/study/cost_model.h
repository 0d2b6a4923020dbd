// The cost of each loop order as a linear model in its coefficients. The textbook forms:
//   z-buffer  t = a + b·P + c·N            (setup, per pixel, per triangle)
//   tracer    t = a + P·(b + c·log2 N)     (setup, per ray, per ray and level of the tree)
//   hybrid    t = a + b·P + c·N + d·P·log2 N   (the sum of both; the two per-pixel terms are one)
// P is the pixel count (primary rays), N the swept axis (triangles). Where N is depth complexity
// D (the occluders family), the z-buffers' fragments add d·P·D (g·P·D for the hybrid, whose d
// is taken). Two extensions, added only where the data demand them (fit.h chooses by
// leave-one-out error):
//   edges  + e·√(P·N): N triangles sharing a fixed part of the screen have edges of total length
//          ∝ N·√(P/N) = √(P·N) pixels; work per edge pixel or per tile an edge crosses (the
//          z-buffer's partly covered blocks, the tracer's packets split at silhouettes)
//   knee   a change of slope at N = k, in one of two directions, each with a coefficient f ≥ 0
//          (every coefficient is a cost, fitted non-negative):
//          steeper past k: + f·max(0, N − k) (z-buffer, hybrid) or + f·P·max(0, log2(N/k))
//            (tracer): each triangle (tree level) past k costs f more, where the working set
//            leaves a cache;
//          flatter past k: + f·min(N, k) (z-buffer, hybrid) or + f·P·min(log2 N, log2 k)
//            (tracer): the first k triangles (levels) cost f more each than the ones past k,
//            where triangles become smaller than the rasterizer's blocks and cost their setup,
//            no longer their area. A negative f on the steeper term would say the same with a
//            negative cost, which the fit does not allow.
#pragma once

#include <stddef.h>

#include <string>
#include <vector>

namespace rvr::study {

enum class ModelForm { ZBuffer, Tracer, Hybrid };

struct CostModel {
  ModelForm form = ModelForm::ZBuffer;
  bool edges = false;    // the e·√(P·N) term
  double knee = 0;       // > 0: the knee term, its change of slope at N = knee
  bool flatter = false;  // the knee's slope falls past it (min(N, k)) instead of rising
  bool depth = false;    // N is depth complexity: the z-buffers' d·P·D (g for the hybrid)

  CostModel() = default;
  CostModel(ModelForm f) : form(f) {}  // NOLINT: the textbook form, implicitly
  CostModel(ModelForm f, bool with_edges, double cache_knee, bool knee_flatter = false)
      : form(f), edges(with_edges), knee(cache_knee), flatter(knee_flatter) {}
  bool extended() const { return edges || knee > 0; }
};

const char* to_string(ModelForm form);        // "zbuffer", "tracer", "hybrid"
std::string formula(const CostModel& model);  // "t = a + b·P + c·N + e·√(P·N)"

// The coefficients' names, in the order of features(): a, b, c (, d) (, e) (, f).
std::vector<std::string> coefficient_names(const CostModel& model);

// What each coefficient multiplies at (P, N): the model is the dot product with them.
std::vector<double> features(const CostModel& model, double pixels, double n);

// The coefficient multiplying P alone: it cannot be told from `a` when every point has the same
// P. Its index in coefficient_names().
constexpr size_t kPixelCoefficient = 1;

double predict(const CostModel& model, const std::vector<double>& coefficients, double pixels,
               double n);

}  // namespace rvr::study
