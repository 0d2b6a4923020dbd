// An absolute view of how busy the machine is, beside the study's relative one (the reference
// frame): what a constant load, invisible to a ratio of frame times, shows here. What
// pyperf's `system show` reports, read from /proc and /sys.
#pragma once

#include <string>

namespace rvr::study {

struct SystemSnapshot {
  double at = 0;                            // seconds since the study began
  int cpus = 0;                             // online CPUs
  double load1 = 0, load5 = 0, load15 = 0;  // /proc/loadavg
  // Over a short window in which the study itself waited: the share of all CPU time that
  // other work used (user, nice, system, irq, softirq), and that the hypervisor stole.
  double other_busy = 0, steal = 0;
  double mhz = 0;  // mean current clock over the CPUs (cpufreq, else /proc/cpuinfo); 0: unknown
  std::string governor;  // cpufreq's scaling governor of cpu0; "" where there is none
  bool known = false;    // false where /proc/stat could not be read (the other fields are 0)
};

// The share of other work above which a session counts as run on a busy machine.
constexpr double kBusyOtherShare = 0.25;

// Whether the snapshot shows other work (or steal) beyond kBusyOtherShare of the CPUs.
bool shows_other_work(const SystemSnapshot& s);

// Reads the machine's state, waiting `window_seconds` (idle) between two reads of /proc/stat.
SystemSnapshot probe_system(double window_seconds);

// "load 0.4 0.9 0.6 on 2 CPUs, 3% other work, 0% steal, 2596 MHz, governor unknown"
std::string describe(const SystemSnapshot& s);

}  // namespace rvr::study
