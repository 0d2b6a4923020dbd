// How far long work has got, for whoever wants to show it (the command line draws a bar on a
// terminal). Renderers report through RenderOptions::progress; the library never prints.
//
//   if (ProgressSink* p = options.progress) p->begin("trace", pixels, "pixels", "rays");
//   ... per finished tile or chunk (never per ray):
//   if (ProgressSink* p = options.progress) p->advance(tile_pixels, tile_rays);
//
// The sink also carries a request to stop: cancel() from any thread; a renderer looks at
// cancelled() where it advances (one relaxed load per tile or chunk), skips the work left and
// returns cancelled_error() instead of a partial image.
//
//   if (is_cancelled(options.progress)) return;  // in the tile loop: the tiles left are skipped
#pragma once

#include <atomic>
#include <chrono>
#include <cstdint>
#include <mutex>
#include <string>

namespace rvr {

// A consistent copy of the current phase, for drawing.
struct ProgressSnapshot {
  std::string phase;      // e.g. "build", "trace", "setup", "raster", "shade"
  std::string unit;       // what `done` and `total` count, e.g. "pixels", "triangles"
  std::string rate_unit;  // what `rate_done` counts, e.g. "rays"; the unit when none was given
  uint64_t total = 0;     // 0: unknown (only the phase and its time are known)
  uint64_t done = 0;
  uint64_t rate_done = 0;
  double seconds = 0;  // since the phase began
};

// Thread-safe: begin() from the renderer's own thread between phases; advance() from any worker
// thread (two relaxed atomic adds); snapshot() from a drawing thread.
class ProgressSink {
 public:
  ProgressSink() = default;
  ProgressSink(const ProgressSink&) = delete;
  ProgressSink& operator=(const ProgressSink&) = delete;

  // Starts a phase of `total` units of `unit`. `rate_unit`, when not empty, names a second
  // count reported alongside for the speed (the fraction is in pixels, the speed in rays,
  // whose total is not known in advance).
  void begin(std::string phase, uint64_t total = 0, std::string unit = "",
             std::string rate_unit = "");
  // `units` more of the phase's total are done, and `rate_units` more of its rate unit.
  void advance(uint64_t units, uint64_t rate_units = 0) noexcept {
    done_.fetch_add(units, std::memory_order_relaxed);
    if (rate_units) rate_done_.fetch_add(rate_units, std::memory_order_relaxed);
  }
  ProgressSnapshot snapshot() const;

  // Asks the work reporting here to stop as soon as it next looks; never undone (begin() keeps
  // it). Relaxed: the flag orders nothing else, the renderer's own joins publish its results.
  void cancel() noexcept { cancelled_.store(true, std::memory_order_relaxed); }
  bool cancelled() const noexcept { return cancelled_.load(std::memory_order_relaxed); }

 private:
  mutable std::mutex mutex_;  // guards the strings and the start time, never taken by advance
  std::string phase_, unit_, rate_unit_;
  std::chrono::steady_clock::time_point start_ = std::chrono::steady_clock::now();
  std::atomic<uint64_t> total_{0}, done_{0}, rate_done_{0};
  std::atomic<bool> cancelled_{false};
};

// True when `sink` (may be null: nobody watching, nobody can cancel) was asked to stop.
inline bool is_cancelled(const ProgressSink* sink) noexcept {
  return sink && sink->cancelled();
}

}  // namespace rvr
