// A session's memory estimated from probes at small N (see memory_estimate.h).
#include "rvr/study/memory_estimate.h"

#include <fmt/format.h>
#include <malloc.h>

#include <algorithm>
#include <cstdio>
#include <fstream>
#include <initializer_list>
#include <memory>
#include <nlohmann/json.hpp>
#include <string>
#include <tuple>
#include <utility>

#include "rvr/core/check.h"
#include "rvr/core/scene.h"
#include "rvr/renderers/prepared_renderer.h"
#include "rvr/renderers/registry.h"
#include "rvr/study/renderer_frames.h"
#include "rvr/study/run_study.h"
#include "rvr/study/study_markdown.h"

namespace rvr::study {
namespace {

using nlohmann::json;

// The line through (x_i, y_i) by least squares (the constant through one point), made
// non-decreasing: a part that measured smaller at the larger N is held at its largest value.
LinearBytes fit_line(const std::vector<double>& x, const std::vector<double>& y) {
  RVR_CHECK(!x.empty() && x.size() == y.size(), "one value per probe: ", x.size(), " N, ", y.size(),
            " values");
  const double n = double(x.size());
  double sx = 0, sy = 0;
  for (size_t i = 0; i < x.size(); ++i) sx += x[i], sy += y[i];
  const double mx = sx / n, my = sy / n;
  double sxx = 0, sxy = 0;
  for (size_t i = 0; i < x.size(); ++i) {
    sxx += (x[i] - mx) * (x[i] - mx);
    sxy += (x[i] - mx) * (y[i] - my);
  }
  if (sxx <= 0 || sxy <= 0) return {*std::max_element(y.begin(), y.end()), 0.0};
  const double slope = sxy / sxx;
  return {my - slope * mx, slope};
}

// The composition estimate_peak describes, over one set of parts.
double compose(double baseline, double scene, double scene_peak,
               const std::vector<double>& retained, const std::vector<double>& prepare_peak,
               const std::vector<double>& frame_peak) {
  double held = 0, most = 0;
  for (size_t k = 0; k < retained.size(); ++k) {
    most = std::max(most, held + prepare_peak[k]);
    held += retained[k];
  }
  for (double f : frame_peak) most = std::max(most, held + f);
  return baseline + std::max(scene_peak, scene + most);
}

// This process's resident memory and its peak (VmRSS, VmHWM of /proc/self/status), in bytes.
struct Resident {
  double now = 0, peak = 0;
};

Resident read_resident() {
  std::ifstream in("/proc/self/status");
  Resident r;
  std::string line;
  while (std::getline(in, line)) {
    double kib = 0;
    if (std::sscanf(line.c_str(), "VmRSS: %lf kB", &kib) == 1) r.now = kib * 1024;
    if (std::sscanf(line.c_str(), "VmHWM: %lf kB", &kib) == 1) r.peak = kib * 1024;
  }
  return r;
}

// Sets the peak resident memory back to what is resident now (Linux ≥ 4.0); false when the
// kernel does not allow it.
bool reset_peak() {
  std::ofstream out("/proc/self/clear_refs");
  out << "5";
  out.flush();
  return bool(out);
}

// One part of a probe: the resident memory before it, and after it with its peak.
class Part {
 public:
  explicit Part(bool& reset_ok) {
    reset_ok = reset_peak() && reset_ok;
    before_ = read_resident();
  }
  double before() const { return before_.now; }
  // (growth, peak above `base`) since the part began; `most` keeps the largest peak seen.
  std::pair<double, double> end(double base, double& most) const {
    const Resident after = read_resident();
    const double peak = std::max(after.peak, after.now);
    most = std::max(most, peak);
    return {after.now - before_.now, peak - base};
  }

