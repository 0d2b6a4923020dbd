#include "render_stats.h"

#include <sys/resource.h>

#include <cstdint>
#include <glm/glm.hpp>
#include <map>
#include <nlohmann/json.hpp>
#include <vector>

#include "rvr/core/shapes/triangle_mesh.h"

namespace rvr {
namespace {

uint64_t peak_memory_bytes() {
  rusage usage{};
  getrusage(RUSAGE_SELF, &usage);
  return uint64_t(usage.ru_maxrss) * 1024;
}

}  // namespace

std::string render_stats_json(const std::string& renderer, const Scene& scene, RenderMode mode,
                              const RenderTimes& times, const RenderOutput& out) {
  nlohmann::json j;
  j["renderer"] = renderer;
  j["scene"] = scene.source;
  j["width"] = scene.image.width;
  j["height"] = scene.image.height;
  j["mode"] = to_string(mode);
  j["time"] = {{"load", times.load}, {"render", times.render}, {"write", times.write}};
  nlohmann::json counters = nlohmann::json::object();
  for (const auto& [k, v] : out.stats) counters[k] = stat_json<nlohmann::json>(k, v);
  j["stats"] = counters;
  j["info"] = out.info;
  // The scene loader's warnings (each names the file), then the renderer's.
  std::vector<std::string> warnings = scene.warnings;
  warnings.insert(warnings.end(), out.warnings.begin(), out.warnings.end());
  j["warnings"] = warnings;
  j["peak_memory_bytes"] = peak_memory_bytes();
  // The scene's own vertex and index data, to read peak memory against.
  uint64_t scene_bytes = 0;
  for (const Object& o : scene.objects)
    scene_bytes += o.mesh.positions.size() * sizeof(glm::vec3) +
                   o.mesh.normals.size() * sizeof(glm::vec3) +
                   o.mesh.triangles.size() * sizeof(glm::uvec3);
  j["scene_mesh_bytes"] = scene_bytes;
  return j.dump(2) + "\n";
}

}  // namespace rvr
