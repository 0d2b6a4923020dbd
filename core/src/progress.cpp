#include "rvr/core/progress.h"

#include <utility>

#include "rvr/core/timer.h"

namespace rvr {

void ProgressSink::begin(std::string phase, uint64_t total, std::string unit,
                         std::string rate_unit) {
  std::lock_guard lock(mutex_);
  phase_ = std::move(phase);
  unit_ = std::move(unit);
  rate_unit_ = std::move(rate_unit);
  start_ = std::chrono::steady_clock::now();
  done_.store(0, std::memory_order_relaxed);
  rate_done_.store(0, std::memory_order_relaxed);
  total_.store(total, std::memory_order_relaxed);
}

ProgressSnapshot ProgressSink::snapshot() const {
  ProgressSnapshot s;
  std::lock_guard lock(mutex_);
  s.phase = phase_;
  s.unit = unit_;
  s.total = total_.load(std::memory_order_relaxed);
  s.done = done_.load(std::memory_order_relaxed);
  if (rate_unit_.empty()) {
    s.rate_unit = unit_;
    s.rate_done = s.done;
  } else {
    s.rate_unit = rate_unit_;
    s.rate_done = rate_done_.load(std::memory_order_relaxed);
  }
  s.seconds = seconds_since(start_);
  return s;
}

}  // namespace rvr
