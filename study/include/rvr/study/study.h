// A study: what was swept, every measurement, the fitted models and the conclusions computed
// from them. Written as study.json (rvr-study/1, study_json.h) and study.md (study_markdown.h).
#pragma once

#include <map>
#include <string>
#include <vector>

#include "rvr/study/crossover.h"
#include "rvr/study/fit.h"
#include "rvr/study/measurement.h"

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
  std::vector<std::string> notes;  // what the budget cut short, and the like
  bool interrupted = false;        // the sweep was stopped (Ctrl-C) before its end
};

}  // namespace rvr::study
