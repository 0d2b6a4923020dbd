#include "terminal_progress.h"

#include <fmt/format.h>
#include <sys/ioctl.h>

#include <algorithm>
#include <atomic>
#include <cerrno>
#include <cmath>
#include <compare>
#include <cstdlib>
#include <cstring>

namespace rvr {
namespace {

constexpr int kBarWidth = 20;
constexpr auto kRedraw = std::chrono::milliseconds(100);
constexpr char kErase[] = "\r\x1b[K";  // to column 0, clear to the end of the line

// The one line on a terminal belongs to one TerminalProgress at a time.
std::atomic<TerminalProgress*> g_active{nullptr};
std::atomic<bool> g_on_screen{false};
static_assert(std::atomic<bool>::is_always_lock_free, "read from a signal handler");

void write_all(int fd, const std::string& s) {
  size_t off = 0;
  while (off < s.size()) {
    ssize_t n = ::write(fd, s.data() + off, s.size() - off);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) return;  // a closed terminal: progress is not worth failing for
    off += size_t(n);
  }
}

int terminal_columns(int fd) {
  winsize ws{};
  if (::ioctl(fd, TIOCGWINSZ, &ws) == 0 && ws.ws_col > 0) return ws.ws_col;
  return 80;
}

}  // namespace

bool progress_wanted(bool quiet, int fd) {
  if (quiet || !::isatty(fd)) return false;
  const char* term = std::getenv("TERM");
  return !(term && std::strcmp(term, "dumb") == 0);  // dumb terminals cannot erase a line
}

std::string format_count(double v) {
  if (!(v >= 0)) v = 0;
  if (v < 1e3) return fmt::format("{:.0f}", v);
  if (v < 1e6) return fmt::format("{:.1f}k", v / 1e3);
  if (v < 1e9) return fmt::format("{:.2f}M", v / 1e6);
  return fmt::format("{:.2f}G", v / 1e9);
}

std::string format_duration(double seconds) {
  long s = std::isfinite(seconds) ? long(std::ceil(std::max(0.0, seconds))) : 0;
  if (s < 60) return fmt::format("{}s", s);
  if (s < 3600) return fmt::format("{}m{:02}s", s / 60, s % 60);
  return fmt::format("{}h{:02}m", s / 3600, (s % 3600) / 60);
}

std::string format_progress_line(const std::string& label, const ProgressSnapshot& s, int columns) {
  std::string head = label.empty() ? s.phase : label + "  " + s.phase;
  std::string rate;
  if (s.rate_done > 0 && s.seconds > 0 && !s.rate_unit.empty())
    rate = "  " + format_count(double(s.rate_done) / s.seconds) + " " + s.rate_unit + "/s";
  std::string line, bar;
  if (s.total == 0) {
    line = fmt::format("{}  {:.1f}s{}", head, s.seconds, rate);
  } else {
    const double fraction = std::min(1.0, double(s.done) / double(s.total));
    const int filled = int(fraction * kBarWidth);
    bar = " [" + std::string(size_t(filled), '#') + std::string(size_t(kBarWidth - filled), '.') +
          "]";
    // Time left in this phase at its average speed so far.
    std::string eta = "--";
    if (s.done >= s.total)
      eta = "0s";
    else if (s.done > 0 && s.seconds > 0)
      eta = format_duration(s.seconds * double(s.total - s.done) / double(s.done));
    const std::string percent = fmt::format("  {:3d}%", int(fraction * 100.0));
    line = head + percent + bar + rate + "  ETA " + eta;
    if (int(line.size()) >= columns) line = head + percent + rate + "  ETA " + eta;
  }
  if (columns > 1 && int(line.size()) >= columns) line.resize(size_t(columns - 1));
  return line;
}

TerminalProgress::TerminalProgress(bool enabled, int fd, std::chrono::milliseconds delay)
    : enabled_(enabled), fd_(fd), delay_(delay), start_(std::chrono::steady_clock::now()) {
  if (!enabled_) return;
  thread_ = std::thread([this] { run(); });
  g_active.store(this);
}

TerminalProgress::~TerminalProgress() {
  stop();
  TerminalProgress* self = this;
  g_active.compare_exchange_strong(self, nullptr);
}

void TerminalProgress::begin(const std::string& label, const std::string& phase) {
  if (!enabled_) return;
  std::lock_guard lock(mutex_);
  label_ = label;
  sink_.begin(phase);
}

void TerminalProgress::stop() {
  if (!enabled_) return;
  {
    std::lock_guard lock(mutex_);
    stopping_ = true;
  }
  wake_.notify_all();
  if (thread_.joinable()) thread_.join();
  std::lock_guard lock(mutex_);
  if (drawn_) {
    write_all(fd_, kErase);
    drawn_ = false;
    g_on_screen.store(false);
  }
}

void TerminalProgress::run() {
  std::unique_lock lock(mutex_);
  while (!stopping_) {
    wake_.wait_for(lock, kRedraw);
    if (stopping_) break;
    if (std::chrono::steady_clock::now() - start_ < delay_) continue;  // short work: nothing
    draw_locked();
  }
}

void TerminalProgress::draw_locked() {
  const std::string line = format_progress_line(label_, sink_.snapshot(), terminal_columns(fd_));
  drawn_ = true;
  g_on_screen.store(true);  // before the write: a signal during it still erases
  write_all(fd_, "\r" + line + "\x1b[K");
}

void stop_active_progress() {
  if (TerminalProgress* p = g_active.load()) p->stop();
}

bool progress_line_on_screen() noexcept {
  return g_on_screen.load();
}

}  // namespace rvr
