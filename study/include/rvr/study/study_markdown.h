// study.md: the conclusions as sentences generated from the numbers of a study.
#pragma once

#include <string>
#include <vector>

#include "rvr/study/crossover.h"
#include "rvr/study/fit.h"
#include "rvr/study/study.h"

namespace rvr::study {

// 2.1×10^6 for large and small numbers, 3 significant digits between 0.01 and 10^4.
std::string format_number(double v);

std::string study_markdown(const StudyResult& result);

// The sentences study.md lists, one each without the list marker or line end, for study.html to
// say the same: where two renderers cross, which one wins over the whole range, each model.
std::string crossover_sentence(const StudyResult& r, const Crossover& c);
std::string dominance_sentence(const StudyResult& r, const Dominance& d);
std::string model_sentence(const RendererModels& m, const std::string& scene, const ModelFit& f);
// A crossover's prediction checked after the fit: held, failed or inconclusive, and why.
std::string check_sentence(const PredictionCheck& c);

// What the study covers (families, image size, mode, static scenes, one machine type), and how
// it measured and judged: said at the top of study.md and study.html alike.
std::string scope_text(const StudyResult& r);
std::string method_text(const StudyResult& r);

// The chapter's question, per family: every z-buffer against every tracer along N, as a
// crossover, a dominance, a tie or why nothing is concluded.
std::vector<std::string> headline_sentences(const StudyResult& r);

// In full mode, per renderer, family and effect: the range of its error in the effect's mask
// against raytrace's frame over the sweep's points (Measurement::effect_errors), its worst
// point named. Empty when no point holds such errors.
std::vector<std::string> technique_error_sentences(const StudyResult& r);

// "a = 1.2 ms (95%: 0.9 – 1.5)" (ns for the per-pixel, per-triangle and per-ray terms); empty
// for a coefficient that is not identifiable.
std::string coefficient_text(const Coefficient& c);

}  // namespace rvr::study
