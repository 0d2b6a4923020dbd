// Studies of one sweep measured apart (shards of it, or runs on several machines) brought
// together: the studies of one machine type and mode are pooled (their points united) and
// concluded again; those of different machine types are never pooled, each is concluded apart
// and their conclusions are set side by side.
#pragma once

#include <string>
#include <vector>

#include "rvr/core/expected.h"
#include "rvr/study/study.h"

namespace rvr::study {

// A study read back (load_study_json) and where it came from, for notes and errors.
struct StudySource {
  std::string name;  // "shard-3" (its folder)
  StudyResult study;
};

// The studies of one machine type (machine.cpu, threads and kernels) and mode, pooled.
struct MachineGroup {
  std::string label;  // "AMD EPYC 7763, 2 threads, kernels avx512 (...), local mode"
  std::string slug;   // "amd-epyc-7763-2t-avx512-local": a folder name, unique among the groups
  std::vector<std::string> sources;
  StudyResult study;  // concluded
};

// Groups the studies by machine type and mode, in the order first seen; in each, the points are
// united (a point measured by several studies, same renderer, scene, scene_n and width, keeps
// every repetition of each, or of those that measured it on a quiet machine if any did: not
// `busy`), ordered by family, N, width and renderer, and concluded with the
// first study's seed and bootstrap replicates. Renderers and families are united; budgets and
// elapsed times add up; `notes` says which studies were pooled, which shards are missing and
// each source's own notes. A BadInput error when studies pooled differ in image size, or give
// one point different axis values or pixel counts.
Expected<std::vector<MachineGroup>> merge_studies(const std::vector<StudySource>& sources);

// comparison.md: every crossover and dominance (same pair of renderers, family and axis) of the
// groups side by side, one column per machine type.
std::string comparison_markdown(const std::vector<MachineGroup>& groups);

}  // namespace rvr::study