 private:
  Resident before_;
};

json probe_to_json(const MemoryProbe& p) {
  return {{"n", p.n},
          {"baseline_bytes", p.baseline_bytes},
          {"scene_bytes", p.scene_bytes},
          {"scene_peak_bytes", p.scene_peak_bytes},
          {"retained_bytes", p.retained_bytes},
          {"prepare_peak_bytes", p.prepare_peak_bytes},
          {"frame_peak_bytes", p.frame_peak_bytes},
          {"peak_bytes", p.peak_bytes},
          {"peak_reset", p.peak_reset}};
}

}  // namespace

MemoryModel fit_memory_model(const std::vector<MemoryProbe>& probes) {
  RVR_CHECK(!probes.empty(), "a memory model needs at least one probe");
  const size_t renderers = probes[0].retained_bytes.size();
  std::vector<double> x;
  x.reserve(probes.size());
  for (const MemoryProbe& p : probes) {
    RVR_CHECK(p.retained_bytes.size() == renderers && p.prepare_peak_bytes.size() == renderers &&
                  p.frame_peak_bytes.size() == renderers,
              "every probe has one part per renderer: ", renderers);
    x.push_back(p.n);
  }
  auto line = [&](auto part) {
    std::vector<double> y;
    y.reserve(probes.size());
    for (const MemoryProbe& p : probes) y.push_back(part(p));
    return fit_line(x, y);
  };
  MemoryModel m;
  // The baseline does not grow with N: what the point before leaves resident is what malloc
  // keeps of blocks under its mmap threshold (32 MiB at most each); larger ones go back to the
  // system. Its largest probe's value.
  for (const MemoryProbe& p : probes)
    m.baseline.fixed = std::max(m.baseline.fixed, p.baseline_bytes);
  m.scene = line([](const MemoryProbe& p) { return p.scene_bytes; });
  m.scene_peak = line([](const MemoryProbe& p) { return p.scene_peak_bytes; });
  for (size_t k = 0; k < renderers; ++k) {
    m.retained.push_back(line([k](const MemoryProbe& p) { return p.retained_bytes[k]; }));
    m.prepare_peak.push_back(line([k](const MemoryProbe& p) { return p.prepare_peak_bytes[k]; }));
    m.frame_peak.push_back(line([k](const MemoryProbe& p) { return p.frame_peak_bytes[k]; }));
  }
  return m;
}

double estimate_peak(const MemoryModel& m, double n) {
  std::vector<double> retained, prepare_peak, frame_peak;
  for (size_t k = 0; k < m.retained.size(); ++k) {
    retained.push_back(m.retained[k].at(n));
    prepare_peak.push_back(m.prepare_peak[k].at(n));
    frame_peak.push_back(m.frame_peak[k].at(n));
  }
  return compose(m.baseline.at(n), m.scene.at(n), m.scene_peak.at(n), retained, prepare_peak,
                 frame_peak);
}

double composed_peak(const MemoryProbe& p) {
  return compose(p.baseline_bytes, p.scene_bytes, p.scene_peak_bytes, p.retained_bytes,
                 p.prepare_peak_bytes, p.frame_peak_bytes);
}

std::vector<size_t> memory_probe_ns(const Family& family) {
  Family all = family;
  all.max_n = 0;
  const std::vector<size_t> ns = sweep_ns(all);
  RVR_CHECK(!ns.empty(), "a family plans at least one N");
  size_t high = ns.front();
  for (size_t n : ns)
    if (n <= kMemoryProbeMaxN) high = n;
  size_t low = ns.front();
  for (size_t n : ns)  // a tenth, give or take the grid's rounding
    if (double(n) <= 0.101 * double(high)) low = n;
  if (low == high) return {high};
  return {low, high};
}

Expected<MemoryProbe> probe_memory_here(const std::vector<std::string>& renderers, RenderMode mode,
                                        const Family& family, size_t n, int width) {
  std::vector<RendererChoice> choices;
  for (const std::string& name : renderers) {
    RVR_TRY_ASSIGN(c, find_renderer_choice(name));
    choices.push_back(*c);
  }
  // Every block of 1 MiB or more mapped on its own and unmapped when freed, as glibc does by
  // itself for blocks over 32 MiB: what one renderer's preparation frees (the BVH build's
  // scratch) is then not held for the next, at the probes' small N as at the sweep's large N,
  // so that the parts grow with N alike at both.
  mallopt(M_MMAP_THRESHOLD, 1 << 20);
  // What every session holds beside its point.
  RVR_TRY_ASSIGN(reference, prepare_frames(renderers, mode, family, family.low, width));
  // What the pixel sweep leaves: the frame-memory pool (pixel_memory.h) keeps its narrower frames'
  // blocks, which no full-size frame takes again. A session's first measures those points before
  // its larger N; a later one takes them in random order among the others. Their blocks are the
  // same at every N, so they are made at the family's smallest.
  for (int narrower : pixel_sweep_widths(width)) {
    RVR_TRY_ASSIGN(swept, prepare_frames(renderers, mode, family, family.low, narrower));
    for (size_t k = 0; k < renderers.size(); ++k)
      if (Expected<FrameTime> t = (*swept)->time_frame(k); !t) return t.error();
  }
  // What a session leaves behind from the point it measured before (the planned N below: the
  // first session goes up in N), still resident when the next is prepared.
  Family all = family;
  all.max_n = 0;
  size_t before = 0;
  for (size_t planned : sweep_ns(all))
    if (planned < n && planned > family.low) before = planned;
  if (before > 0) {
    RVR_TRY_ASSIGN(earlier, prepare_frames(renderers, mode, family, before, width));
    for (size_t k = 0; k < renderers.size(); ++k)
      if (Expected<FrameTime> t = (*earlier)->time_frame(k); !t) return t.error();
  }
  // What the points before freed goes back to the system, as a session's worker returns it when
  // it releases a point (malloc_trim), so that what they leave is the frame-memory pool's blocks.
  malloc_trim(0);
  MemoryProbe p;
  p.n = double(n);
  bool reset_ok = true;
  std::unique_ptr<Scene> scene;
  {
    Part part(reset_ok);
    p.baseline_bytes = part.before();
    RVR_TRY_ASSIGN(built, family_scene(family, n, width));
    scene = std::make_unique<Scene>(std::move(*built));
    std::tie(p.scene_bytes, p.scene_peak_bytes) = part.end(p.baseline_bytes, p.peak_bytes);
  }
  RenderOptions options;
  options.mode = mode;
  std::vector<std::unique_ptr<PreparedRenderer>> prepared;
  for (const RendererChoice& choice : choices) {
    Part part(reset_ok);
    RVR_TRY_ASSIGN(r, prepare_renderer(choice, *scene, {}, options));
    if (Expected<RenderOutput> first = (*r)->render(); !first) return first.error();
    prepared.push_back(std::move(*r));
    auto [grown, peak] = part.end(part.before(), p.peak_bytes);
    p.retained_bytes.push_back(grown);
    p.prepare_peak_bytes.push_back(peak);
  }
  const double all_prepared = read_resident().now;
  for (std::unique_ptr<PreparedRenderer>& r : prepared) {
    Part part(reset_ok);
    if (Expected<RenderOutput> frame = r->render(); !frame) return frame.error();
    p.frame_peak_bytes.push_back(part.end(all_prepared, p.peak_bytes).second);
  }
  p.peak_reset = reset_ok;
  return p;
}

Expected<FamilyMemory> check_family_memory(const Family& family,
                                           const std::vector<std::string>& renderers, int width,
                                           const ProbeMemory& probe, double available_bytes) {
  FamilyMemory m;
  m.scene = family.name;
  m.renderers = renderers;
  for (size_t n : memory_probe_ns(family)) {
    RVR_TRY_ASSIGN(p, probe(family, n, width));
    if (p->retained_bytes.size() != renderers.size())
      return internal_error(fmt::format("study: a memory probe of {} measured {} renderers, not {}",
                                        family.name, p->retained_bytes.size(), renderers.size()));
    m.probes.push_back(*p);
  }
  m.model = fit_memory_model(m.probes);
  m.available_bytes = available_bytes;
  m.usable_bytes = kMemoryUsableShare * available_bytes;
  Family all = family;
  all.max_n = 0;
  bool fitting = true;  // every N so far fits: the estimate grows with N
  for (size_t n : sweep_ns(all)) {
    PointMemory point;
    point.n = double(n);
    point.peak_bytes = estimate_peak(m.model, point.n);
    point.scene_bytes = m.model.scene.at(point.n);
    for (size_t k = 0; k < renderers.size(); ++k) {
      point.renderer_bytes.push_back(m.model.retained[k].at(point.n));
      point.build_peak_bytes.push_back(m.model.prepare_peak[k].at(point.n));
    }
    point.fits = available_bytes <= 0 || point.peak_bytes <= m.usable_bytes;
    fitting = fitting && point.fits;
    if (fitting)
      m.max_n = n;
    else
      m.dropped.push_back(n);
    m.points.push_back(point);
  }
  return m;
}

std::string memory_note(const FamilyMemory& m) {
  if (m.dropped.empty()) return "";
  const PointMemory* first = nullptr;
  for (const PointMemory& p : m.points)
    if (double(m.dropped.front()) == p.n) first = &p;
  RVR_CHECK(first != nullptr, "a dropped N is a planned one");
  std::string ns;
  for (size_t n : m.dropped) ns += (ns.empty() ? "" : ", ") + format_number(double(n));
  return fmt::format(
      "{}: N = {} dropped from the plan: a session would need about {} at {} (estimated from "
      "preparations at N = {}), more than the {} a session may take ({:.0f}% of the {} "
      "available when the study started)",
      m.scene, ns, format_bytes(first->peak_bytes), format_number(first->n),
      [&] {
        std::string at;
        for (const MemoryProbe& p : m.probes)
          at += (at.empty() ? "" : " and ") + format_number(p.n);
        return at;
      }(),
      format_bytes(m.usable_bytes), 100 * kMemoryUsableShare, format_bytes(m.available_bytes));
}

std::string memory_sentence(const FamilyMemory& m) {
  if (m.points.empty()) return "";
  const PointMemory* top = &m.points.back();
  for (const PointMemory& p : m.points)
    if (p.fits) top = &p;
  std::string parts = fmt::format("the scene {}", format_bytes(top->scene_bytes));
  for (size_t k = 0; k < m.renderers.size(); ++k)
    parts +=
        fmt::format(", {} {} (preparing: up to {} more than was held before it)", m.renderers[k],
                    format_bytes(top->renderer_bytes[k]), format_bytes(top->build_peak_bytes[k]));
  std::string probes;
  for (const MemoryProbe& p : m.probes)
    probes += fmt::format("{}{} at N = {}", probes.empty() ? "" : ", ", format_bytes(p.peak_bytes),
                          format_number(p.n));
  return fmt::format(
      "{}: a session is estimated to peak at {} at N = {}, the largest N kept ({}, over a "
      "process and its reference point of {}), from preparations measured in fresh processes "
      "({}); {} available, {:.0f}% of it usable.",
      m.scene, format_bytes(top->peak_bytes), format_number(top->n), parts,
      format_bytes(m.model.baseline.at(top->n)), probes, format_bytes(m.available_bytes),
      100 * kMemoryUsableShare);
}

double available_memory_bytes() {
  std::ifstream in("/proc/meminfo");
  std::string line;
  while (std::getline(in, line)) {
    double kib = 0;
    if (std::sscanf(line.c_str(), "MemAvailable: %lf kB", &kib) == 1) return kib * 1024;
  }
  return 0;
}

std::string memory_probe_json(const MemoryProbe& p) {
  return probe_to_json(p).dump();
}

Expected<MemoryProbe> parse_memory_probe(const std::string& text) {
  json j = json::parse(text, nullptr, false);
  try {
    MemoryProbe p;
    p.n = j.at("n").get<double>();
    p.baseline_bytes = j.at("baseline_bytes").get<double>();
    p.scene_bytes = j.at("scene_bytes").get<double>();
    p.scene_peak_bytes = j.at("scene_peak_bytes").get<double>();
    p.retained_bytes = j.at("retained_bytes").get<std::vector<double>>();
    p.prepare_peak_bytes = j.at("prepare_peak_bytes").get<std::vector<double>>();
    p.frame_peak_bytes = j.at("frame_peak_bytes").get<std::vector<double>>();
    p.peak_bytes = j.at("peak_bytes").get<double>();
    p.peak_reset = j.at("peak_reset").get<bool>();
    return p;
  } catch (const json::exception& e) {
    return internal_error(std::string("study: a memory probe that is not one: ") + e.what());
  }
}

std::string format_bytes(double bytes) {
  const double mib = bytes / double(1 << 20);
  if (mib >= 1024) return fmt::format("{:.1f} GiB", mib / 1024);
  if (mib < 0.5) return "under 1 MiB";
  return fmt::format("{:.0f} MiB", mib);
}

}  // namespace rvr::study
