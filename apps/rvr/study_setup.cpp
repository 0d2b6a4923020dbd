#include "study_setup.h"

#include <algorithm>
#include <map>
#include <thread>

#include "cpu_probe.h"
#include "rvr/core/isa.h"
#include "rvr/renderers/environment.h"

namespace rvr {

std::vector<std::string> default_study_renderers() {
  return {"softraster", "raytrace", "hybrid_soft"};
}

std::vector<std::string> study_renderers(const std::vector<std::string>& extra) {
  std::vector<std::string> names = default_study_renderers();
  for (const std::string& name : extra)
    if (std::find(names.begin(), names.end(), name) == names.end()) names.push_back(name);
  return names;
}

study::MachineInfo machine_info(const std::string& version) {
  study::MachineInfo m;
  m.cpu = cli::cpu_model();
  m.threads = std::thread::hardware_concurrency();
  m.kernels = describe_isa_choice();
  const TracerLibraries tracer = tracer_libraries();
  m.versions = {
      {"rvr", version}, {"embree", tracer.embree}, {"tbb", tracer.tbb}, {"compiler", __VERSION__}};
  return m;
}

}  // namespace rvr
