// What a session of the study holds in memory at one point, estimated before the sweep goes
// past the N the estimate is made from, and which of a family's planned N fit in the memory.
//
// A session process holds the family's reference point and one point at a time: the point's
// scene, then every renderer prepared for it (the tracers' and the hybrids' BVH, built over
// scratch memory that is freed afterwards) and each renderer's frames (softraster sets up every
// triangle of the scene in each frame). Each of these grows about linearly with N, so the
// estimate is a straight line per part, through the same parts measured in fresh processes at
// two small N of the family (memory_probe_ns), composed in the order a session takes them.
// Planned N whose estimate is above kMemoryUsableShare of the memory available then are dropped
// from the sweep, with a note, rather than run out of memory mid-sweep. (Up to the probes' N,
// a session holds no more than the probe did: the sweep starts at once and the check is made
// before its first larger point, so a study of small N or a short budget pays nothing for it.)
#pragma once

#include <stddef.h>

#include <functional>
#include <string>
#include <vector>

#include "rvr/core/expected.h"
#include "rvr/core/renderer.h"
#include "rvr/study/sweep_plan.h"

namespace rvr::study {

// A session's resident memory at one point, measured in a fresh process that does what a
// session does: the family's reference point prepared first, the pixel sweep's narrower widths
// prepared, rendered and released (at the family's smallest N), the planned N below the point
// prepared, rendered and released (the first session goes up in N), then the point's scene
// built, each renderer prepared and its first frame rendered (in the study's order of
// renderers), then one more frame of each renderer with all of them prepared. Bytes.
struct MemoryProbe {
  double n = 0;  // the point's scene N
  // Resident before its scene: the program, its libraries, the reference point, the pixel
  // sweep's frame blocks the frame-memory pool keeps (pixel_memory.h), and what the point before
  // left resident.
  double baseline_bytes = 0;
  double scene_bytes = 0;       // resident growth while the scene was built
  double scene_peak_bytes = 0;  // the most resident while it was built, above the baseline
  // Per renderer: the growth over its preparation and first frame (what it keeps: its BVH and
  // triangles) and the most resident during them above what was resident before them (the BVH
  // build's scratch, the first frame's); and, with every renderer prepared, the most resident
  // during one more of its frames above what was resident once all were prepared.
  std::vector<double> retained_bytes, prepare_peak_bytes, frame_peak_bytes;
  // The process's peak resident memory over all of it, as measured (composed_peak gives it
  // back from the parts, to the drift of resident memory between them).
  double peak_bytes = 0;
  // Whether the peak could be reset before each part (/proc/self/clear_refs): when it could
  // not, each part's peak is the process's so far, and the estimate is an upper bound.
  bool peak_reset = true;
};

// bytes = fixed + per_n · N.
struct LinearBytes {
  double fixed = 0, per_n = 0;
  double at(double n) const { return fixed + per_n * n; }
};

// A session's memory at any N of a family: each part of MemoryProbe as a line in N.
struct MemoryModel {
  LinearBytes baseline, scene, scene_peak;
  std::vector<LinearBytes> retained, prepare_peak, frame_peak;  // per renderer
};

// The lines through the probes' parts (least squares; two probes: the line through them), but
// for the baseline, held at its largest (it does not grow with N: see the source). Each line is
// made non-decreasing (a part that shrank between probes is held at its largest). The probes
// in increasing N, at least one, each with one entry per renderer.
MemoryModel fit_memory_model(const std::vector<MemoryProbe>& probes);

// The session's peak resident memory at N: baseline plus the largest of the scene's peak while
// it is built and the scene plus the largest of, for each renderer k, what the renderers before
// it retain plus k's preparation peak, and what all retain plus any renderer's frame peak.
// Through two probes it gives each probe's composed_peak back.
double estimate_peak(const MemoryModel& model, double n);
// The same sum over a probe's measured parts.
double composed_peak(const MemoryProbe& probe);

// What a session may hold: this share of the memory available (MemAvailable) when the study
// starts. The rest covers the estimate's error (see kMemoryProbeMaxN) and what other processes
// allocate meanwhile.
constexpr double kMemoryUsableShare = 0.8;

// The largest N the probes are taken at. Both probes must hold enough triangles for what
// grows with N to outweigh what does not, and the smaller one must sit well below the larger:
// softraster's buffers stop growing at a chunk of 262,144 triangles, and between neighbouring
// N the BVH's bytes per triangle vary by ±10% with its vectors' capacities. Probes at 10^5 and
// 10^6 (a few seconds on two cores) give the peaks measured at 3×10^6 and 10^7 within 6%, below
// them (tests/test_study_plan.cpp holds them to 10%).
constexpr size_t kMemoryProbeMaxN = 1'000'000;

// The N a family's memory is probed at: the largest planned N (full width) up to
// kMemoryProbeMaxN, and the largest planned N up to about a tenth of it (or the smallest).
std::vector<size_t> memory_probe_ns(const Family& family);

// Measures a MemoryProbe of builtin:<family>:<n> (or n copies of its file) at width × width·3/4,
// `renderers` prepared in `mode`, in this process, whose resident memory so far is the
// baseline: meant for a fresh process (rvr study-worker's "memory" request). It fixes malloc's
// mmap threshold for the rest of the process (see the source) and resets its peak resident
// memory (VmHWM, and so the ru_maxrss its parent sees) before each part.
Expected<MemoryProbe> probe_memory_here(const std::vector<std::string>& renderers, RenderMode mode,
                                        const Family& family, size_t n, int width);

// A MemoryProbe taken in a fresh process (the CLI), or elsewhere (tests).
using ProbeMemory = std::function<Expected<MemoryProbe>(const Family& family, size_t n, int width)>;

// The estimate at one planned N, in bytes.
struct PointMemory {
  double n = 0;
  double peak_bytes = 0;                 // estimate_peak
  double scene_bytes = 0;                // the scene's part of it
  std::vector<double> renderer_bytes;    // each renderer's retained part
  std::vector<double> build_peak_bytes;  // each renderer's preparation peak above what was there
  bool fits = true;                      // peak_bytes within the usable memory
};

// One family's memory: its probes, the model, and its planned N checked against the memory.
struct FamilyMemory {
  std::string scene;
  std::vector<std::string> renderers;  // the study's, in order
  std::vector<MemoryProbe> probes;
  MemoryModel model;
  double available_bytes = 0;       // MemAvailable when the study started
  double usable_bytes = 0;          // kMemoryUsableShare of it
  std::vector<PointMemory> points;  // each planned N at the full width, in increasing order
  size_t max_n = 0;                 // the largest planned N that fits (0: none does)
  std::vector<size_t> dropped;      // planned N above max_n
};

// Probes the family at memory_probe_ns, fits the model and checks every planned N at the full
// width against kMemoryUsableShare of `available_bytes`. A probe's error is returned as it is.
Expected<FamilyMemory> check_family_memory(const Family& family,
                                           const std::vector<std::string>& renderers, int width,
                                           const ProbeMemory& probe, double available_bytes);

// The note a family gets when planned N were dropped ("" when none was): which, and why.
std::string memory_note(const FamilyMemory& m);

// One sentence of the estimate for study.md: the largest planned N's estimate and its parts.
std::string memory_sentence(const FamilyMemory& m);

// MemAvailable from /proc/meminfo, in bytes; 0 when it cannot be read.
double available_memory_bytes();

// A probe as JSON text and back (the worker's reply; study.json's "memory").
std::string memory_probe_json(const MemoryProbe& p);
Expected<MemoryProbe> parse_memory_probe(const std::string& json_text);

// "1.5 GiB", "310 MiB", "under 1 MiB".
std::string format_bytes(double bytes);

}  // namespace rvr::study
