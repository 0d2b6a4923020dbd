// rvr render: one renderer, one image, its AOVs and --stats.
#include <sys/resource.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <glm/glm.hpp>
#include <map>
#include <memory>
#include <nlohmann/json.hpp>
#include <string>
#include <utility>
#include <vector>

#include "cli_exit.h"
#include "commands.h"
#include "rvr/renderers/registry.h"
#include "rvr/shared/image_io.h"
#include "rvr/shared/renderer.h"
#include "rvr/shared/scene.h"
#include "rvr/shared/timer.h"
#include "terminal_progress.h"

namespace rvr::cli {

namespace {

double peak_memory_bytes() {
  rusage usage{};
  getrusage(RUSAGE_SELF, &usage);
  return double(usage.ru_maxrss) * 1024.0;
}

nlohmann::json finite_or_null(double v) {
  return std::isfinite(v) ? nlohmann::json(v) : nlohmann::json();
}

}  // namespace

int run_render(const RenderArgs& a) {
  const bool stats_to_stdout = a.stats == "-";  // as tools read "-": standard output
  std::vector<std::string> outputs{a.out};
  if (!stats_to_stdout && !a.stats.empty()) outputs.push_back(a.stats);
  const std::string base = std::filesystem::path(a.out).replace_extension().string();
  for (const std::string& aov : a.aovs) {
    std::string name = base;
    name.append(".").append(aov).append(aov == "cost" ? ".png" : ".exr");
    outputs.push_back(std::move(name));
  }
  if (std::count(a.aovs.begin(), a.aovs.end(), "cost")) outputs.push_back(base + ".cost.exr");
  refuse_overwriting_inputs({a.common.scene}, outputs);
  TerminalProgress progress(progress_wanted(a.common.quiet));
  progress.begin("", "load");
  RenderOptions options = render_options(a.common, "full");
  double load_seconds = 0;
  Scene scene = load(a.common, options, load_seconds);
  std::unique_ptr<Renderer> renderer = take(make_renderer(a.renderer, gl_backend(a.common)));
  options.progress = progress.sink();
  progress.begin(a.renderer, "render");
  auto start = Clock::now();
  RenderOutput out = take(renderer->render(scene, options));
  double render_seconds = seconds_since(start);

  progress.begin(a.renderer, "write");
  auto write_start = Clock::now();
  check(write_image(a.out, color_image(out.buffers)));
  if (!a.aovs.empty()) check(write_aovs(a.out, out.buffers, a.aovs));
  double write_seconds = seconds_since(write_start);
  progress.stop();  // before the warnings and the summary

  for (const std::string& w : scene.warnings) std::fprintf(stderr, "warning: %s\n", w.c_str());
  for (const std::string& w : out.warnings)
    std::fprintf(stderr, "warning: %s: %s\n", a.renderer.c_str(), w.c_str());
  if (!a.stats.empty()) {
    nlohmann::json j;
    j["renderer"] = a.renderer;
    j["scene"] = scene.source;
    j["width"] = scene.image.width;
    j["height"] = scene.image.height;
    j["mode"] = to_string(options.mode);
    j["time"] = {{"load", load_seconds}, {"render", render_seconds}, {"write", write_seconds}};
    nlohmann::json counters = nlohmann::json::object();
    for (const auto& [k, v] : out.stats) counters[k] = finite_or_null(v);
    j["stats"] = counters;
    j["info"] = out.info;
    // The scene loader's warnings (each names the file), then the renderer's.
    std::vector<std::string> warnings = scene.warnings;
    warnings.insert(warnings.end(), out.warnings.begin(), out.warnings.end());
    j["warnings"] = warnings;
    j["peak_memory_bytes"] = peak_memory_bytes();
    // The scene's own vertex and index data, to read peak memory against.
    double scene_bytes = 0;
    for (const Object& o : scene.objects)
      scene_bytes += double(o.mesh.positions.size() * sizeof(glm::vec3) +
                            o.mesh.normals.size() * sizeof(glm::vec3) +
                            o.mesh.triangles.size() * sizeof(glm::uvec3));
    j["scene_mesh_bytes"] = scene_bytes;
    if (stats_to_stdout)
      std::fputs((j.dump(2) + "\n").c_str(), stdout);
    else
      check(write_text_file(a.stats, j.dump(2) + "\n"));
  }
  if (!a.common.quiet) {
    std::fprintf(stderr, "%s: %s %dx%d %s in %.3f s -> %s\n", a.renderer.c_str(),
                 scene.source.c_str(), scene.image.width, scene.image.height,
                 to_string(options.mode), render_seconds, a.out.c_str());
  }
  return 0;
}

}  // namespace rvr::cli
