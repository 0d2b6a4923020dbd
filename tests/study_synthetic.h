// Synthetic measurements for the study's tests: frames whose cost comes from a known function,
// with noise at each level the study resamples (test_study.cpp, test_study_fit.cpp).
#pragma once

#include <stddef.h>

#include <cmath>
#include <functional>
#include <map>
#include <string>
#include <vector>

#include "rvr/study/bootstrap.h"
#include "rvr/study/measurement.h"
#include "rvr/study/sweep_plan.h"

namespace rvr::study::fake {

using CostFn = std::function<double(double pixels, double n)>;

// Log-normal standard deviations of the noise at each level.
struct Noise {
  double frame = 0.03;   // every frame on its own
  double round = 0.0;    // a round's frames alike, every renderer (a load that comes and goes)
  double session = 0.0;  // a run, each renderer its own (a process's memory layout)
  double point = 0.0;    // a renderer at a point, in every run (a size that suits it)
};

// One point of each renderer, `runs` runs of `rounds` rounds, sessions 0 .. runs-1.
inline std::vector<Measurement> synthetic_point(const std::vector<std::string>& renderers,
                                                const std::vector<CostFn>& costs, double pixels,
                                                double n, int runs, int rounds, const Noise& noise,
                                                Rng& rng, const std::string& scene = "synthetic") {
  std::vector<Measurement> out(renderers.size());
  std::vector<double> point(renderers.size());
  for (size_t r = 0; r < renderers.size(); ++r) {
    Measurement& m = out[r];
    m.renderer = renderers[r];
    m.scene = scene;
    m.scene_n = m.n = n;
    m.pixels = pixels;
    m.width = int(std::lround(std::sqrt(pixels * 4.0 / 3.0)));
    m.height = m.width * 3 / 4;
    point[r] = noise.point * rng.normal();
  }
  for (int s = 0; s < runs; ++s) {
    std::vector<double> session(renderers.size());
    for (double& v : session) v = noise.session * rng.normal();
    std::vector<Run> run(renderers.size());
    for (int k = 0; k < rounds; ++k) {
      const double shared = noise.round * rng.normal();
      for (size_t r = 0; r < renderers.size(); ++r)
        run[r].seconds.push_back(costs[r](pixels, n) * std::exp(point[r] + session[r] + shared +
                                                                noise.frame * rng.normal()));
    }
    for (size_t r = 0; r < renderers.size(); ++r) {
      run[r].session = s;
      run[r].order.assign(run[r].seconds.size(), int(r));
      run[r].reference_ratio = 1.0;
      out[r].runs.push_back(run[r]);
    }
  }
  return out;
}

// One renderer's point.
inline Measurement synthetic(const std::string& renderer, const CostFn& cost, double pixels,
                             double n, int rounds, double frame_noise, Rng& rng, int runs = 3) {
  Noise noise;
  noise.frame = frame_noise;
  return synthetic_point({renderer}, {cost}, pixels, n, runs, rounds, noise, rng)[0];
}

// A sweep of 13 log-spaced N from 10^2 to 10^6 at each of the pixel counts, one renderer.
inline std::vector<Measurement> sweep(const std::string& renderer, const CostFn& cost,
                                      const std::vector<double>& pixel_counts, int rounds,
                                      double frame_noise, Rng& rng) {
  std::vector<Measurement> out;
  for (double p : pixel_counts)
    for (size_t n : log_spaced(100, 1000000, 13))
      out.push_back(synthetic(renderer, cost, p, double(n), rounds, frame_noise, rng));
  return out;
}

// Two renderers' sweeps along N at `pixels`: `ns` points, sessions shared as the study does.
inline std::pair<std::vector<Measurement>, std::vector<Measurement>> sweep_pair(
    const CostFn& a, const CostFn& b, const std::vector<double>& ns, double pixels,
    const Noise& noise, Rng& rng, int runs = 3, int rounds = 5) {
  std::pair<std::vector<Measurement>, std::vector<Measurement>> out;
  for (double n : ns) {
    std::vector<Measurement> p =
        synthetic_point({"softraster", "raytrace"}, {a, b}, pixels, n, runs, rounds, noise, rng);
    out.first.push_back(p[0]);
    out.second.push_back(p[1]);
  }
  return out;
}

// The counts of one frame's work at (pixels, n), by counter name.
using CountsFn = std::function<std::map<std::string, double>(double pixels, double n)>;

// One renderer's sweep of 13 log-spaced N from 10^2 to 10^6 at each of the pixel counts, whose
// every point records counts(P, N) as its counters and whose frames cost
// u0 + Σ unit[k]·count_k seconds ("pixels" in `unit` is P), with `noise`.
inline std::vector<Measurement> counted_sweep(const std::string& renderer, const CountsFn& counts,
                                              double u0, const std::map<std::string, double>& unit,
                                              const std::vector<double>& pixel_counts,
                                              const Noise& noise, Rng& rng, int runs = 3,
                                              int rounds = 5) {
  CostFn cost = [&](double p, double n) {
    std::map<std::string, double> c = counts(p, n);
    double t = u0;
    for (const auto& [name, u] : unit) t += u * (name == "pixels" ? p : c.at(name));
    return t;
  };
  std::vector<Measurement> out;
  for (double p : pixel_counts)
    for (size_t n : log_spaced(100, 1000000, 13)) {
      Measurement m =
          synthetic_point({renderer}, {cost}, p, double(n), runs, rounds, noise, rng)[0];
      m.counters = counts(p, double(n));
      out.push_back(m);
    }
  return out;
}

}  // namespace rvr::study::fake
