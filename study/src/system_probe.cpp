// Reading /proc and /sys for the machine's state (see system_probe.h).
#include "rvr/study/system_probe.h"

#include <fmt/format.h>

#include <array>
#include <chrono>
#include <cstdint>
#include <fstream>
#include <thread>

namespace rvr::study {
namespace {

// The first line of /proc/stat: user nice system idle iowait irq softirq steal (jiffies).
struct CpuTimes {
  std::array<uint64_t, 8> field{};
  bool ok = false;
  uint64_t total() const {
    uint64_t t = 0;
    for (uint64_t f : field) t += f;
    return t;
  }
  uint64_t busy() const { return field[0] + field[1] + field[2] + field[5] + field[6]; }
  uint64_t steal() const { return field[7]; }
};

CpuTimes read_cpu_times() {
  CpuTimes t;
  std::ifstream in("/proc/stat");
  std::string label;
  if (!(in >> label) || label != "cpu") return t;
  for (uint64_t& f : t.field)
    if (!(in >> f)) return t;
  t.ok = true;
  return t;
}

int online_cpus(std::ifstream& stat) {
  int cpus = 0;
  std::string line;
  while (std::getline(stat, line))
    if (line.rfind("cpu", 0) == 0 && line.size() > 3 && line[3] >= '0' && line[3] <= '9') ++cpus;
  return cpus;
}

std::string first_word(const std::string& path) {
  std::ifstream in(path);
  std::string word;
  in >> word;
  return word;
}

// The mean clock over the CPUs: cpufreq's (kHz) where the kernel has it, else /proc/cpuinfo's.
double mean_mhz(int cpus) {
  double sum = 0;
  int count = 0;
  for (int c = 0; c < cpus; ++c) {
    std::ifstream in(fmt::format("/sys/devices/system/cpu/cpu{}/cpufreq/scaling_cur_freq", c));
    double khz = 0;
    if (in >> khz) sum += khz / 1e3, ++count;
  }
  if (count > 0) return sum / count;
  std::ifstream info("/proc/cpuinfo");
  std::string line;
  while (std::getline(info, line))
    if (line.rfind("cpu MHz", 0) == 0) {
      std::istringstream value(line.substr(line.find(':') + 1));
      double mhz = 0;
      if (value >> mhz) sum += mhz, ++count;
    }
  return count > 0 ? sum / count : 0.0;
}

}  // namespace

bool shows_other_work(const SystemSnapshot& s) {
  return s.known && s.other_busy + s.steal > kBusyOtherShare;
}

SystemSnapshot probe_system(double window_seconds) {
  SystemSnapshot s;
  std::ifstream load("/proc/loadavg");
  load >> s.load1 >> s.load5 >> s.load15;
  std::ifstream stat("/proc/stat");
  s.cpus = online_cpus(stat);
  CpuTimes before = read_cpu_times();
  std::this_thread::sleep_for(std::chrono::duration<double>(window_seconds));
  CpuTimes after = read_cpu_times();
  if (before.ok && after.ok && after.total() > before.total()) {
    const double total = double(after.total() - before.total());
    s.other_busy = double(after.busy() - before.busy()) / total;
    s.steal = double(after.steal() - before.steal()) / total;
    s.known = true;
  }
  s.mhz = mean_mhz(s.cpus);
  s.governor = first_word("/sys/devices/system/cpu/cpu0/cpufreq/scaling_governor");
  return s;
}

std::string describe(const SystemSnapshot& s) {
  if (!s.known) return "machine state unknown (no /proc/stat)";
  return fmt::format(
      "load {:.2f} {:.2f} {:.2f} on {} CPUs, {:.0f}% other work, {:.0f}% steal, {}, "
      "governor {}",
      s.load1, s.load5, s.load15, s.cpus, 100 * s.other_busy, 100 * s.steal,
      s.mhz > 0 ? fmt::format("{:.0f} MHz", s.mhz) : std::string("clock unknown"),
      s.governor.empty() ? "unknown" : s.governor);
}

}  // namespace rvr::study
