// A study: what was swept, every measurement, the fitted models and the conclusions computed
// from them. Written as study.json (rvr-study/1, study_json.h) and study.md (study_markdown.h).
#pragma once

#include <map>
#include <optional>
#include <string>
#include <vector>

#include "rvr/study/crossover.h"
#include "rvr/study/fit.h"
#include "rvr/study/measurement.h"
#include "rvr/study/sweep_plan.h"

namespace rvr::study {

struct MachineInfo {
  std::string cpu;
  unsigned threads = 0;
  std::string kernels;                          // which SIMD kernels ran and why
  std::map<std::string, std::string> versions;  // rvr, embree, tbb, compiler
};

// One renderer's model, fitted separately to each scene: a sphere's triangles and a soup's do
// not cost the same.
struct RendererModels {
  std::string name;
  std::string loop_order;  // "triangle-major", "pixel-major", "hybrid"
  ModelForm form = ModelForm::ZBuffer;
  std::map<std::string, ModelFit> fits;  // by scene
};

// The log-log slope of time against an axis over one decade of it (the family's N at the full
// width), or over the whole pixel sweep at one N.
struct ScalingExponent {
  std::string renderer, scene;
  std::string axis;  // the family's ("triangles", "depth") or "pixels"
  double from = 0, to = 0;
  double exponent = 0;
  double n = 0;  // the N held fixed on the pixels axis; 0 on the others
};

// Time per triangle and per primary ray at one measured point.
struct UnitCost {
  std::string renderer, scene;
  double n = 0, seconds = 0;
  double ns_per_triangle = 0, ns_per_ray = 0;
};

// A crossover's prediction checked by new measurements after the fit: at a third of and at
// three times the crossover, the renderer the study says is faster there, and which one was.
struct PredictionCheck {
  std::string a, b, scene, axis;
  double crossover = 0;  // the crossover's value on the axis
  double at = 0;         // where the check measured: the axis value of its point
  double pixels = 0;
  std::string predicted_faster, measured_faster;
  double ratio = 0;  // the measured slower's time over the faster's
  bool holds = false;
};

// A hybrid's frame split into its z-buffer pass and its tracer's part, at one point.
struct PhaseSplit {
  std::string renderer, scene;
  double n = 0, pixels = 0;
  double zbuffer_seconds = 0, trace_seconds = 0;  // medians over the repetitions
  double zbuffer_share = 0;                       // zbuffer / (zbuffer + trace)
};

struct StudyResult {
  std::vector<std::string> scenes;          // families: "tessphere"
  std::vector<std::string> renderers;       // in the order asked for
  std::map<std::string, std::string> axes;  // scene -> "triangles" | "depth"
  int width = 0, height = 0;
  std::string mode;
  double budget_seconds = 0, elapsed_seconds = 0;
  int repetitions = 0;
  uint64_t seed = 0;
  int bootstrap_replicates = 0;
  std::string command;  // the command line, when the caller sets it
  MachineInfo machine;
  std::vector<Measurement> points;
  std::vector<RendererModels> models;
  std::vector<Crossover> crossovers;
  std::vector<Dominance> dominance;
  std::vector<ScalingExponent> scaling;
  std::vector<UnitCost> costs;
  std::vector<PhaseSplit> splits;  // the hybrids', at the smallest and largest N at full width
  std::vector<PredictionCheck> checks;
  std::vector<std::string> notes;  // what the budget cut short, and the like
  bool interrupted = false;        // the sweep was stopped (Ctrl-C) before its end
  std::optional<Shard> shard;      // the share of the planned points measured (--shard)
};

}  // namespace rvr::study
