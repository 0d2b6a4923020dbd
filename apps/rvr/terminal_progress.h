// The command line's progress line: one line on stderr, redrawn in place while long work runs,
// erased before anything else is printed. Renderers only count (rvr/core/progress.h).
#pragma once

#include <unistd.h>

#include <chrono>
#include <condition_variable>
#include <mutex>
#include <string>
#include <thread>

#include "rvr/core/progress.h"

namespace rvr {

// Progress is drawn only on a real terminal (TERM=dumb is none) and never with --quiet.
bool progress_wanted(bool quiet, int fd = STDERR_FILENO);

// One line for a snapshot: "2/3 raytrace  trace  42% [########............]  1.23M rays/s
// ETA 3s", or "raster  render  2.1s" when the phase has no count. At most columns - 1
// characters (the bar goes first), so the terminal never wraps it and "\r" can redraw it.
std::string format_progress_line(const std::string& label, const ProgressSnapshot& s, int columns);

// "850", "12.3k", "1.23M", "4.56G": a rate, compactly.
std::string format_count(double v);
// "3s", "2m05s", "1h02m".
std::string format_duration(double seconds);

// Owns the sink renderers report to and a timer thread that redraws the line about ten times
// a second, starting only once the work has run `delay` (short work shows nothing).
class TerminalProgress {
 public:
  // Disabled: draws nothing, sink() is null and every call is a no-op.
  explicit TerminalProgress(bool enabled, int fd = STDERR_FILENO,
                            std::chrono::milliseconds delay = std::chrono::milliseconds(500));
  ~TerminalProgress();
  TerminalProgress(const TerminalProgress&) = delete;
  TerminalProgress& operator=(const TerminalProgress&) = delete;

  // For RenderOptions::progress; null when disabled, so renderers skip even the atomics.
  ProgressSink* sink() { return enabled_ ? &sink_ : nullptr; }
  // What the line starts with ("raytrace", "2/3 raytrace"), and a phase the command line
  // itself runs ("load", "render", "write"); a renderer's own phases replace the latter.
  void begin(const std::string& label, const std::string& phase);
  // Stops the timer and erases the line. Idempotent; call before printing anything else.
  void stop();

 private:
  void run();
  void draw_locked();

  const bool enabled_;
  const int fd_;
  const std::chrono::milliseconds delay_;
  const std::chrono::steady_clock::time_point start_;
  ProgressSink sink_;
  std::mutex mutex_;  // one writer on the terminal at a time; guards the fields below
  std::condition_variable wake_;
  std::string label_;
  bool stopping_ = false;
  bool drawn_ = false;  // a line is on screen and must be erased
  std::thread thread_;
};

// Erases the line of the TerminalProgress that is running, if any: for error paths that print
// from deep inside (the "error:" line must start a clean line).
void stop_active_progress();

// Whether a progress line may be on screen; async-signal-safe, for a signal handler that
// must erase it ("\r\x1b[K") before its own message.
bool progress_line_on_screen() noexcept;

}  // namespace rvr
